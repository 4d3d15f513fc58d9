#include "accuracy_report.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>

#include "cli.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"

namespace tilesplat::accuracy {

namespace {

AccuracyModes with(std::initializer_list<const char*> tokens) {
  std::string text;
  for (const char* token : tokens) {
    if (!text.empty()) text += '+';
    text += token;
  }
  return parse_accuracy_modes(text);
}

}  // namespace

std::vector<AccuracyModes> default_modes() {
  return {
      with({"reference"}),
      with({"depth24"}),
      with({"depth16"}),
      with({"square-tiles"}),
      with({"opacity-extent"}),
      with({"opacity-extent", "square-tiles"}),
      with({"sh0"}),
      with({"sh1"}),
      with({"sh2"}),
      with({"fp16-sh"}),
      with({"fp16-cov"}),
      with({"t-cutoff=1e-3"}),
      with({"t-cutoff=1e-2"}),
      with({"alpha-cutoff=1/128"}),
      with({"alpha-cutoff=1/64"}),
      with({"resort4"}),
      with({"resort8"}),
      with({"resort16"}),
      // Sorted by distance: the order a turn in place keeps (Spark's radial sort); alone and re-sorted.
      with({"radial"}),
      with({"radial", "resort4"}),
      with({"radial", "resort16"}),
      // The raster compositor's half-precision blend (its report only: the others refuse it).
      with({"fp16-blend"}),
      // What a web viewer does: 16-bit depths, fp16 attributes, opacity-aware squares.
      with({"depth16", "opacity-extent", "fp16-sh", "fp16-cov"}),
      // ... and looser cut-offs on top.
      with({"depth16", "opacity-extent", "fp16-sh", "fp16-cov", "t-cutoff=1e-3", "alpha-cutoff=1/64"}),
  };
}

bool applies_to(const AccuracyModes& modes, int scene_sh_degree) {
  return modes.sh_degree_cap >= 3 || modes.sh_degree_cap < scene_sh_degree;
}

const char* to_string(CameraPath path) {
  switch (path) {
    case CameraPath::kDolly: return "dolly";
    case CameraPath::kPan: return "pan";
    case CameraPath::kOrbit: return "orbit";
  }
  return "?";
}

std::optional<CameraPath> parse_camera_path(const std::string& text) {
  for (CameraPath path : {CameraPath::kDolly, CameraPath::kPan, CameraPath::kOrbit})
    if (text == to_string(path)) return path;
  return std::nullopt;
}

std::vector<Camera> camera_path(CameraPath kind, const Camera& start, const std::array<double, 3>& centre, int frames,
                                double step_fraction) {
  double distance = 0;
  for (int k = 0; k < 3; ++k) distance += (centre[k] - start.position[k]) * (centre[k] - start.position[k]);
  distance = std::sqrt(distance);
  // The rows of the world-to-camera rotation are the camera's axes in world space: row 0 is x, row 1 y.
  const std::array<double, 3> camera_x = {start.rotation[0], start.rotation[1], start.rotation[2]};
  const std::array<double, 3> camera_y = {start.rotation[3], start.rotation[4], start.rotation[5]};
  std::vector<Camera> path;
  for (int f = 0; f < frames; ++f) {
    Camera camera = start;
    switch (kind) {
      case CameraPath::kDolly:
        for (int k = 0; k < 3; ++k) camera.position[k] += f * step_fraction * distance * camera_x[k];
        break;
      case CameraPath::kPan:
        // Turning in place about the camera's y axis. Turning the rig by -a is x_cam' = R_y(a) x_cam.
        camera = turn_camera(start, start.position, camera_y, -f * step_fraction);
        break;
      case CameraPath::kOrbit:
        // The whole rig turns about the line through `centre` along the camera's y axis.
        camera = turn_camera(start, centre, camera_y, f * step_fraction);
        break;
    }
    path.push_back(camera);
  }
  return path;
}

std::vector<Row> report_rows(const Options& options, int scene_sh_degree) {
  const auto modes = options.modes.empty() ? default_modes() : options.modes;
  std::vector<Row> rows;
  const Compositor first = options.compositor.value_or(Compositor::kSorted);
  for (const AccuracyModes& m : modes)
    if (applies_to(m, scene_sh_degree) && compositor_draws(first, m)) rows.push_back({m, first});
  // The default report: the raster compositor beside the sorted one, on the reference modes. (Modes
  // given by name are measured as given, by the compositor given.)
  if (options.modes.empty() && !options.compositor) rows.push_back({AccuracyModes{}, Compositor::kRaster});
  return rows;
}

std::string row_name(const Row& row) {
  if (row.compositor == Compositor::kSorted) return to_string(row.modes);
  const std::string compositor = to_string(row.compositor);
  return row.modes == AccuracyModes{} ? compositor : compositor + "+" + to_string(row.modes);
}

int work_units(const Options& options, int scene_sh_degree) {
  const std::vector<Row> rows = report_rows(options, scene_sh_degree);
  int applicable = 0, other_compositors = 0;
  bool raster = false;
  for (const Row& row : rows) {
    ++applicable;
    other_compositors += row.compositor != Compositor::kSorted ? 1 : 0;
    raster = raster || row.compositor == Compositor::kRaster;
  }
  const int views = int(options.views.size());
  // The path starts at the first view, whose reference it reuses. References: each view in both orders
  // and each later path frame; renders: per mode, per view the timed frames, and the path's frames (with
  // their depth, which the timed frames do not write).
  const int later_path_frames = std::max(options.path_frames - 1, 0);
  const int consistency_pair = options.consistency_angle > 0 ? 2 : 0;
  // A row of another compositor also renders (and times) the sorted compositor's frames at each view. The
  // consistency pair's references are in both orders.
  return 2 * views + later_path_frames + 2 * consistency_pair +
         applicable * (views * (options.warmup + options.repeat) + options.path_frames + consistency_pair) +
         other_compositors * views * (options.warmup + options.repeat) +
         (raster ? views : 0);  // the raster rule's references
}

namespace {

using Step = std::function<void(const std::string&)>;

// The float64 references a scene's rows are held to.
struct References {
  std::vector<RenderImage> views;      // each view's
  std::vector<RenderImage> ray_order;  // each view's in the exact ray order (pinhole views; else none at all)
  std::vector<RenderImage> path;       // the path's frames (frame 0 is the first view's)
  std::vector<RenderImage> raster;     // the raster rule's at each view, when a row draws with it
};

// Raw change between two frames: the excess over a sequence that stands still.
double flicker_of(const RenderImage& a0, const RenderImage& a1) {
  return temporal_excess(a0, a1, a0, a0, kFlickerThreshold).flicker_fraction;
}

// The depth-warped difference of a path's frames f - 1 and f.
TemporalDifference warp_of(const std::vector<RenderImage>& frames, const std::vector<Camera>& path,
                           size_t f) {
  return depth_warp_difference(frames[f - 1], path[f - 1], frames[f], path[f], kWarpBlock, kWarpThreshold);
}

// The view-consistency pair's difference: the same camera turned in place.
TemporalDifference inconsistency_of(const RenderImage& a, const RenderImage& b,
                                    const std::vector<Camera>& turned) {
  return rotation_inconsistency(a, turned[0], b, turned[1], kConsistencyBlock, kConsistencyThreshold);
}

// The view-consistency pair: the first view and the same camera turned in place, at a size where a
// block of pixels stands for one pixel of the view; none without an angle.
std::vector<Camera> turned_pair(const Options& options) {
  if (options.consistency_angle <= 0) return {};
  const Camera& view = options.views.front();
  const Camera large = resize_camera(view, kConsistencyScale * view.width, kConsistencyScale * view.height);
  return camera_path(CameraPath::kPan, large, {}, 2, options.consistency_angle);
}

// The references of the views (and their exact ray order) and of the path's frames.
References render_references(const GaussianScene& scene, const Options& options,
                             const std::vector<Camera>& path, const RenderSettings& settings,
                             const Step& step) {
  References refs;
  for (size_t v = 0; v < options.views.size(); ++v) {
    refs.views.push_back(render_reference(scene, options.views[v], settings));
    step("float64 reference, " + options.view_names[v]);
    // The exact per-pixel order's rays are a pinhole's; other views get no such reference.
    if (options.views[v].model == CameraModel::kPinhole)
      refs.ray_order.push_back(
          render_reference(scene, options.views[v], settings, ReferenceOrder::kRayDepth));
    step("float64 reference in exact ray order, " + options.view_names[v]);
  }
  // path[0] is the first view: its reference is already made.
  for (size_t f = 0; f < path.size(); ++f) {
    if (f == 0) {
      refs.path.push_back(refs.views.front());
      continue;
    }
    refs.path.push_back(render_reference(scene, path[f], settings));
    step("float64 reference, path frame " + std::to_string(f));
  }
  return refs;
}

// The float64 reference's raster rule at each view, when a row draws with the raster compositor.
std::vector<RenderImage> render_raster_references(const GaussianScene& scene, const Options& options,
                                                  const std::vector<Row>& rows,
                                                  const RenderSettings& settings, const Step& step) {
  std::vector<RenderImage> raster;
  if (std::none_of(rows.begin(), rows.end(),
                   [](const Row& row) { return row.compositor == Compositor::kRaster; }))
    return raster;
  RenderSettings raster_rule = settings;
  raster_rule.compositor = Compositor::kRaster;
  for (size_t v = 0; v < options.views.size(); ++v) {
    raster.push_back(render_reference(scene, options.views[v], raster_rule));
    step("float64 reference's raster rule, " + options.view_names[v]);
  }
  return raster;
}

// The reference's own change, flicker, popping and depth-warped popping along the path.
void measure_reference_path(SceneReport& report, const std::vector<RenderImage>& frames,
                            const std::vector<Camera>& path) {
  for (size_t f = 1; f < frames.size(); ++f) {
    const double pairs = double(path.size() - 1);
    report.reference_change += frame_change(frames[f - 1], frames[f]) / pairs;
    report.reference_flicker += flicker_of(frames[f - 1], frames[f]) / pairs;
  }
  for (size_t f = 2; f < frames.size(); ++f)
    report.reference_pops +=
        popping(frames[f - 2], frames[f - 1], frames[f], kFlickerThreshold).flicker_fraction /
        double(path.size() - 2);
  for (size_t f = 1; f < frames.size(); ++f) {
    report.reference_warp_pops_per_step.push_back(warp_of(frames, path, f).flicker_fraction);
    report.reference_warp_pops += report.reference_warp_pops_per_step.back() / double(path.size() - 1);
  }
}

// The float64 reference's inconsistency over the turned pair, in the centre-depth order and in the exact
// ray order (none there for a camera that is not a pinhole's, whose rays it does not follow).
void measure_reference_consistency(SceneReport& report, const GaussianScene& scene,
                                   const std::vector<Camera>& turned, const RenderSettings& settings,
                                   const Step& step) {
  auto pair_inconsistency = [&](ReferenceOrder order,
                                const std::string& what) -> std::optional<TemporalDifference> {
    std::vector<RenderImage> pair;
    for (size_t f = 0; f < turned.size(); ++f) {
      if (order != ReferenceOrder::kRayDepth || turned[f].model == CameraModel::kPinhole)
        pair.push_back(render_reference(scene, turned[f], settings, order));
      step(what + ", turned view " + std::to_string(f));
    }
    if (pair.size() != turned.size()) return std::nullopt;
    return inconsistency_of(pair[0], pair[1], turned);
  };
  const TemporalDifference centre_order = *pair_inconsistency(ReferenceOrder::kSettings, "float64 reference");
  report.reference_inconsistency = centre_order.flicker_fraction;
  report.reference_inconsistency_mean = centre_order.mean_abs;
  if (const auto exact =
          pair_inconsistency(ReferenceOrder::kRayDepth, "float64 reference in exact ray order")) {
    report.exact_order_inconsistency = exact->flicker_fraction;
    report.exact_order_inconsistency_mean = exact->mean_abs;
  }
}

// A row's frames at every view: timed (median GPU time of the repeats, per pass too), and held to the
// references (and, for another compositor, to the sorted compositor's frame timed alike).
void measure_views(ModeResult& result, Renderer& renderer, const Row& row, const RenderSettings& settings,
                   const Options& options, const References& refs, const Step& step) {
  double psnr_vs_sorted_sum = 0, psnr_vs_rule_sum = 0, psnr_vs_ray_order_sum = 0;
  std::vector<double> sorted_ms_per_view;
  std::vector<double> frame_ms_per_view;
  std::map<std::string, std::vector<double>> pass_ms_per_view;
  std::vector<std::string> pass_order;
  double psnr_sum = 0, ssim_sum = 0;
  for (size_t v = 0; v < options.views.size(); ++v) {
    RenderImage image;
    std::vector<double> frames;
    std::map<std::string, std::vector<double>> passes;
    for (int r = 0; r < options.warmup + options.repeat; ++r) {
      image = renderer.render(options.views[v], settings);
      const FrameStats& stats = renderer.last_frame_stats();
      if (r >= options.warmup) {
        frames.push_back(stats.gpu_ms);
        // A pass recorded several times a frame counts once, with its total.
        std::map<std::string, double> frame_passes;
        for (const auto& pass : stats.passes) {
          if (std::find(pass_order.begin(), pass_order.end(), pass.name) == pass_order.end())
            pass_order.push_back(pass.name);
          frame_passes[pass.name] += pass.gpu_ms;
        }
        for (const auto& [name, ms] : frame_passes) passes[name].push_back(ms);
      }
      if (v == 0) result.intersections = stats.intersections;
      step(result.name + ", " + options.view_names[v]);
    }
    frame_ms_per_view.push_back(cli::median(frames));
    for (const auto& [name, samples] : passes) pass_ms_per_view[name].push_back(cli::median(samples));
    if (row.compositor != Compositor::kSorted) {  // the sorted compositor's frames, timed alike
      RenderSettings sorted = settings;
      sorted.compositor = Compositor::kSorted;
      // fp16-blend is the raster's attachment format; the sorted compositor blends in float32.
      sorted.accuracy.fp16_blend = false;
      RenderImage sorted_image;
      std::vector<double> sorted_frames;
      for (int r = 0; r < options.warmup + options.repeat; ++r) {
        sorted_image = renderer.render(options.views[v], sorted);
        if (r >= options.warmup) sorted_frames.push_back(renderer.last_frame_stats().gpu_ms);
        step(result.name + ", the sorted compositor's frame, " + options.view_names[v]);
      }
      sorted_ms_per_view.push_back(cli::median(sorted_frames));
      psnr_vs_sorted_sum += compare_images(image, sorted_image).psnr_db;
    }
    if (row.compositor == Compositor::kRaster)
      psnr_vs_rule_sum += compare_images(image, refs.raster[v]).psnr_db;
    if (refs.ray_order.size() == options.views.size())
      psnr_vs_ray_order_sum += compare_images(image, refs.ray_order[v]).psnr_db;
    const ImageDifference difference = compare_images(image, refs.views[v]);
    psnr_sum += difference.psnr_db;
    ssim_sum += ssim(image, refs.views[v]);
    result.max_abs = std::max(result.max_abs, difference.max_abs);
  }
  result.frame_ms = cli::median(frame_ms_per_view);
  for (const auto& name : pass_order) result.passes.push_back({name, cli::median(pass_ms_per_view[name])});
  result.psnr_db = psnr_sum / double(options.views.size());
  if (row.compositor != Compositor::kSorted) {
    result.psnr_vs_sorted_db = psnr_vs_sorted_sum / double(options.views.size());
    result.sorted_frame_ms = cli::median(sorted_ms_per_view);
  }
  if (row.compositor == Compositor::kRaster)
    result.psnr_vs_rule_db = psnr_vs_rule_sum / double(options.views.size());
  result.psnr_vs_ray_order_db = refs.ray_order.size() == options.views.size()
                                    ? psnr_vs_ray_order_sum / double(options.views.size())
                                    : std::numeric_limits<double>::quiet_NaN();
  result.ssim = ssim_sum / double(options.views.size());
}

// A row along the path, each frame with its depth (the timed frames leave it out): change, flicker,
// excess over the reference's, popping, depth-warped popping.
void measure_path(ModeResult& result, Renderer& renderer, const RenderSettings& settings,
                  const std::vector<Camera>& path, const std::vector<RenderImage>& path_references,
                  const Step& step) {
  RenderSettings path_settings = settings;
  path_settings.depth = true;
  std::vector<RenderImage> frames;
  for (size_t f = 0; f < path.size(); ++f) {
    frames.push_back(renderer.render(path[f], path_settings));
    step(result.name + ", path frame " + std::to_string(f));
  }
  for (size_t f = 1; f < frames.size(); ++f) {
    const double pairs = double(frames.size() - 1);
    result.frame_change += frame_change(frames[f - 1], frames[f]) / pairs;
    result.flicker += flicker_of(frames[f - 1], frames[f]) / pairs;
    result.excess +=
        temporal_excess(frames[f - 1], frames[f], path_references[f - 1], path_references[f]).mean_abs /
        pairs;
  }
  for (size_t f = 2; f < frames.size(); ++f) {
    const TemporalDifference pops = popping(frames[f - 2], frames[f - 1], frames[f], kFlickerThreshold);
    result.pops += pops.flicker_fraction / double(frames.size() - 2);
    result.pop_mean += pops.mean_abs / double(frames.size() - 2);
  }
  for (size_t f = 1; f < frames.size(); ++f) {
    const TemporalDifference warped = warp_of(frames, path, f);
    result.warp_pops_per_step.push_back(warped.flicker_fraction);
    result.warp_pops += warped.flicker_fraction / double(frames.size() - 1);
    result.warp_mean += warped.mean_abs / double(frames.size() - 1);
  }
}

// One row: its frames at the views, along the path and over the turned pair.
ModeResult measure_row(Renderer& renderer, const Row& row, const Options& options, const References& refs,
                       const std::vector<Camera>& path, const std::vector<Camera>& turned, const Step& step) {
  ModeResult result;
  result.modes = row.modes;
  result.compositor = row.compositor;
  result.name = row_name(row);
  result.psnr_vs_sorted_db = std::numeric_limits<double>::quiet_NaN();
  result.psnr_vs_rule_db = std::numeric_limits<double>::quiet_NaN();
  RenderSettings settings;
  settings.sort = options.sort;
  settings.depth = false;
  settings.splat_count = false;
  settings.accuracy = row.modes;
  settings.compositor = row.compositor;
  settings.reuse_lists = false;  // the repeats time whole frames, not the composite on reused lists
  measure_views(result, renderer, row, settings, options, refs, step);
  measure_path(result, renderer, settings, path, refs.path, step);
  if (!turned.empty()) {
    std::vector<RenderImage> pair;
    for (size_t f = 0; f < turned.size(); ++f) {
      pair.push_back(renderer.render(turned[f], settings));
      step(result.name + ", turned view " + std::to_string(f));
    }
    const TemporalDifference inconsistency = inconsistency_of(pair[0], pair[1], turned);
    result.inconsistency = inconsistency.flicker_fraction;
    result.inconsistency_mean = inconsistency.mean_abs;
  }
  return result;
}

}  // namespace

SceneReport measure_scene(Renderer& renderer, const GaussianScene& scene, const Options& options,
                          const std::function<void(int, int, const std::string&)>& progress) {
  if (options.views.empty()) throw std::invalid_argument("accuracy report: no views");
  const std::vector<Row> rows = report_rows(options, scene.sh_degree);
  const int total = work_units(options, scene.sh_degree);
  int done = 0;
  const Step step = [&](const std::string& what) { progress(++done, total, what); };

  SceneReport report;
  report.path = options.path;
  report.path_frames = options.path_frames;
  report.path_step = options.path_step;
  RenderSettings reference_settings;
  reference_settings.depth = true;  // the path's depth-warped popping needs it
  reference_settings.splat_count = false;

  const Bounds bounds = compute_bounds(scene);
  const std::vector<Camera> path =
      camera_path(options.path, options.views.front(), {bounds.center[0], bounds.center[1], bounds.center[2]},
                  options.path_frames, options.path_step);
  const std::vector<Camera> turned = turned_pair(options);
  report.consistency_angle = turned.empty() ? 0 : options.consistency_angle;

  // The references: the views', the path's, the turned pair's, the raster rule's.
  References refs = render_references(scene, options, path, reference_settings, step);
  measure_reference_path(report, refs.path, path);
  if (!turned.empty()) measure_reference_consistency(report, scene, turned, reference_settings, step);
  refs.raster = render_raster_references(scene, options, rows, reference_settings, step);

  renderer.set_scene(scene);
  for (const Row& row : rows)
    report.modes.push_back(measure_row(renderer, row, options, refs, path, turned, step));
  return report;
}

}  // namespace tilesplat::accuracy
