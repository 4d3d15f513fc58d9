#include "sample_curve.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "bench_plot.h"
#include "cli.h"
#include "text_tables.h"
#include "tilesplat/image.h"
#include "tilesplat/lens.h"
#include "tilesplat/shutter.h"

namespace tilesplat::sample_curve {

namespace {

namespace cli = tilesplat::cli;

std::string fixed(double value, int decimals) {
  return cli::format_fixed(value, decimals);
}

const std::vector<std::string> kColumns = {"samples", "GPU ms", "GPU ms per sample", "PSNR dB", "max abs"};

std::vector<std::string> cells(const Row& row) {
  return {std::to_string(row.samples), fixed(row.gpu_ms, 3), fixed(row.gpu_ms / row.samples, 3),
          bench::psnr_cell(row.psnr_db), fixed(row.max_abs, 4)};
}

std::string what_is_averaged(Effect effect) {
  switch (effect) {
    case Effect::kLens:
      return "depth of field: a thin lens of aperture 0.05 of the view depth of the scene's centre, focused "
             "there";
    case Effect::kTime:
      return "motion blur: the shutter open over the frame while the camera turns 5 degrees about the "
             "scene's centre";
    case Effect::kLensSobol:
      return "depth of field as 'lens', its positions the progressive (sobol) pattern's";
    case Effect::kTimeSobol:
      return "motion blur as 'time', its times the progressive (sobol) pattern's";
    case Effect::kStochastic:
      return "the stochastic compositor's frames, thresholds from the hash";
    case Effect::kStochasticStratified:
      return "the stochastic compositor's frames, thresholds from the stratified sampler";
    case Effect::kStochasticSobol:
      return "the stochastic compositor's frames, thresholds from the sobol sampler";
  }
  return "";
}

// What the PSNR is against, for the reports.
std::string held_to(Effect effect) {
  return held_to_sorted_frame(effect) ? "the sorted frame"
                                      : std::to_string(kReferenceSamples) + " samples of the even pattern";
}

}  // namespace

std::string effect_name(Effect effect) {
  switch (effect) {
    case Effect::kLens:
      return "lens";
    case Effect::kTime:
      return "time";
    case Effect::kLensSobol:
      return "lens-sobol";
    case Effect::kTimeSobol:
      return "time-sobol";
    case Effect::kStochastic:
      return "stochastic";
    case Effect::kStochasticStratified:
      return "stochastic-stratified";
    case Effect::kStochasticSobol:
      return "stochastic-sobol";
  }
  return "";
}

std::optional<Effect> parse_effect(const std::string& name) {
  for (Effect e : {Effect::kLens, Effect::kTime, Effect::kLensSobol, Effect::kTimeSobol, Effect::kStochastic,
                   Effect::kStochasticStratified, Effect::kStochasticSobol})
    if (effect_name(e) == name) return e;
  return std::nullopt;
}

bool held_to_sorted_frame(Effect effect) {
  return effect == Effect::kStochastic || effect == Effect::kStochasticStratified ||
         effect == Effect::kStochasticSobol;
}

namespace {

// What every row's frames share: the options' settings and sort (the stochastic curves' reference, the
// sorted frame).
RenderSettings shared_settings(const Options& options) {
  RenderSettings settings = options.settings;
  settings.sort = options.sort;
  return settings;
}

}  // namespace

RenderSettings effect_settings(const Options& options, const Camera& view, int samples) {
  RenderSettings settings = shared_settings(options);
  if (held_to_sorted_frame(options.effect)) {
    settings.compositor = Compositor::kStochastic;
    settings.stochastic.frames = uint32_t(samples);
    settings.stochastic.sampler = options.effect == Effect::kStochasticStratified
                                      ? StochasticSampler::kStratified
                                  : options.effect == Effect::kStochasticSobol ? StochasticSampler::kSobol
                                                                               : StochasticSampler::kHash;
  } else if (options.effect == Effect::kLens || options.effect == Effect::kLensSobol) {
    const double focus = view.to_camera(options.centre)[2];
    settings.lens = {
        .aperture_diameter = 0.05 * focus,
        .focus_distance = focus,
        .samples = samples,
        .pattern = options.effect == Effect::kLensSobol ? SamplePattern::kSobol : SamplePattern::kEven};
  } else {
    settings.shutter = {
        .open = 0,
        .close = 1,
        .samples = samples,
        .end_camera = turn_camera(view, options.centre, {0, -1, 0}, 5 * std::numbers::pi / 180),
        .scan = ShutterScan::kGlobal,
        .pattern = options.effect == Effect::kTimeSobol ? SamplePattern::kSobol : SamplePattern::kEven};
  }
  return settings;
}

RenderSettings reference_settings(const Options& options, const Camera& view) {
  if (held_to_sorted_frame(options.effect)) return shared_settings(options);
  RenderSettings settings = effect_settings(options, view, kReferenceSamples);
  settings.lens.pattern = settings.shutter.pattern = SamplePattern::kEven;
  return settings;
}

int work_units(const Options& options) {
  return int(options.views.size()) * (1 + int(options.counts.size()) * (options.warmup + options.repeat));
}

Run measure(const RendererOptions& renderer_options, const GaussianScene& scene, const Options& options,
            std::vector<Row>& rows, const std::function<void(int, int, const std::string&)>& progress) {
  std::vector<int> counts = options.counts;
  std::sort(counts.begin(), counts.end());
  counts.erase(std::unique(counts.begin(), counts.end()), counts.end());
  auto renderer = Renderer::create(renderer_options);
  renderer->set_scene(scene);
  const int total = work_units(options);
  int done = 0;
  std::vector<RenderImage> references;
  for (const Camera& view : options.views) {
    references.push_back(renderer->render(view, reference_settings(options, view)));
    progress(++done, total, held_to(options.effect));
  }
  const size_t views = options.views.size();
  std::vector<std::vector<std::vector<double>>> times(counts.size(), std::vector<std::vector<double>>(views));
  std::vector<std::vector<RenderImage>> images(counts.size(), std::vector<RenderImage>(views));
  for (int frame = 0; frame < options.warmup + options.repeat; ++frame)
    for (size_t r = 0; r < counts.size(); ++r)
      for (size_t v = 0; v < views; ++v) {
        RenderImage image =
            renderer->render(options.views[v], effect_settings(options, options.views[v], counts[r]));
        if (frame >= options.warmup) times[r][v].push_back(renderer->last_frame_stats().gpu_ms);
        if (frame + 1 == options.warmup + options.repeat) images[r][v] = std::move(image);
        progress(++done, total, std::to_string(counts[r]) + " samples");
      }
  rows.clear();
  for (size_t r = 0; r < counts.size(); ++r) {
    Row row;
    row.samples = counts[r];
    std::vector<double> medians;
    double psnr = 0;
    size_t differing = 0;
    for (size_t v = 0; v < views; ++v) {
      medians.push_back(cli::median(times[r][v]));
      const ImageDifference difference = compare_images(references[v], images[r][v]);
      if (!std::isinf(difference.psnr_db)) {
        psnr += difference.psnr_db;
        ++differing;
      }
      row.max_abs = std::max(row.max_abs, difference.max_abs);
    }
    row.gpu_ms = cli::median(medians);
    row.psnr_db = differing == 0 ? std::numeric_limits<double>::infinity() : psnr / double(differing);
    rows.push_back(row);
  }
  return {renderer->device_info(), renderer->validation_messages()};
}

std::string text_table(const std::vector<Row>& rows) {
  return bench::aligned_table(kColumns, bench::table_rows(rows, cells), /*label_column=*/false);
}

std::string markdown(const std::vector<Row>& rows, Effect effect, const std::string& scene,
                     const DeviceInfo& device, const std::string& command) {
  std::string out = "# Samples against error and time, " + effect_name(effect) + ": " + scene + "\n\n";
  out += "Device: " + device.name + " (driver " + device.driver + "). Command: `" + command + "`.\n\n";
  out += "The effect: " + what_is_averaged(effect) +
         ". GPU ms: median over repeats, then views. PSNR and max abs: against " + held_to(effect) +
         " from the same view.\n\n";
  return out + bench::markdown_table(kColumns, bench::table_rows(rows, cells), "|---:|---:|---:|---:|---:|");
}

std::string csv(const std::vector<Row>& rows, Effect effect, const std::string& scene,
                const DeviceInfo& device) {
  std::string out = "device,scene,effect,samples,gpu_ms,gpu_ms_per_sample,psnr_db,max_abs\n";
  for (const Row& row : rows)
    out += cli::csv_field(device.name) + "," + cli::csv_field(scene) + "," + effect_name(effect) + "," +
           std::to_string(row.samples) + "," + fixed(row.gpu_ms, 4) + "," +
           fixed(row.gpu_ms / row.samples, 4) + "," +
           (std::isinf(row.psnr_db) ? "inf" : fixed(row.psnr_db, 3)) + "," + fixed(row.max_abs, 5) + "\n";
  return out;
}

std::string svg(const std::vector<Row>& rows, Effect effect, const std::string& scene,
                const DeviceInfo& device) {
  plot::LineChart chart;
  chart.title = "Samples against error, " + effect_name(effect) + ": " + scene;
  chart.subtitle = device.name + "; PSNR against " + held_to(effect);
  chart.x_label = "samples";
  chart.y_label = "PSNR against " + held_to(effect) + " (dB)";
  chart.x_scale = plot::Scale::kLog10;
  plot::LineSeries series{effect_name(effect) + " samples", 0, 0, {}};
  for (const Row& row : rows)
    if (!std::isinf(row.psnr_db)) series.points.emplace_back(double(row.samples), row.psnr_db);
  chart.series = {series};
  return plot::line_chart_svg(chart);
}

}  // namespace tilesplat::sample_curve
