#include "effects_report.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numbers>

#include "cli.h"
#include "tilesplat/lens.h"
#include "tilesplat/scene_description.h"
#include "tilesplat/shutter.h"

namespace tilesplat::effects {

namespace {

std::string fixed(double value, int decimals) { return cli::format_fixed(value, decimals); }

// Pass names in frame order, over all rows (a row may have passes the others lack).
std::vector<std::string> pass_names(const std::vector<Row>& rows) {
  std::vector<std::string> names;
  for (const Row& row : rows)
    for (const PassTiming& pass : row.passes)
      if (std::find(names.begin(), names.end(), pass.name) == names.end()) names.push_back(pass.name);
  return names;
}

// "-" for a pass the row's frame does not run.
std::string pass_ms(const Row& row, const std::string& name) {
  for (const PassTiming& pass : row.passes)
    if (pass.name == name) return fixed(pass.gpu_ms, 3);
  return "-";
}

std::string row_label(const Row& row) {
  return row.scene_variant == SceneVariant::kScene ? row.name : row.name + " [" + to_string(row.scene_variant) + "]";
}

// Relative to the first row (the base), in percent.
std::string versus_base(const std::vector<Row>& rows, const Row& row) {
  const double base = rows.front().frame_ms;
  if (&row == &rows.front() || !(base > 0)) return "";
  const double percent = 100.0 * (row.frame_ms - base) / base;
  std::string text = percent >= 0 ? "+" : "";
  text += fixed(percent, 1);
  return text + "%";
}

}  // namespace

std::string to_string(SceneVariant variant) {
  switch (variant) {
    case SceneVariant::kScene: return "";
    case SceneVariant::kStoredSh0: return "stored SH0";
    case SceneVariant::kNoNormals: return "no normals";
    case SceneVariant::kPaddedSh3: return "padded to SH3";
  }
  return "";
}

GaussianScene make_variant(const GaussianScene& scene, SceneVariant variant) {
  switch (variant) {
    case SceneVariant::kScene: return scene;
    case SceneVariant::kStoredSh0: return with_sh_degree(scene, 0);
    case SceneVariant::kPaddedSh3: return with_sh_degree(scene, 3);
    case SceneVariant::kNoNormals: {
      GaussianScene copy = scene;
      copy.normals.clear();
      return copy;
    }
  }
  return scene;
}

Lighting bench_lighting(const GaussianScene& scene) {
  const Bounds bounds = compute_bounds(scene);
  Lighting lighting;
  lighting.ambient = {0.2f, 0.2f, 0.2f};
  Light sun;  // travels down (+y is down in the trainer's convention) and away from the default orbit
  sun.direction = {0.3f, 0.8f, 0.52f};
  const float norm = std::sqrt(0.3f * 0.3f + 0.8f * 0.8f + 0.52f * 0.52f);
  for (float& v : sun.direction) v /= norm;
  sun.color = {1.0f, 0.95f, 0.9f};
  Light lamp;
  lamp.type = Light::Type::kPoint;
  lamp.position = {float(bounds.center[0]), float(bounds.center[1] - bounds.radius), float(bounds.center[2])};
  lamp.color = {0.6f, 0.7f, 1.0f};
  lamp.intensity = float(bounds.radius * bounds.radius);  // about 1 at the scene's centre
  lighting.lights = {sun, lamp};
  return lighting;
}

DepthConvention bench_depth_convention() {
  constexpr double kNear = 0.05, kFar = 200;
  DepthConvention convention;  // d = a + b / z with d(near) = 0 and d(far) = 1
  convention.a = kFar / (kFar - kNear);
  convention.b = -kFar * kNear / (kFar - kNear);
  return convention;
}

std::vector<float> plane_through_scene(const GaussianScene& scene, const Camera& camera,
                                       const DepthConvention& convention) {
  const Bounds bounds = compute_bounds(scene);
  const double centre = camera.to_camera({bounds.center[0], bounds.center[1], bounds.center[2]})[2];
  const double nx = std::sin(35 * std::numbers::pi / 180), nz = std::cos(35 * std::numbers::pi / 180);
  std::vector<float> depth(size_t(camera.width) * size_t(camera.height));
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const double rx = (x + 0.5 - camera.cx) / camera.fx;  // the pixel's ray is (rx, ry, 1)
      const double t = nz * centre / (nx * rx + nz);        // where n . (t r) = n . (0, 0, centre)
      depth[size_t(y) * size_t(camera.width) + size_t(x)] =
          t > 0 ? float(convention.window_depth(t)) : float(convention.far_depth());
    }
  return depth;
}

std::vector<Row> plan_rows(const GaussianScene& scene, const RenderSettings& base_settings) {
  RenderSettings base = base_settings;
  base.accuracy.sh_degree_cap = 3;
  base.antialiasing = Antialiasing::kClassic;
  base.lighting = {};
  base.depth = false;
  base.splat_count = false;
  base.compositor = Compositor::kSorted;

  std::vector<Row> rows;
  auto add = [&](const std::string& name, SceneVariant variant, auto&& change) {
    Row row;
    row.name = name;
    row.scene_variant = variant;
    row.settings = base;
    change(row.settings);
    rows.push_back(std::move(row));
  };
  add("base (all off, SH" + std::to_string(scene.sh_degree) + ")", SceneVariant::kScene, [](RenderSettings&) {});
  for (int degree = 0; degree < scene.sh_degree; ++degree)
    add("sh" + std::to_string(degree), SceneVariant::kScene,
        [degree](RenderSettings& s) { s.accuracy.sh_degree_cap = degree; });
  if (scene.sh_degree > 0) add("sh0", SceneVariant::kStoredSh0, [](RenderSettings&) {});
  // A scene below SH3 is padded with zero bands to show what degree 3 would cost on this geometry.
  if (scene.sh_degree < 3) add("sh3", SceneVariant::kPaddedSh3, [](RenderSettings&) {});
  const Lighting lighting = bench_lighting(scene);
  add("lights: 1 directional + 1 point", SceneVariant::kScene, [&](RenderSettings& s) { s.lighting = lighting; });
  if (scene.has_normals()) add("lights off", SceneVariant::kNoNormals, [](RenderSettings&) {});
  add("antialiased", SceneVariant::kScene, [](RenderSettings& s) { s.antialiasing = Antialiasing::kAntialiased; });
  add("mip", SceneVariant::kScene, [](RenderSettings& s) { s.antialiasing = Antialiasing::kMip; });
  add("+depth", SceneVariant::kScene, [](RenderSettings& s) { s.depth = true; });
  add("+splat count", SceneVariant::kScene, [](RenderSettings& s) { s.splat_count = true; });
  add("+depth +splat count", SceneVariant::kScene, [](RenderSettings& s) { s.depth = s.splat_count = true; });
  // Not an effect but the other side of the sort's cost: no depth sort, one hashed sample per pixel.
  // (The modes that reorder by depth have no stochastic form.)
  if (compositor_draws(Compositor::kStochastic, base.accuracy)) {
    add("stochastic, 1 frame", SceneVariant::kScene, [](RenderSettings& s) {
      s.compositor = Compositor::kStochastic;
      s.stochastic.frames = 1;
    });
    // A host's depth in (a plane through the scene) and out; "no host depth" is the base row.
    add("host depth in + out (a plane through the scene)", SceneVariant::kScene, [](RenderSettings&) {});
    rows.back().host_plane = true;
    // The third compositor: the same depth sort, the splats drawn and blended by the graphics pipeline;
    // with a host's depth as its depth attachment, and with the splats' depth out too (its fragments
    // read the running alpha).
    add("raster compositor", SceneVariant::kScene,
        [](RenderSettings& s) { s.compositor = Compositor::kRaster; });
    add("raster, host depth in (a plane through the scene)", SceneVariant::kScene,
        [](RenderSettings& s) { s.compositor = Compositor::kRaster; });
    rows.back().host_plane = true;
    rows.back().host_depth_out = false;
    add("raster, host depth in + out (a plane through the scene)", SceneVariant::kScene,
        [](RenderSettings& s) { s.compositor = Compositor::kRaster; });
    rows.back().host_plane = true;
  }

  // The camera models, each of the view's pose and size; the per-pixel re-sorting is the pinhole's.
  if (base.accuracy.resort_window == 0) {
    const Bounds bounds = compute_bounds(scene);
    const std::array<double, 3> centre = {bounds.center[0], bounds.center[1], bounds.center[2]};
    auto camera_row = [&](const std::string& name, std::function<Camera(const Camera&)> camera) {
      add(name, SceneVariant::kScene, [](RenderSettings&) {});
      rows.back().camera = std::move(camera);
    };
    camera_row("camera: opencv (k1 -0.1, k2 0.02, p1 0.001, p2 -0.001)", [](const Camera& view) {
      Camera camera = view;
      camera.model = CameraModel::kOpenCV;
      camera.distortion = {-0.1, 0.02, 0.001, -0.001, 0, 0, 0, 0};
      return camera;
    });
    camera_row("camera: opencv, all coefficients 0 (off)", [](const Camera& view) {
      Camera camera = view;
      camera.model = CameraModel::kOpenCV;
      return camera;
    });
    camera_row("camera: fisheye, 180 degrees", [](const Camera& view) { return fisheye_camera(view, 180); });
    camera_row("camera: orthographic, the view's framing", [centre](const Camera& view) {
      // As tall as the pinhole's view is at the scene's centre.
      return orthographic_camera(view, 2 * view.to_camera(centre)[2] * view.tan_half_fov_y());
    });
    camera_row("camera: equirectangular, 360x180 in the view's size",
               [](const Camera& view) { return equirectangular_camera(view); });
    // The averaged frames: 8 samples each, so about 8 frames' time; off (no aperture, a closed shutter)
    // the base frame.
    add("depth of field, aperture 0 (off)", SceneVariant::kScene,
        [](RenderSettings& s) { s.lens = {.aperture_diameter = 0, .focus_distance = 1, .samples = 8}; });
    add("motion blur, shutter closed (off)", SceneVariant::kScene, [](RenderSettings&) {});
    rows.back().for_view = [centre](RenderSettings& settings, const Camera& view) {
      settings.shutter = {.open = 0.5,
                          .close = 0.5,
                          .samples = 8,
                          .end_camera = turn_camera(view, centre, {0, -1, 0}, 5 * std::numbers::pi / 180)};
    };
    add("depth of field, 8 lens samples", SceneVariant::kScene, [](RenderSettings&) {});
    rows.back().for_view = [centre](RenderSettings& settings, const Camera& view) {
      const double focus = view.to_camera(centre)[2];
      settings.lens = {.aperture_diameter = 0.05 * focus, .focus_distance = focus, .samples = 8};
    };
    add("motion blur, 8 time samples (5 degrees of orbit)", SceneVariant::kScene, [](RenderSettings&) {});
    rows.back().for_view = [centre](RenderSettings& settings, const Camera& view) {
      settings.shutter = {.open = 0,
                          .close = 1,
                          .samples = 8,
                          .end_camera = turn_camera(view, centre, {0, -1, 0}, 5 * std::numbers::pi / 180)};
    };
    // The same motion read out in 8 bands of rows, each a region of the image at its time: the projection
    // 8 times, the rest about once.
    add("rolling shutter, 8 bands top to bottom (5 degrees of orbit)", SceneVariant::kScene,
        [](RenderSettings&) {});
    rows.back().for_view = [centre](RenderSettings& settings, const Camera& view) {
      settings.shutter = {.open = 0,
                          .close = 1,
                          .samples = 8,
                          .end_camera = turn_camera(view, centre, {0, -1, 0}, 5 * std::numbers::pi / 180),
                          .scan = ShutterScan::kTopToBottom};
    };
  }
  return rows;
}

int work_units(const std::vector<Row>& rows, const Options& options) {
  return int(rows.size() * options.views.size()) * (options.warmup + options.repeat);
}

Run measure(const RendererOptions& renderer_options, const GaussianScene& scene, std::vector<Row>& rows,
            const Options& options, const std::function<void(int, int, const std::string&)>& progress) {
  // One renderer per scene variant, each holding its scene, so that rows interleave without uploads; and
  // one more for the raster rows of each: on Mesa 22's lavapipe, once a renderer has drawn through the
  // graphics pipeline its later compute frames read their timestamps late (a sorted frame's composite
  // then shows under tile_ranges), while frame totals stay right.
  using RendererKey = std::pair<SceneVariant, bool>;
  auto key_of = [](const Row& row) {
    return RendererKey{row.scene_variant, row.settings.compositor == Compositor::kRaster};
  };
  std::map<RendererKey, std::unique_ptr<Renderer>> renderers;
  for (const Row& row : rows) {
    if (renderers.count(key_of(row))) continue;
    auto renderer = Renderer::create(renderer_options);
    if (row.scene_variant == SceneVariant::kScene)
      renderer->set_scene(scene);
    else
      renderer->set_scene(make_variant(scene, row.scene_variant));
    renderers.emplace(key_of(row), std::move(renderer));
  }

  // The host's plane as each view sees it, for the host depth rows.
  std::vector<std::vector<float>> planes;
  for (const Camera& view : options.views)
    planes.push_back(plane_through_scene(scene, view, bench_depth_convention()));

  const int total = work_units(rows, options);
  int done = 0;
  // samples[row][view][pass name] and frame times, over the repeats.
  std::vector<std::vector<std::map<std::string, std::vector<double>>>> pass_samples(
      rows.size(), std::vector<std::map<std::string, std::vector<double>>>(options.views.size()));
  std::vector<std::vector<std::vector<double>>> frame_samples(rows.size(),
                                                              std::vector<std::vector<double>>(options.views.size()));
  std::vector<std::vector<std::string>> pass_order(rows.size());  // as the renderer reports them
  for (int frame = 0; frame < options.warmup + options.repeat; ++frame) {
    for (size_t r = 0; r < rows.size(); ++r) {
      Renderer& renderer = *renderers.at(key_of(rows[r]));
      RenderSettings settings = rows[r].settings;
      settings.sort = options.sort;
      settings.reuse_lists = false;  // whole frames: consecutive rows often share the camera and lists
      for (size_t v = 0; v < options.views.size(); ++v) {
        if (rows[r].host_plane)
          settings.host = HostDepth{bench_depth_convention(), planes[v], rows[r].host_depth_out, 0.5f};
        const Camera view = rows[r].camera ? rows[r].camera(options.views[v]) : options.views[v];
        if (rows[r].for_view) rows[r].for_view(settings, view);
        renderer.render(view, settings);
        const FrameStats& stats = renderer.last_frame_stats();
        if (frame == 0 && v == 0) rows[r].device_bytes = stats.device_bytes;
        if (frame >= options.warmup) {
          frame_samples[r][v].push_back(stats.gpu_ms);
          for (const PassTiming& pass : stats.passes) {
            pass_samples[r][v][pass.name].push_back(pass.gpu_ms);
            auto& order = pass_order[r];
            if (std::find(order.begin(), order.end(), pass.name) == order.end()) order.push_back(pass.name);
          }
        }
        progress(++done, total, row_label(rows[r]));
      }
    }
  }
  for (size_t r = 0; r < rows.size(); ++r) {
    std::vector<double> frame_medians;
    std::map<std::string, std::vector<double>> pass_medians;
    for (size_t v = 0; v < options.views.size(); ++v) {
      frame_medians.push_back(cli::median(frame_samples[r][v]));
      for (const auto& [name, samples] : pass_samples[r][v]) pass_medians[name].push_back(cli::median(samples));
    }
    rows[r].frame_ms = cli::median(frame_medians);
    rows[r].passes.clear();
    for (const std::string& name : pass_order[r]) rows[r].passes.push_back({name, cli::median(pass_medians[name])});
  }
  Run run;
  run.device = renderers.begin()->second->device_info();
  for (const auto& [variant, renderer] : renderers) run.validation_messages += renderer->validation_messages();
  return run;
}

std::string text_table(const std::vector<Row>& rows) {
  const std::vector<std::string> passes = pass_names(rows);
  size_t label_width = 10;
  for (const Row& row : rows) label_width = std::max(label_width, row_label(row).size());
  std::string out;
  auto cell = [](const std::string& text, size_t width) {
    return std::string(width > text.size() ? width - text.size() : 0, ' ') + text;
  };
  std::string header = "effect" + std::string(label_width - 6, ' ');
  for (const auto& name : passes) header += cell(name, std::max<size_t>(name.size(), 8) + 2);
  header += cell("frame ms", 10) + cell("vs base", 9) + cell("MiB", 9);
  out += header + "\n";
  for (const Row& row : rows) {
    const std::string label = row_label(row);
    std::string line = label + std::string(label_width - label.size(), ' ');
    for (const auto& name : passes) line += cell(pass_ms(row, name), std::max<size_t>(name.size(), 8) + 2);
    line += cell(fixed(row.frame_ms, 3), 10) + cell(versus_base(rows, row), 9) +
            cell(fixed(double(row.device_bytes) / (1024.0 * 1024.0), 1), 9);
    out += line + "\n";
  }
  return out;
}

std::string markdown(const std::vector<Row>& rows, const std::string& scene, const DeviceInfo& device,
                     const std::string& command) {
  const std::vector<std::string> passes = pass_names(rows);
  std::string out = "# Effect costs: " + scene + "\n\n";
  out += "Device: " + device.name + " (driver " + device.driver + "). Command: `" + command + "`.\n\n";
  out += "GPU ms per pass (median over repeats, then views). `[stored SH0]` and `[no normals]` rows render a "
         "scene that never had the effect, beside the row that turns it off.\n\n| effect |";
  for (const auto& name : passes) out += " " + name + " |";
  out += " frame ms | vs base | device MiB |\n|---|";
  for (size_t i = 0; i < passes.size(); ++i) out += "---:|";
  out += "---:|---:|---:|\n";
  for (const Row& row : rows) {
    // Appended piece by piece: GCC 12 warns (-Wrestrict, falsely) about "literal" + std::string.
    std::vector<std::string> cells = {row_label(row)};
    for (const auto& name : passes) cells.push_back(pass_ms(row, name));
    cells.push_back(fixed(row.frame_ms, 3));
    cells.push_back(versus_base(rows, row));
    cells.push_back(fixed(double(row.device_bytes) / (1024.0 * 1024.0), 1));
    out += "|";
    for (const std::string& text : cells) {
      out += ' ';
      out += text;
      out += " |";
    }
    out += '\n';
  }
  return out;
}

std::string csv(const std::vector<Row>& rows, const std::string& scene, const DeviceInfo& device) {
  std::string out = "device,scene,effect,scene_variant,pass,gpu_ms\n";
  for (const Row& row : rows) {
    const std::string prefix =
        cli::csv_field(device.name) + "," + cli::csv_field(scene) + "," + cli::csv_field(row.name) + "," +
        cli::csv_field(to_string(row.scene_variant)) + ",";
    for (const PassTiming& pass : row.passes) out += prefix + cli::csv_field(pass.name) + "," + fixed(pass.gpu_ms, 4) + "\n";
    out += prefix + "frame," + fixed(row.frame_ms, 4) + "\n";
    out += prefix + "device_mib," + fixed(double(row.device_bytes) / (1024.0 * 1024.0), 3) + "\n";
  }
  return out;
}

}  // namespace tilesplat::effects
