#include "accuracy_report.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>

#include "bench_plot.h"
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

SceneReport measure_scene(Renderer& renderer, const GaussianScene& scene, const Options& options,
                          const std::function<void(int, int, const std::string&)>& progress) {
  if (options.views.empty()) throw std::invalid_argument("accuracy report: no views");
  const std::vector<Row> rows = report_rows(options, scene.sh_degree);
  const int total = work_units(options, scene.sh_degree);
  int done = 0;
  auto step = [&](const std::string& what) { progress(++done, total, what); };

  SceneReport report;
  report.path = options.path;
  report.path_frames = options.path_frames;
  report.path_step = options.path_step;
  RenderSettings reference_settings;
  reference_settings.depth = true;  // the path's depth-warped popping needs it
  reference_settings.splat_count = false;

  std::vector<RenderImage> references, ray_order_references;
  for (size_t v = 0; v < options.views.size(); ++v) {
    references.push_back(render_reference(scene, options.views[v], reference_settings));
    step("float64 reference, " + options.view_names[v]);
    // The exact per-pixel order's rays are a pinhole's; other views get no such reference.
    if (options.views[v].model == CameraModel::kPinhole)
      ray_order_references.push_back(
          render_reference(scene, options.views[v], reference_settings, ReferenceOrder::kRayDepth));
    step("float64 reference in exact ray order, " + options.view_names[v]);
  }
  const Bounds bounds = compute_bounds(scene);
  const std::vector<Camera> path =
      camera_path(options.path, options.views.front(), {bounds.center[0], bounds.center[1], bounds.center[2]},
                  options.path_frames, options.path_step);
  // path[0] is the first view: its reference is already made.
  std::vector<RenderImage> path_references;
  for (size_t f = 0; f < path.size(); ++f) {
    if (f == 0) {
      path_references.push_back(references.front());
      continue;
    }
    path_references.push_back(render_reference(scene, path[f], reference_settings));
    step("float64 reference, path frame " + std::to_string(f));
  }
  // Raw change between two frames: the excess over a sequence that stands still.
  auto flicker_of = [](const RenderImage& a0, const RenderImage& a1) {
    return temporal_excess(a0, a1, a0, a0, kFlickerThreshold).flicker_fraction;
  };
  for (size_t f = 1; f < path_references.size(); ++f) {
    const double pairs = double(path.size() - 1);
    report.reference_change += frame_change(path_references[f - 1], path_references[f]) / pairs;
    report.reference_flicker += flicker_of(path_references[f - 1], path_references[f]) / pairs;
  }
  for (size_t f = 2; f < path_references.size(); ++f)
    report.reference_pops += popping(path_references[f - 2], path_references[f - 1], path_references[f],
                                     kFlickerThreshold).flicker_fraction /
                             double(path.size() - 2);
  auto warp_of = [&path](const std::vector<RenderImage>& frames, size_t f) {
    return depth_warp_difference(frames[f - 1], path[f - 1], frames[f], path[f], kWarpBlock, kWarpThreshold);
  };
  for (size_t f = 1; f < path_references.size(); ++f) {
    report.reference_warp_pops_per_step.push_back(warp_of(path_references, f).flicker_fraction);
    report.reference_warp_pops += report.reference_warp_pops_per_step.back() / double(path.size() - 1);
  }

  // The view-consistency pair: the first view and the same camera turned in place, at a size where a
  // block of pixels stands for one pixel of the view.
  std::vector<Camera> turned;
  if (options.consistency_angle > 0) {
    const Camera& view = options.views.front();
    const Camera large = resize_camera(view, kConsistencyScale * view.width, kConsistencyScale * view.height);
    turned = camera_path(CameraPath::kPan, large, {}, 2, options.consistency_angle);
  }
  auto inconsistency_of = [&turned](const RenderImage& a, const RenderImage& b) {
    return rotation_inconsistency(a, turned[0], b, turned[1], kConsistencyBlock, kConsistencyThreshold);
  };
  report.consistency_angle = turned.empty() ? 0 : options.consistency_angle;
  if (!turned.empty()) {
    // The float64 reference's pair in `order`; none in the exact ray order, whose rays are a pinhole's, for
    // another camera (as for the views above).
    auto reference_pair_inconsistency = [&](ReferenceOrder order,
                                            const std::string& what) -> std::optional<TemporalDifference> {
      std::vector<RenderImage> pair;
      for (size_t f = 0; f < turned.size(); ++f) {
        if (order != ReferenceOrder::kRayDepth || turned[f].model == CameraModel::kPinhole)
          pair.push_back(render_reference(scene, turned[f], reference_settings, order));
        step(what + ", turned view " + std::to_string(f));
      }
      if (pair.size() != turned.size()) return std::nullopt;
      return inconsistency_of(pair[0], pair[1]);
    };
    const TemporalDifference centre_order =
        *reference_pair_inconsistency(ReferenceOrder::kSettings, "float64 reference");
    report.reference_inconsistency = centre_order.flicker_fraction;
    report.reference_inconsistency_mean = centre_order.mean_abs;
    if (const auto exact =
            reference_pair_inconsistency(ReferenceOrder::kRayDepth, "float64 reference in exact ray order")) {
      report.exact_order_inconsistency = exact->flicker_fraction;
      report.exact_order_inconsistency_mean = exact->mean_abs;
    }
  }

  // The float64 reference's raster rule at each view, when a row draws with the raster compositor.
  std::vector<RenderImage> raster_references;
  if (std::any_of(rows.begin(), rows.end(),
                  [](const Row& row) { return row.compositor == Compositor::kRaster; })) {
    RenderSettings raster_rule = reference_settings;
    raster_rule.compositor = Compositor::kRaster;
    for (size_t v = 0; v < options.views.size(); ++v) {
      raster_references.push_back(render_reference(scene, options.views[v], raster_rule));
      step("float64 reference's raster rule, " + options.view_names[v]);
    }
  }

  renderer.set_scene(scene);
  for (const Row& row : rows) {
    const AccuracyModes& m = row.modes;
    ModeResult result;
    result.modes = m;
    result.compositor = row.compositor;
    result.name = row_name(row);
    result.psnr_vs_sorted_db = std::numeric_limits<double>::quiet_NaN();
    result.psnr_vs_rule_db = std::numeric_limits<double>::quiet_NaN();
    RenderSettings settings;
    settings.sort = options.sort;
    settings.depth = false;
    settings.splat_count = false;
    settings.accuracy = m;
    settings.compositor = row.compositor;
    settings.reuse_lists = false;  // the repeats time whole frames, not the composite on reused lists
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
        psnr_vs_rule_sum += compare_images(image, raster_references[v]).psnr_db;
      if (ray_order_references.size() == options.views.size())
        psnr_vs_ray_order_sum += compare_images(image, ray_order_references[v]).psnr_db;
      const ImageDifference difference = compare_images(image, references[v]);
      psnr_sum += difference.psnr_db;
      ssim_sum += ssim(image, references[v]);
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
    result.psnr_vs_ray_order_db = ray_order_references.size() == options.views.size()
                                      ? psnr_vs_ray_order_sum / double(options.views.size())
                                      : std::numeric_limits<double>::quiet_NaN();
    result.ssim = ssim_sum / double(options.views.size());

    // The path with each frame's depth (the timed frames leave it out).
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
          temporal_excess(frames[f - 1], frames[f], path_references[f - 1], path_references[f]).mean_abs / pairs;
    }
    for (size_t f = 2; f < frames.size(); ++f) {
      const TemporalDifference pops = popping(frames[f - 2], frames[f - 1], frames[f], kFlickerThreshold);
      result.pops += pops.flicker_fraction / double(frames.size() - 2);
      result.pop_mean += pops.mean_abs / double(frames.size() - 2);
    }
    for (size_t f = 1; f < frames.size(); ++f) {
      const TemporalDifference warped = warp_of(frames, f);
      result.warp_pops_per_step.push_back(warped.flicker_fraction);
      result.warp_pops += warped.flicker_fraction / double(frames.size() - 1);
      result.warp_mean += warped.mean_abs / double(frames.size() - 1);
    }
    if (!turned.empty()) {
      std::vector<RenderImage> pair;
      for (size_t f = 0; f < turned.size(); ++f) {
        pair.push_back(renderer.render(turned[f], settings));
        step(result.name + ", turned view " + std::to_string(f));
      }
      const TemporalDifference inconsistency = inconsistency_of(pair[0], pair[1]);
      result.inconsistency = inconsistency.flicker_fraction;
      result.inconsistency_mean = inconsistency.mean_abs;
    }
    report.modes.push_back(std::move(result));
  }
  return report;
}

// The PSNR against the sorted compositor's image, "-" for the sorted compositor's own rows.
std::string psnr_vs_sorted(const ModeResult& m) {
  return std::isnan(m.psnr_vs_sorted_db) ? "-" : cli::format_number(m.psnr_vs_sorted_db, 2);
}
std::string time_vs_sorted(const ModeResult& m) {
  return std::isnan(m.psnr_vs_sorted_db) || m.sorted_frame_ms <= 0
             ? "-"
             : cli::format_number(m.frame_ms / m.sorted_frame_ms, 2) + "x";
}
std::string psnr_vs_rule(const ModeResult& m) {
  return std::isnan(m.psnr_vs_rule_db) ? "-" : cli::format_number(m.psnr_vs_rule_db, 2);
}

std::string psnr_vs_ray_order(const ModeResult& m) {
  return std::isnan(m.psnr_vs_ray_order_db) ? "-" : cli::format_number(m.psnr_vs_ray_order_db, 2);
}

std::string text_table(const SceneReport& report) {
  std::string text =
      "  " + report.scene + ", " + report.description + ", " + report.views + "; float64 reference on the " +
      to_string(report.path) + ": " + cli::format_number(100.0 * report.reference_flicker, 3) +
      "% flicker, " + cli::format_number(100.0 * report.reference_pops, 3) + "% pops, " +
      cli::format_number(100.0 * report.reference_warp_pops, 3) + "% warped pops; turned " +
      cli::format_number(report.consistency_angle, 3) +
      " rad: " + cli::format_number(100.0 * report.reference_inconsistency, 3) + "% inconsistent" +
      (std::isnan(report.exact_order_inconsistency)
           ? std::string()
           : " (in the exact ray order " + cli::format_number(100.0 * report.exact_order_inconsistency, 3) +
                 "%)") +
      "\n";
  char line[512];
  std::snprintf(line, sizeof(line), "  %-58s %10s %8s %9s %8s %9s %10s %9s %9s %8s %8s %9s %8s %9s %8s %9s\n",
                "mode", "GPU ms", "vs ref", "PSNR dB", "SSIM", "max abs", "pairs", "flicker%", "excess",
                "pops%", "warp%", "incons%", "vs ray", "vs tiles", "t/tiles", "vs rule");
  text += line;
  const double reference_ms = report.modes.empty() ? 0 : report.modes.front().frame_ms;
  for (const auto& m : report.modes) {
    std::snprintf(
        line, sizeof(line), "  %-58s %10s %7sx %9s %8s %9s %10llu %9s %9s %8s %8s %9s %8s %9s %8s %9s\n",
        m.name.c_str(), cli::format_number(m.frame_ms, 2).c_str(),
        cli::format_number(reference_ms > 0 ? m.frame_ms / reference_ms : 0, 2).c_str(),
        cli::format_number(m.psnr_db, 2).c_str(), cli::format_number(m.ssim, 5).c_str(),
        cli::format_number(m.max_abs, 4).c_str(), static_cast<unsigned long long>(m.intersections),
        cli::format_number(100.0 * m.flicker, 3).c_str(), cli::format_number(m.excess, 5).c_str(),
        cli::format_number(100.0 * m.pops, 3).c_str(), cli::format_number(100.0 * m.warp_pops, 3).c_str(),
        cli::format_number(100.0 * m.inconsistency, 3).c_str(), psnr_vs_ray_order(m).c_str(),
        psnr_vs_sorted(m).c_str(), time_vs_sorted(m).c_str(), psnr_vs_rule(m).c_str());
    text += line;
  }
  return text;
}

std::string markdown(const std::vector<SceneReport>& reports, const DeviceInfo& device, const std::string& command) {
  std::string md = "Device: " + device.name + " (" + device.driver + "). Command:\n\n```\n" + command + "\n```\n";
  md +=
      "\nErrors are measured on the trained display values (sRGB-encoded, peak 1), as renders are compared "
      "with "
      "photographs (docs/colour.md).\n";
  for (const auto& report : reports) {
    md += "\n### " + report.scene + "\n\n" + report.description + "; " + report.views + ". Popping over a " +
          std::to_string(report.path_frames) + "-frame " + to_string(report.path) + " (step " +
          cli::format_fixed(report.path_step, 4) + "): the float64 reference itself changes " +
          cli::format_number(report.reference_change, 5) + " per frame on average, with " +
          cli::format_number(100.0 * report.reference_flicker, 3) + "% of pixels changing by more than " +
          cli::format_number(kFlickerThreshold, 2) + " (flicker), and " +
          cli::format_number(100.0 * report.reference_pops, 3) +
          "% of pixels popping: their second difference over three frames exceeds that (`popping()`, which "
          "smooth motion cancels). Warped pops: each frame warped onto the next by its rendered depth, "
          "what the motion reveals or hides left out, the share of " +
          std::to_string(kWarpBlock) + "x" + std::to_string(kWarpBlock) + " blocks differing by more than " +
          cli::format_number(kWarpThreshold, 2) + " (`depth_warp_difference()`; the float64 reference: " +
          cli::format_number(100.0 * report.reference_warp_pops, 3) +
          "%). PSNR vs exact ray order: against the float64 reference blending each pixel's splats in the "
          "order of their depth along its ray (`ReferenceOrder::kRayDepth`).";
    if (report.consistency_angle > 0)
      md += " View consistency: the first view and the same camera turned in place by " +
            cli::format_number(report.consistency_angle, 3) + " rad, rendered at " +
            std::to_string(kConsistencyScale) +
            "x its size; the first resampled onto the second and compared over blocks of " +
            std::to_string(kConsistencyBlock) + "x" + std::to_string(kConsistencyBlock) +
            " pixels (`rotation_inconsistency()`): the float64 reference has " +
            cli::format_number(100.0 * report.reference_inconsistency, 3) +
            "% of blocks differing by more than " + cli::format_number(kConsistencyThreshold, 2) +
            " (inconsistent %), and a mean difference of " +
            cli::format_number(report.reference_inconsistency_mean, 6) + "." +
            (std::isnan(report.exact_order_inconsistency)
                 ? std::string()
                 : " In the exact ray order it has " +
                       cli::format_number(100.0 * report.exact_order_inconsistency, 3) + "% (" +
                       cli::format_number(report.exact_order_inconsistency_mean, 6) +
                       "): not 0, since where two splats' ray depths cross within a pixel the blend order "
                       "flips, an edge the turned view's resampling does not reproduce.");
    md += "\n\n";
    md +=
        "| mode | GPU frame ms | vs reference | PSNR dB | SSIM | max abs | pairs | flicker % | excess change "
        "| pops % | warped pops % "
        "| inconsistent % | inconsistency | PSNR vs exact ray order dB | PSNR vs sorted compositor dB | time "
        "vs sorted compositor | PSNR vs own float64 rule dB |\n";
    md += "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    const double reference_ms = report.modes.empty() ? 0 : report.modes.front().frame_ms;
    for (const auto& m : report.modes)
      md += "| " + m.name + " | " + cli::format_number(m.frame_ms, 2) + " | " +
            cli::format_number(reference_ms > 0 ? m.frame_ms / reference_ms : 0, 2) + "x | " +
            cli::format_number(m.psnr_db, 2) + " | " + cli::format_number(m.ssim, 5) + " | " +
            cli::format_number(m.max_abs, 4) + " | " + std::to_string(m.intersections) + " | " +
            cli::format_number(100.0 * m.flicker, 3) + " | " + cli::format_number(m.excess, 5) + " | " +
            cli::format_number(100.0 * m.pops, 3) + " | " + cli::format_number(100.0 * m.warp_pops, 3) +
            " | " + cli::format_number(100.0 * m.inconsistency, 3) + " | " +
            cli::format_number(m.inconsistency_mean, 6) + " | " + psnr_vs_ray_order(m) + " | " +
            psnr_vs_sorted(m) + " | " + time_vs_sorted(m) + " | " + psnr_vs_rule(m) + " |\n";
    // Per-pass times: a column per mode would not fit; the passes whose time a mode changes.
    md += "\nPer-pass median GPU ms:\n\n| mode |";
    std::vector<std::string> names;
    for (const auto& m : report.modes)
      for (const auto& p : m.passes)
        if (std::find(names.begin(), names.end(), p.name) == names.end()) names.push_back(p.name);
    for (const auto& name : names) md += " " + name + " |";
    md += "\n|---|";
    for (size_t i = 0; i < names.size(); ++i) md += "---:|";
    md += "\n";
    for (const auto& m : report.modes) {
      md += "| " + m.name + " |";
      for (const auto& name : names) {
        auto it = std::find_if(m.passes.begin(), m.passes.end(), [&](const PassTime& p) { return p.name == name; });
        md += ' ';
        md += it == m.passes.end() ? std::string("-") : cli::format_number(it->ms, 2);
        md += " |";
      }
      md += "\n";
    }
  }
  return md;
}

std::string csv(const std::vector<SceneReport>& reports, const DeviceInfo& device) {
  std::string out =
      "device,scene,mode,gpu_frame_ms,psnr_db,ssim,max_abs,intersections,frame_change,flicker_fraction,"
      "excess_change,pop_fraction,pop_mean,inconsistent_fraction,inconsistency_mean,passes,psnr_vs_sorted_db,"
      "psnr_vs_rule_db,warp_pop_fraction,warp_pop_mean,psnr_vs_ray_order_db\n";
  for (const auto& report : reports)
    for (const auto& m : report.modes) {
      std::string passes;
      for (const auto& p : m.passes)
        passes += (passes.empty() ? "" : ";") + p.name + "=" + cli::format_number(p.ms, 4);
      out += cli::csv_field(device.name) + "," + cli::csv_field(report.scene) + "," + cli::csv_field(m.name) +
             "," + cli::format_number(m.frame_ms, 4) + "," + cli::format_number(m.psnr_db, 4) + "," +
             cli::format_number(m.ssim, 6) + "," + cli::format_number(m.max_abs, 6) + "," +
             std::to_string(m.intersections) + "," + cli::format_number(m.frame_change, 6) + "," +
             cli::format_number(m.flicker, 6) + "," + cli::format_number(m.excess, 6) + "," +
             cli::format_number(m.pops, 6) + "," + cli::format_number(m.pop_mean, 6) + "," +
             cli::format_number(m.inconsistency, 6) + "," + cli::format_number(m.inconsistency_mean, 6) +
             "," + cli::csv_field(passes) + "," +
             (std::isnan(m.psnr_vs_sorted_db) ? std::string() : cli::format_number(m.psnr_vs_sorted_db, 4)) +
             "," +
             (std::isnan(m.psnr_vs_rule_db) ? std::string() : cli::format_number(m.psnr_vs_rule_db, 4)) +
             "," + cli::format_number(m.warp_pops, 6) + "," + cli::format_number(m.warp_mean, 6) + "," +
             (std::isnan(m.psnr_vs_ray_order_db) ? std::string()
                                                 : cli::format_number(m.psnr_vs_ray_order_db, 4)) +
             "\n";
    }
  return out;
}

std::string consistency_svg(const SceneReport& report, const DeviceInfo& device) {
  plot::ScatterChart chart;
  chart.title = "View consistency against time: " + report.scene;
  chart.subtitle = report.description + ", turned in place by " +
                   cli::format_number(report.consistency_angle, 3) + " rad; float64 reference " +
                   cli::format_number(100.0 * report.reference_inconsistency, 3) + "%" +
                   (std::isnan(report.exact_order_inconsistency)
                        ? std::string()
                        : ", in exact ray order " +
                              cli::format_number(100.0 * report.exact_order_inconsistency, 3) + "%") +
                   "; " + device.name;
  chart.x_label = "median GPU frame time (ms, log scale)";
  chart.x_scale = plot::Scale::kLog10;
  chart.y_label = "blocks inconsistent under the turn (%)";
  chart.y_higher_is_better = false;
  for (size_t i = 0; i < report.modes.size(); ++i) {
    const auto& m = report.modes[i];
    chart.points.push_back({m.name, m.frame_ms, 100.0 * m.inconsistency, i});
  }
  return plot::scatter_svg(chart);
}

std::string pareto_svg(const SceneReport& report, const DeviceInfo& device) {
  plot::ScatterChart chart;
  chart.title = "Accuracy against time: " + report.scene;
  chart.subtitle = report.description + ", " + report.views + "; " + device.name;
  chart.x_label = "median GPU frame time (ms, log scale)";
  chart.x_scale = plot::Scale::kLog10;  // the re-sorting modes cost tens of times the others
  chart.y_label = "PSNR against the float64 reference (dB)";
  chart.y_higher_is_better = true;
  for (size_t i = 0; i < report.modes.size(); ++i) {
    const auto& m = report.modes[i];
    chart.points.push_back({m.name, m.frame_ms, m.psnr_db, i});
  }
  return plot::scatter_svg(chart);
}

std::string popping_svg(const SceneReport& report, const DeviceInfo& device) {
  plot::LineChart chart;
  chart.title = "Popping along the path: " + report.scene;
  chart.subtitle = report.description + ", " + std::to_string(report.path_frames) + "-frame " +
                   to_string(report.path) + " (step " + cli::format_fixed(report.path_step, 4) +
                   "), each frame warped onto the next by its depth; " + device.name;
  chart.x_label = "frame pair along the path";
  chart.y_label = "blocks differing after the warp (%)";
  auto series = [](const std::string& label, const std::vector<double>& per_step, size_t color, size_t dash) {
    plot::LineSeries line{label, color, dash, {}};
    for (size_t i = 0; i < per_step.size(); ++i) line.points.push_back({double(i + 1), 100.0 * per_step[i]});
    return line;
  };
  chart.series.push_back(series("float64 reference", report.reference_warp_pops_per_step, 0, 1));
  for (size_t i = 0; i < report.modes.size(); ++i)
    chart.series.push_back(series(report.modes[i].name, report.modes[i].warp_pops_per_step, i, 0));
  return plot::line_chart_svg(chart);
}

}  // namespace tilesplat::accuracy
