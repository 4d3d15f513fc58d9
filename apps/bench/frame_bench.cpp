#include "frame_bench.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "bench_plot.h"
#include "progress.h"
#include "tilesplat/gradients.h"
#include "tilesplat/sort.h"

namespace tilesplat::bench {

namespace cli = tilesplat::cli;
namespace fs = std::filesystem;
namespace plot = tilesplat::plot;

namespace {

// Where the scene's cameras come from, for the JSON: --cameras, the scene file's own, or null (orbit).
std::string cameras_source(const BenchScene& scene) {
  if (!scene.cameras.empty()) return scene.cameras;
  const cli::SceneViews own = cli::scene_views(scene.loaded);
  return own.views.empty() ? std::string() : own.file.string();
}

std::string size_of(const Case& c) {
  return cli::format_size(c.camera.camera.width, c.camera.camera.height);
}

// "320x180"; without --resolutions or --width/--height, views of a cameras.json keep their own sizes,
// which need not agree.
std::string size_label(const Group& group) {
  const std::string first = size_of(*group.cases.front());
  for (const Case* c : group.cases)
    if (size_of(*c) != first) return "each view's own size";
  return first;
}

std::string orbit_label(double azimuth_deg) {
  return "azimuth " + cli::format_fixed(azimuth_deg, 1);
}

// The statistics of a training step: the forward frame render() just drew, then its backward on the
// forward's lists (a fixed random colour gradient), whose passes and GPU time are added to the frame's.
tilesplat::FrameStats with_backward(tilesplat::Renderer& renderer, const tilesplat::Camera& camera,
                                    tilesplat::RenderSettings settings) {
  tilesplat::FrameStats step = renderer.last_frame_stats();
  static std::vector<float> gradients;
  const size_t values = size_t(camera.width) * size_t(camera.height) * 3;
  if (gradients.size() != values) {
    gradients.resize(values);
    uint32_t state = 12345u;
    for (float& g : gradients) {
      state = state * 1664525u + 1013904223u;  // a fixed sequence: every run times the same work
      g = float(state >> 8) / float(1u << 24) * 2.0f - 1.0f;
    }
  }
  settings.reuse_lists = true;
  const auto start = std::chrono::steady_clock::now();
  renderer.backward(camera, settings, tilesplat::FrameGradients{gradients, {}, {}, {}});
  const double backward_cpu_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  for (const tilesplat::PassTiming& pass : renderer.last_frame_stats().passes) {
    step.passes.push_back(pass);
    step.gpu_ms += pass.gpu_ms;
  }
  step.cpu_ms += backward_cpu_ms;
  return step;
}

// Per metric, one sample per view: that view's median. Summarized, they give the median, min and
// max over the views of a path.
StrategyResult over_views(const std::vector<const Case*>& cases, size_t sort) {
  StrategyResult summary;
  summary.sort = cases.front()->results[sort].sort;
  for (const Case* c : cases) {
    const StrategyResult& result = c->results[sort];
    for (const auto& row : result.passes)
      find_series(summary.passes, row.name, row.kind, row.unit)
          .samples.push_back(summarize(row.samples).median);
    for (const auto& row : result.frame)
      find_series(summary.frame, row.name, row.kind, row.unit)
          .samples.push_back(summarize(row.samples).median);
  }
  return summary;
}

std::vector<Group> group_cases(const std::vector<Case>& cases, size_t sort_count) {
  std::vector<Group> groups;
  for (const auto& c : cases) {
    if (groups.empty() || groups.back().cases.front()->scene != c.scene ||
        groups.back().cases.front()->size != c.size)
      groups.emplace_back();
    groups.back().cases.push_back(&c);
  }
  for (auto& group : groups)
    for (size_t sort = 0; sort < sort_count; ++sort)
      group.over_views.push_back(over_views(group.cases, sort));
  return groups;
}

void print_table(const StrategyResult& result, const std::string& heading) {
  std::printf("\nsort %s: %s\n", result.sort.c_str(), heading.c_str());
  size_t name_width = 20;
  for (const auto* rows : {&result.passes, &result.frame})
    for (const auto& row : *rows) name_width = std::max(name_width, row.name.size());
  const int width = static_cast<int>(name_width);
  std::printf("  %-*s %-4s %12s %12s %12s\n", width, "metric", "unit", "median", "min", "max");
  for (const auto* rows : {&result.passes, &result.frame}) {
    for (const auto& row : *rows) {
      const Summary summary = summarize(row.samples);
      std::printf("  %-*s %-4s %12s %12s %12s\n", width, row.name.c_str(), unit_name(row.unit),
                  format_value(summary.median, row.unit).c_str(), format_value(summary.min, row.unit).c_str(),
                  format_value(summary.max, row.unit).c_str());
    }
  }
}

void print_comparison(const std::vector<StrategyResult>& results, const std::string& what) {
  if (results.size() < 2) return;
  size_t fastest = 0;
  for (size_t i = 1; i < results.size(); ++i)
    if (median_of(results[i].frame, "gpu frame") < median_of(results[fastest].frame, "gpu frame"))
      fastest = i;
  std::printf("\nsort comparison (%s):\n", what.c_str());
  for (size_t i = 0; i < results.size(); ++i)
    std::printf("  %-20s %12s ms%s\n", results[i].sort.c_str(),
                cli::format_fixed(median_of(results[i].frame, "gpu frame"), 3).c_str(),
                i == fastest ? "  (fastest)" : "");
}

// "(51.258..52.382)"
std::string min_max(const Summary& summary) {
  std::string text = "(";
  text += cli::format_fixed(summary.min, 3) + ".." + cli::format_fixed(summary.max, 3) + ")";
  return text;
}

// One group on stdout. A single camera gets the full table per sort; a path of several gets a line
// per view and sort, then the full tables over the views, so that it stays readable at any length.
void print_group(const Group& group, const BenchScene& scene, const BenchOptions& options) {
  const std::string frames =
      std::to_string(options.repeat) + " frames after " + std::to_string(options.warmup) + " warm-up";
  if (group.cases.size() == 1) {
    const Case& c = *group.cases.front();
    std::printf("\n== %s at %s, %s ==\n", scene.name.c_str(), size_label(group).c_str(),
                c.camera.description.c_str());
    for (const auto& result : c.results) print_table(result, frames);
    print_comparison(c.results, "median gpu frame");
    return;
  }

  const size_t views = group.cases.size();
  std::printf("\n== %s at %s: %zu views, %s each ==\n", scene.name.c_str(), size_label(group).c_str(), views,
              frames.c_str());
  size_t label_width = 8;
  for (const Case* c : group.cases) label_width = std::max(label_width, c->view_label.size());
  const int lw = static_cast<int>(label_width);
  std::printf("  %-*s %-12s %12s  %-20s %12s %14s\n", lw, "view", "sort", "gpu frame ms", "(min..max)",
              "cpu ms", "intersections");
  for (const Case* c : group.cases) {
    for (const auto& result : c->results) {
      const Series* gpu = find_series(result.frame, "gpu frame");
      const Summary s = gpu ? summarize(gpu->samples) : Summary{};
      std::printf("  %-*s %-12s %12s  %-20s %12s %14s\n", lw, c->view_label.c_str(), result.sort.c_str(),
                  cli::format_fixed(s.median, 3).c_str(), min_max(s).c_str(),
                  cli::format_fixed(median_of(result.frame, "cpu frame"), 3).c_str(),
                  cli::format_fixed(median_of(result.frame, "intersections"), 0).c_str());
    }
  }
  const std::string over =
      "median, min and max over the " + std::to_string(views) + " views of each view's median";
  for (const auto& summary : group.over_views) print_table(summary, over);
  print_comparison(group.over_views, "median over the views of the median gpu frame");
}

// One CSV line per metric: the rows of each camera ("frames": statistics over the measured
// frames), then with a path of several views the rows over its views (view "all").
std::string make_csv(const std::vector<Group>& groups, const std::vector<BenchScene>& scenes,
                     const tilesplat::DeviceInfo& device) {
  std::string csv =
      "device,scene,width,height,view,camera,sort,kind,metric,unit,over,median,min,max,samples\n";
  auto add = [&](const std::string& scene, const std::string& width, const std::string& height,
                 const std::string& view, const std::string& camera, const StrategyResult& result,
                 const char* over) {
    for_each_metric(result, [&](const Series& row) {
      const Summary summary = summarize(row.samples);
      csv += cli::csv_field(device.name) + "," + cli::csv_field(scene) + "," + width + "," + height + "," +
             cli::csv_field(view) + "," + cli::csv_field(camera) + "," + cli::csv_field(result.sort) + "," +
             row.kind + "," + cli::csv_field(row.name) + "," + unit_name(row.unit) + "," + over + "," +
             number_text(summary.median) + "," + number_text(summary.min) + "," + number_text(summary.max) +
             "," + std::to_string(row.samples.size()) + "\n";
    });
  };
  for (const auto& group : groups) {
    const std::string& scene = scenes[group.cases.front()->scene].loaded.path.string();
    for (const Case* c : group.cases)
      for (const auto& result : c->results)
        add(scene, std::to_string(c->camera.camera.width), std::to_string(c->camera.camera.height),
            c->view_label, c->camera.description, result, "frames");
    if (group.cases.size() < 2) continue;
    const Case& first = *group.cases.front();
    const bool one_size = size_label(group) == size_of(first);
    const std::string width = one_size ? std::to_string(first.camera.camera.width) : "";
    const std::string height = one_size ? std::to_string(first.camera.camera.height) : "";
    for (const auto& summary : group.over_views)
      add(scene, width, height, "all", std::to_string(group.cases.size()) + " views", summary, "views");
  }
  return csv;
}

Json json_metrics(const StrategyResult& result, bool with_samples) {
  Json metrics = Json::array();
  for_each_metric(result, [&](const Series& row) {
    const Summary summary = summarize(row.samples);
    Json metric = {{"name", row.name},
                   {"kind", row.kind},
                   {"unit", unit_name(row.unit)},
                   {"median", json_number(summary.median)},
                   {"min", json_number(summary.min)},
                   {"max", json_number(summary.max)}};
    if (with_samples) {
      Json samples = Json::array();
      for (const double sample : row.samples) samples.push_back(json_number(sample));
      metric["samples"] = std::move(samples);
    }
    metrics.push_back(std::move(metric));
  });
  return metrics;
}

// "results": one entry per camera and sort, every sample included; "summaries" (for paths of several
// views, like the CSV's view "all"): per scene, size and sort, the median, min and max over the views
// of each view's median.
std::string make_json(const std::vector<Group>& groups, const std::vector<BenchScene>& scenes,
                      const tilesplat::DeviceInfo& device, const BenchOptions& options) {
  Json json;
  add_provenance(json, "tilesplat-bench", options.command);
  json["device"] = json_device(device);
  json["warmup"] = options.warmup;
  json["repeat"] = options.repeat;
  Json& scene_list = json["scenes"] = Json::array();
  for (const auto& scene : scenes) {
    const std::string cameras = cameras_source(scene);
    scene_list.push_back({{"path", scene.loaded.path.string()},
                          {"gaussians", scene.gaussians},
                          {"sh_degree", scene.sh_degree},
                          {"cameras", cameras.empty() ? Json(nullptr) : Json(cameras)}});
  }
  Json& results = json["results"] = Json::array();
  for (const auto& group : groups)
    for (const Case* c : group.cases)
      for (const auto& result : c->results)
        results.push_back({{"scene", scenes[c->scene].loaded.path.string()},
                           {"width", c->camera.camera.width},
                           {"height", c->camera.camera.height},
                           {"view", c->view_label},
                           {"camera", c->camera.description},
                           {"sort", result.sort},
                           {"metrics", json_metrics(result, true)}});
  Json& summaries = json["summaries"] = Json::array();
  for (const auto& group : groups) {
    if (group.cases.size() < 2) continue;
    const Case& c = *group.cases.front();
    for (const auto& summary : group.over_views)
      summaries.push_back({{"scene", scenes[c.scene].loaded.path.string()},
                           {"size", size_label(group)},
                           {"views", group.cases.size()},
                           {"sort", summary.sort},
                           {"metrics", json_metrics(summary, false)}});
  }
  return json.dump(2) + "\n";
}

// A bar per scene, size and sort; its segments are the passes of the frame stats (the median over
// the views of each view's median), in frame order.
std::string make_frame_svg(const std::vector<Group>& groups, const std::vector<BenchScene>& scenes,
                           const tilesplat::DeviceInfo& device, const BenchOptions& options) {
  plot::StackedBarChart chart;
  std::vector<std::string> scene_names;
  std::vector<std::string> sizes;
  for (const auto& group : groups) {
    add_unique(scene_names, scenes[group.cases.front()->scene].name);
    add_unique(sizes, size_label(group));
    for (const auto& summary : group.over_views)
      for (const auto& pass : summary.passes) add_unique(chart.segments, pass.name);
  }
  chart.title = "GPU time per pass: " + join(scene_names) + " at " + join(sizes);
  std::string cameras;
  if (groups.size() == 1 && groups.front().cases.size() == 1)
    cameras = groups.front().cases.front()->camera.description;
  else
    cameras = "median over each path's views";
  chart.subtitle = device_line(device) + "; " + cameras + "; median of " + std::to_string(options.repeat) +
                   " frames after " + std::to_string(options.warmup) + " warm-up";
  chart.axis_label = "GPU time (ms)";
  for (const auto& group : groups) {
    const Case& first = *group.cases.front();
    std::string heading;
    if (groups.size() > 1) {
      heading = scenes[first.scene].name + ", " + size_label(group);
      heading += group.cases.size() == 1 ? ", " + first.camera.description
                                         : ", " + std::to_string(group.cases.size()) + " views";
    }
    for (const auto& summary : group.over_views) {
      plot::StackedBar bar;
      bar.group = heading;
      bar.label = summary.sort;
      for (const auto& segment : chart.segments) {
        const Series* pass = find_series(summary.passes, segment);
        bar.values.push_back(pass ? summarize(pass->samples).median : 0);
      }
      bar.note = "gpu frame " + cli::format_fixed(median_of(summary.frame, "gpu frame"), 1) + " ms";
      chart.bars.push_back(std::move(bar));
    }
  }
  return plot::stacked_bar_svg(chart);
}

}  // namespace

// The cameras of one scene: views of its cameras.json, or orbit positions evenly spaced in azimuth,
// each at every size. Out-of-range views and sizes fail here, before anything is measured.
std::vector<Case> plan_cases(const BenchOptions& options, const BenchScene& scene, size_t scene_index,
                             const std::vector<cli::ImageSize>& sizes) {
  std::vector<Case> cases;
  // Each view through --fisheye, --orthographic or --equirectangular where one is given, named so.
  auto add = [&](size_t size_index, std::string label, cli::NamedCamera camera) {
    if (options.camera_model.enabled()) {
      camera.camera = cli::camera_for_frame(options.camera_model, camera.camera);
      label += std::string(" ") + tilesplat::camera_model_name(camera.camera.model);
      camera.description += std::string(", ") + tilesplat::camera_model_name(camera.camera.model);
    }
    cases.push_back({scene_index, size_index, std::move(label), std::move(camera), {}});
  };
  const cli::SceneViews own = cli::scene_views(scene.loaded);
  if (!scene.cameras.empty() || !own.views.empty()) {
    const auto file_views = scene.cameras.empty() ? own.views : cli::load_camera_views(scene.cameras);
    const fs::path views_file = scene.cameras.empty() ? own.file : fs::path(scene.cameras);
    if (scene.cameras.empty() && (options.orbit > 0 || options.common.orbit_given))
      throw cli::UsageError(
          "--orbit, --azimuth, --elevation, --fov and --distance apply only to orbit cameras, and '" +
          scene.loaded.path.string() + "' has cameras of its own (pick them with --view or --views)");
    std::vector<int> indices = options.views;
    if (options.all_views) {
      indices.resize(file_views.size());
      std::iota(indices.begin(), indices.end(), 0);
    } else if (indices.empty()) {
      indices = {options.common.view};
    }
    const char* flag = options.views.empty() && !options.all_views ? "--view" : "--views";
    for (size_t s = 0; s < sizes.size(); ++s)
      for (const int index : indices)
        add(s, "view " + std::to_string(index),
            cli::view_camera(file_views, index, views_file, sizes[s].width, sizes[s].height, flag));
  } else {
    if (!options.views.empty() || options.all_views || options.common.view_given)
      throw cli::UsageError(
          std::string(options.common.view_given ? "--view" : "--views") + " needs cameras: '" +
          scene.loaded.path.string() +
          "' has none, and no --cameras FILE.json was given (without them the cameras orbit it)");
    const int count = std::max(1, options.orbit);
    for (size_t s = 0; s < sizes.size(); ++s) {
      for (int v = 0; v < count; ++v) {
        tilesplat::OrbitParams orbit = options.common.orbit;
        orbit.azimuth_deg = std::fmod(orbit.azimuth_deg + 360.0 * v / count, 360.0);
        add(s, orbit_label(orbit.azimuth_deg),
            cli::orbit_view(scene.loaded, sizes[s].width, sizes[s].height, orbit));
      }
    }
  }
  return cases;
}

// With "auto" among the sorts: which strategy it stands for on this device (its rows are labelled auto).
void print_auto_choice(const tilesplat::Renderer& renderer, const std::vector<std::string>& sorts) {
  if (std::find(sorts.begin(), sorts.end(), "auto") != sorts.end())
    std::printf("auto    sorts with %s on this device\n", renderer.sort_strategy_for("auto").c_str());
}

int run_frame_bench(const BenchOptions& options) {
  check_outputs(options, scene_and_camera_inputs(options));

  std::vector<std::string> sorts = options.common.sorts;
  if (sorts.empty()) sorts = tilesplat::sort_strategies();
  if (sorts.empty()) sorts = {tilesplat::RenderSettings{}.sort};
  std::vector<cli::ImageSize> sizes = options.resolutions;
  if (sizes.empty()) sizes = {{options.common.width, options.common.height}};

  // Every scene and camera first: a bad file or view fails now, not after an hour of measuring.
  std::vector<BenchScene> scenes;
  std::vector<Case> cases;
  for (size_t s = 0; s < options.common.scenes.size(); ++s) {
    BenchScene scene;
    scene.loaded = cli::load_scene_file(options.common.scenes[s], options.common.strict, kProgram,
                                        cli::SceneHolding::kMerged, options.common.lod);
    scene.name = scene.loaded.path.filename().string();
    scene.description = cli::describe_scene(scene.loaded.scene);
    scene.gaussians = scene.loaded.scene.size();
    scene.sh_degree = scene.loaded.scene.sh_degree;
    const auto& cameras = options.common.cameras_files;
    if (!cameras.empty()) scene.cameras = cameras.size() == 1 ? cameras.front() : cameras[s];
    auto scene_cases = plan_cases(options, scene, s, sizes);
    cases.insert(cases.end(), std::make_move_iterator(scene_cases.begin()),
                 std::make_move_iterator(scene_cases.end()));
    scenes.push_back(std::move(scene));
  }

  const auto renderer = tilesplat::Renderer::create(cli::renderer_options(options.common));
  const tilesplat::DeviceInfo device = renderer->device_info();
  for (const auto& scene : scenes)
    std::printf("scene   %s: %s, loaded in %s ms\n", scene.name.c_str(), scene.description.c_str(),
                cli::format_fixed(scene.loaded.load_ms, 1).c_str());
  std::printf("device  %s (driver %s), subgroup size %u\n", device.name.c_str(), device.driver.c_str(),
              device.subgroup_size);
  const int frames_per_row = options.warmup + options.repeat;
  const int rows = static_cast<int>(cases.size() * sorts.size());
  const int total_frames = frames_per_row * rows;
  print_auto_choice(*renderer, sorts);
  std::printf("frames  %d warm-up + %d measured per camera and sort; %zu cameras x %zu sorts, %d frames\n",
              options.warmup, options.repeat, cases.size(), sorts.size(), total_frames);
  std::fflush(stdout);

  const auto start = std::chrono::steady_clock::now();
  {
    cli::FrameProgress progress(kProgram, total_frames, cli::progress_style(false));
    int done = 0;
    std::vector<tilesplat::RenderImage> images;  // per strategy, of the current camera
    for (size_t i = 0; i < cases.size(); ++i) {
      Case& c = cases[i];
      BenchScene& scene = scenes[c.scene];
      // One renderer for the whole run: set_scene replaces the scene, once per scene. Under a memory
      // budget every frame takes the scene instead (in parts where it does not fit).
      const bool budgeted = options.memory_budget > 0;
      if (!budgeted && (i == 0 || cases[i - 1].scene != c.scene)) renderer->set_scene(scene.loaded.scene);
      const std::string where = scene.name + " " + size_of(c) + " " + c.view_label + " ";
      for (const auto& sort : sorts) {
        tilesplat::RenderSettings settings = cli::base_render_settings(options.common, scene.loaded);
        settings.sort = sort;
        settings.reuse_lists =
            false;  // every measured frame is a whole frame, not a composite on reused lists
        settings.memory_budget = options.memory_budget;
        Collector collector(sort);
        for (int frame = 0; frame < frames_per_row; ++frame) {
          // Rendering reads the image back, which is part of cpu frame; the first measured image of
          // each strategy is kept to check that the strategies agree.
          tilesplat::RenderImage image = budgeted
                                             ? renderer->render(scene.loaded.scene, c.camera.camera, settings)
                                             : renderer->render(c.camera.camera, settings);
          if (frame == options.warmup) images.push_back(std::move(image));
          // A training step's backward also in the warm-up frames, whose first call builds its pipelines.
          const tilesplat::FrameStats stats = options.backward
                                                  ? with_backward(*renderer, c.camera.camera, settings)
                                                  : renderer->last_frame_stats();
          if (frame >= options.warmup) collector.add(stats);
          progress.update(++done, where + sort);
        }
        c.results.push_back(collector.take());
      }
      record_image_agreement(c.results, images);
      images.clear();
      // The renderer holds its own copy; the next scene need not share memory with this one.
      if (i + 1 == cases.size() || cases[i + 1].scene != c.scene) scene.loaded.scene = {};
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const std::vector<Group> groups = group_cases(cases, sorts.size());
  for (const auto& group : groups) print_group(group, scenes[group.cases.front()->scene], options);
  std::fflush(stdout);

  const std::string written = write_outputs(
      {{options.csv,
        [&] { return cli::with_provenance_columns(make_csv(groups, scenes, device), options.command); }},
       {options.json, [&] { return make_json(groups, scenes, device, options); }},
       {options.plot, [&] { return make_frame_svg(groups, scenes, device, options); }}},
      renderer->validation_messages());
  std::string what = scenes.size() == 1 ? scenes.front().name + ", " + scenes.front().description
                                        : std::to_string(scenes.size()) + " scenes";
  what +=
      cases.size() == 1 ? ", " + size_of(cases.front()) : ", " + std::to_string(cases.size()) + " cameras";
  std::fprintf(stderr, "%s: %s, %d frames in %s s%s\n", kProgram, what.c_str(), total_frames,
               cli::format_fixed(seconds, 2).c_str(), written.c_str());
  return cli::kExitOk;
}

}  // namespace tilesplat::bench
