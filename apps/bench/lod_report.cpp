#include "lod_report.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "bench_plot.h"
#include "cli.h"
#include "text_tables.h"
#include "tilesplat/image.h"

namespace tilesplat::lod_report {

namespace {

namespace cli = tilesplat::cli;

std::string fixed(double value, int decimals) {
  return cli::format_fixed(value, decimals);
}

double elapsed_ms(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The cells of a row, in the tables' column order.
std::vector<std::string> cells(const Row& row) {
  return {row_label(row),
          cli::group_thousands(uint64_t(std::llround(row.splats))),
          fixed(row.gpu_ms, 3),
          row.level < 0 ? fixed(row.select_ms, 2) : "-",
          bench::psnr_cell(row.psnr_db),
          fixed(row.max_abs, 4)};
}

const std::vector<std::string> kColumns = {"row", "splats", "GPU ms", "select ms", "PSNR dB", "max abs"};

}  // namespace

std::string row_label(const Row& row) {
  return row.level >= 0 ? "level " + std::to_string(row.level) : "budget " + cli::group_thousands(row.budget);
}

Source source_of(const LodSet& set) {
  Source source;
  for (int level = 0; level < set.levels(); ++level) source.levels.push_back(level);
  source.load_level = [&set](int level) { return set.load_level(level); };
  source.choose = [&set](const Camera& view, uint64_t budget) {
    return set.load_selection(select_lod_levels(set, view, budget));
  };
  return source;
}

Source source_of(const SplatLodTree& tree) {
  Source source;
  // A tree has dozens of levels, most a few percent apart: those about halving the Gaussians make the curve.
  size_t listed = 0;
  for (int level = 0; level < tree.levels(); ++level) {
    const size_t size = tree.level_nodes(level).size();
    if (level == 0 || size <= listed / 2) {
      source.levels.push_back(level);
      listed = size;
    }
  }
  source.load_level = [&tree](int level) { return tree.load_level(level); };
  source.choose = [&tree](const Camera& view, uint64_t budget) { return tree.load(tree.select(view, budget).nodes); };
  return source;
}

std::vector<Row> plan_rows(const Source& source, std::vector<uint64_t> budgets) {
  std::vector<Row> rows;
  for (const int level : source.levels) rows.push_back(Row{level, 0});
  std::sort(budgets.begin(), budgets.end());
  budgets.erase(std::unique(budgets.begin(), budgets.end()), budgets.end());
  for (const uint64_t budget : budgets) rows.push_back(Row{-1, budget});
  return rows;
}

int work_units(const std::vector<Row>& rows, const Options& options) {
  return int(rows.size() * options.views.size()) * (options.warmup + options.repeat);
}

Run measure(const RendererOptions& renderer_options, const Source& source, std::vector<Row>& rows,
            const Options& options, const std::function<void(int, int, const std::string&)>& progress) {
  // Every row's scene at every view, gathered once: a level's is the same at every view; a budget's is
  // what the view chooses under it (timed with its gathering).
  std::vector<GaussianScene> levels(rows.size());
  for (size_t r = 0; r < rows.size(); ++r)
    if (rows[r].level >= 0) levels[r] = source.load_level(rows[r].level);
  std::vector<std::vector<GaussianScene>> chosen(rows.size());
  for (size_t r = 0; r < rows.size(); ++r) {
    if (rows[r].level >= 0) continue;
    std::vector<double> select_ms;
    for (const Camera& view : options.views) {
      const auto start = std::chrono::steady_clock::now();
      chosen[r].push_back(source.choose(view, rows[r].budget));
      select_ms.push_back(elapsed_ms(start));
    }
    rows[r].select_ms = cli::median(select_ms);
  }
  const auto scene_of = [&](size_t r, size_t v) -> const GaussianScene& {
    return rows[r].level >= 0 ? levels[r] : chosen[r][v];
  };

  auto renderer = Renderer::create(renderer_options);
  RenderSettings settings = options.settings;
  settings.sort = options.sort;
  const int total = work_units(rows, options);
  int done = 0;
  std::vector<std::vector<std::vector<double>>> samples(
      rows.size(), std::vector<std::vector<double>>(options.views.size()));
  std::vector<std::vector<RenderImage>> images(rows.size(), std::vector<RenderImage>(options.views.size()));
  for (int frame = 0; frame < options.warmup + options.repeat; ++frame)
    for (size_t r = 0; r < rows.size(); ++r)
      for (size_t v = 0; v < options.views.size(); ++v) {
        renderer->set_scene(scene_of(r, v));
        RenderImage image = renderer->render(options.views[v], settings);
        if (frame >= options.warmup) samples[r][v].push_back(renderer->last_frame_stats().gpu_ms);
        if (frame + 1 == options.warmup + options.repeat) images[r][v] = std::move(image);
        progress(++done, total, row_label(rows[r]));
      }

  const size_t finest = 0;  // rows start with level 0
  for (size_t r = 0; r < rows.size(); ++r) {
    std::vector<double> medians;
    double splats = 0, psnr = 0, max_abs = 0;
    size_t differing = 0;  // views whose image is not level 0's: only they have a finite PSNR to average
    for (size_t v = 0; v < options.views.size(); ++v) {
      medians.push_back(cli::median(samples[r][v]));
      splats += double(scene_of(r, v).size());
      const ImageDifference difference = compare_images(images[finest][v], images[r][v]);
      if (!std::isinf(difference.psnr_db)) {
        psnr += difference.psnr_db;
        ++differing;
      }
      max_abs = std::max(max_abs, difference.max_abs);
    }
    rows[r].gpu_ms = cli::median(medians);
    rows[r].splats = splats / double(options.views.size());
    rows[r].psnr_db = differing == 0 ? std::numeric_limits<double>::infinity() : psnr / double(differing);
    rows[r].max_abs = max_abs;
  }
  return {renderer->device_info(), renderer->validation_messages()};
}

std::string text_table(const std::vector<Row>& rows) {
  return bench::aligned_table(kColumns, bench::table_rows(rows, cells), /*label_column=*/true);
}

std::string markdown(const std::vector<Row>& rows, const std::string& scene, const DeviceInfo& device,
                     const std::string& command) {
  std::string out = "# LOD levels and splat budgets: " + scene + "\n\n";
  out += "Device: " + device.name + " (driver " + device.driver + "). Command: `" + command + "`.\n\n";
  out +=
      "Splats: Gaussians drawn (mean over the views). GPU ms: median over repeats, then views. Select ms: "
      "choosing the levels and gathering the chunks on the host. PSNR and max abs: against level 0 from "
      "the same view.\n\n";
  return out +
         bench::markdown_table(kColumns, bench::table_rows(rows, cells), "|---|---:|---:|---:|---:|---:|");
}

std::string csv(const std::vector<Row>& rows, const std::string& scene, const DeviceInfo& device) {
  std::string out = "device,scene,level,budget,splats,gpu_ms,select_ms,psnr_db,max_abs\n";
  for (const Row& row : rows)
    out += cli::csv_field(device.name) + "," + cli::csv_field(scene) + "," +
           (row.level >= 0 ? std::to_string(row.level) : "") + "," +
           (row.level < 0 ? std::to_string(row.budget) : "") + "," + fixed(row.splats, 1) + "," +
           fixed(row.gpu_ms, 4) + "," + (row.level < 0 ? fixed(row.select_ms, 3) : "") + "," +
           (std::isinf(row.psnr_db) ? "inf" : fixed(row.psnr_db, 3)) + "," + fixed(row.max_abs, 5) + "\n";
  return out;
}

std::string svg(const std::vector<Row>& rows, const std::string& scene, const DeviceInfo& device) {
  plot::LineChart chart;
  chart.title = "LOD levels and splat budgets: " + scene;
  chart.subtitle = device.name + "; PSNR against level 0 (level 0 itself is exact and not drawn)";
  chart.x_label = "Gaussians drawn";
  chart.y_label = "PSNR against level 0 (dB)";
  chart.x_scale = plot::Scale::kLog10;
  plot::LineSeries levels{"whole levels", 0, 1, {}};
  plot::LineSeries budgets{"splat budgets", 1, 0, {}};
  for (const Row& row : rows) {
    if (std::isinf(row.psnr_db)) continue;
    (row.level >= 0 ? levels : budgets).points.emplace_back(row.splats, row.psnr_db);
  }
  std::sort(levels.points.begin(), levels.points.end());
  std::sort(budgets.points.begin(), budgets.points.end());
  chart.series = {levels, budgets};
  return plot::line_chart_svg(chart);
}

}  // namespace tilesplat::lod_report
