#include "report_runs.h"

#include <cstdio>

#include "bench_plot.h"
#include "bench_results.h"
#include "effects_report.h"
#include "formats_report.h"
#include "frame_bench.h"
#include "lod_report.h"
#include "progress.h"
#include "sample_curve.h"
#include "scaling_report.h"

namespace tilesplat::bench {

namespace cli = tilesplat::cli;
namespace fs = std::filesystem;
namespace plot = tilesplat::plot;

// ---------------------------------------------------------------------------------------------
// The accuracy report (accuracy_report.h): every mode against the float64 reference, per scene.

// --plot FILE.svg with several scenes: FILE_<scene>.svg for each.
fs::path scene_plot_path(const std::string& plot, const std::string& scene_file, size_t scenes) {
  if (scenes == 1) return plot;
  fs::path path(plot);
  return path.parent_path() / (path.stem().string() + "_" + fs::path(scene_file).stem().string() + ".svg");
}

// The report renders every mode against the reference itself, so a scene file's sh_degree effect is
// applied to the scene (dropping the bands it excludes gives the same images as the cap) rather than
// to the modes, whose SH cap is one of the things measured.
int run_accuracy_report(const BenchOptions& options) {
  check_outputs(options, scene_and_camera_inputs(options));

  const std::string& command = options.command;

  // Every scene and camera first: a bad file or view fails now, not after an hour of measuring.
  struct Planned {
    BenchScene scene;
    tilesplat::accuracy::Options options;
  };
  std::vector<Planned> planned;
  const cli::ImageSize size{options.common.width, options.common.height};
  for (size_t s = 0; s < options.common.scenes.size(); ++s) {
    Planned p;
    p.scene.loaded = cli::load_scene_file(options.common.scenes[s], options.common.strict, kProgram,
                                          cli::SceneHolding::kMerged, options.common.lod);
    p.scene.name = p.scene.loaded.path.filename().string();
    p.scene.description = cli::describe_scene(p.scene.loaded.scene);
    p.scene.sh_degree = p.scene.loaded.scene.sh_degree;
    const auto& cameras = options.common.cameras_files;
    if (!cameras.empty()) p.scene.cameras = cameras.size() == 1 ? cameras.front() : cameras[s];
    for (const Case& c : plan_cases(options, p.scene, s, {size})) {
      p.options.views.push_back(c.camera.camera);
      p.options.view_names.push_back(c.view_label);
    }
    p.options.modes = options.common.modes;
    p.options.compositor = options.common.compositor;
    p.options.warmup = options.warmup;
    p.options.repeat = options.repeat;
    p.options.path = options.path;
    p.options.path_frames = options.path_frames;
    p.options.path_step = options.path_step;
    p.options.consistency_angle = options.consistency_angle;
    if (!options.common.sorts.empty()) p.options.sort = options.common.sorts.front();
    planned.push_back(std::move(p));
  }

  const auto renderer = tilesplat::Renderer::create(cli::renderer_options(options.common));
  const tilesplat::DeviceInfo device = renderer->device_info();
  std::printf("device  %s (driver %s)\n", device.name.c_str(), device.driver.c_str());
  std::fflush(stdout);
  int total = 0;
  for (const auto& p : planned) total += tilesplat::accuracy::work_units(p.options, p.scene.sh_degree);
  cli::FrameProgress progress(kProgram, total, cli::progress_style(false), "renders");
  int done_before = 0;
  std::vector<tilesplat::accuracy::SceneReport> reports;
  for (auto& p : planned) {
    auto report = tilesplat::accuracy::measure_scene(
        *renderer, p.scene.loaded.scene, p.options, [&](int done, int, const std::string& what) {
          progress.update(done_before + done, p.scene.name + ": " + what);
        });
    done_before += tilesplat::accuracy::work_units(p.options, p.scene.sh_degree);
    report.scene = p.scene.name;
    report.description = p.scene.description;
    std::string views;
    for (const auto& name : p.options.view_names) views += (views.empty() ? "" : ", ") + name;
    report.views =
        views + " at " + cli::format_size(p.options.views.front().width, p.options.views.front().height);
    p.scene.loaded.scene = {};  // measured: release its memory
    progress.finish();
    std::printf("\n%s", tilesplat::accuracy::text_table(report).c_str());
    std::fflush(stdout);
    reports.push_back(std::move(report));
  }

  std::vector<std::pair<std::string, std::function<std::string()>>> files = {
      {options.markdown, [&] { return tilesplat::accuracy::markdown(reports, device, command); }},
      {options.csv,
       [&] { return cli::with_provenance_columns(tilesplat::accuracy::csv(reports, device), command); }}};
  std::vector<std::string> plot_paths;
  if (!options.plot.empty())
    for (const auto& report : reports) {
      plot_paths.push_back(scene_plot_path(options.plot, report.scene, reports.size()).string());
      files.emplace_back(plot_paths.back(),
                         [&report, &device] { return tilesplat::accuracy::pareto_svg(report, device); });
      if (report.consistency_angle > 0) {
        fs::path consistency = plot_paths.back();
        consistency.replace_filename(consistency.stem().string() + "_consistency.svg");
        plot_paths.push_back(consistency.string());
        files.emplace_back(plot_paths.back(), [&report, &device] {
          return tilesplat::accuracy::consistency_svg(report, device);
        });
      }
      if (report.path_frames >= 2) {
        fs::path popping = scene_plot_path(options.plot, report.scene, reports.size());
        popping.replace_filename(popping.stem().string() + "_popping.svg");
        plot_paths.push_back(popping.string());
        files.emplace_back(plot_paths.back(),
                           [&report, &device] { return tilesplat::accuracy::popping_svg(report, device); });
      }
    }
  const std::string written = write_outputs(files, renderer->validation_messages());
  std::fprintf(stderr, "%s: accuracy report, %d renders%s\n", kProgram, total, written.c_str());
  return cli::kExitOk;
}

// The cameras of a report of one scene: its cases at --width and --height.
std::vector<tilesplat::Camera> report_views(const BenchOptions& options, const BenchScene& scene) {
  std::vector<tilesplat::Camera> views;
  for (const Case& c : plan_cases(options, scene, 0, {{options.common.width, options.common.height}}))
    views.push_back(c.camera.camera);
  return views;
}

int run_effects_report(const BenchOptions& options) {
  check_outputs(options, {{"SCENE", options.common.scenes.front()}});
  const std::string& command = options.command;

  BenchScene scene;
  scene.loaded = cli::load_scene_file(options.common.scenes.front(), options.common.strict, kProgram,
                                      cli::SceneHolding::kMerged, options.common.lod);
  scene.name = scene.loaded.path.filename().string();
  scene.description = cli::describe_scene(scene.loaded.scene);
  scene.sh_degree = scene.loaded.scene.sh_degree;
  if (!options.common.cameras_files.empty()) scene.cameras = options.common.cameras_files.front();
  tilesplat::effects::Options effect_options;
  effect_options.views = report_views(options, scene);
  effect_options.warmup = std::max(options.warmup, 1);  // llvmpipe compiles each variant on first use
  effect_options.repeat = options.repeat;
  if (!options.common.sorts.empty()) effect_options.sort = options.common.sorts.front();

  const tilesplat::RenderSettings base = cli::base_render_settings(options.common, scene.loaded);
  std::vector<tilesplat::effects::Row> rows = tilesplat::effects::plan_rows(scene.loaded.scene, base);
  std::printf(
      "scene   %s: %s, %s\n", scene.name.c_str(), scene.description.c_str(),
      cli::format_size(effect_options.views.front().width, effect_options.views.front().height).c_str());
  std::fflush(stdout);
  tilesplat::effects::Run run;
  {
    cli::FrameProgress progress(kProgram, tilesplat::effects::work_units(rows, effect_options),
                                cli::progress_style(false));
    run = tilesplat::effects::measure(
        cli::renderer_options(options.common), scene.loaded.scene, rows, effect_options,
        [&](int done, int, const std::string& what) { progress.update(done, what); });
  }
  std::printf("device  %s (driver %s)\n\n%s", run.device.name.c_str(), run.device.driver.c_str(),
              tilesplat::effects::text_table(rows).c_str());
  std::fflush(stdout);
  const std::string written = write_outputs(
      {{options.markdown,
        [&] { return tilesplat::effects::markdown(rows, scene.name, run.device, command); }},
       {options.csv,
        [&] {
          return cli::with_provenance_columns(tilesplat::effects::csv(rows, scene.name, run.device), command);
        }}},
      run.validation_messages);
  std::fprintf(stderr, "%s: effect costs, %zu rows%s\n", kProgram, rows.size(), written.c_str());
  return cli::kExitOk;
}

// "PLOT.svg" -> "PLOT_SUFFIX.svg": the scaling report's second and third charts.
std::string plot_with_suffix(const std::string& plot, const std::string& suffix) {
  return plot.substr(0, plot.size() - 4) + "_" + suffix + ".svg";
}

int run_scaling_report(const BenchOptions& options) {
  check_outputs(options, scene_and_camera_inputs(options));
  tilesplat::scaling::Options scaling_options;
  const std::vector<cli::ImageSize> sizes =
      options.resolutions.empty()
          ? std::vector<cli::ImageSize>{{960, 540}, {1920, 1080}, {2560, 1440}, {3840, 2160}}
          : options.resolutions;
  for (const cli::ImageSize& size : sizes) scaling_options.sizes.push_back({size.width, size.height});
  scaling_options.warmup = std::max(options.warmup, 1);  // llvmpipe compiles each variant on first use
  scaling_options.repeat = options.repeat;
  if (!options.common.sorts.empty()) scaling_options.sort = options.common.sorts.front();
  if (options.common.compositor) scaling_options.compositor = *options.common.compositor;

  std::vector<tilesplat::scaling::Scene> scenes;
  for (const std::string& file : options.common.scenes) {
    cli::LoadedScene loaded = cli::load_scene_file(file, options.common.strict, kProgram,
                                                   cli::SceneHolding::kMerged, options.common.lod);
    if (loaded.scene.empty()) throw cli::UsageError("'" + file + "' has no Gaussians to measure");
    std::printf("scene   %s: %s\n", loaded.path.filename().string().c_str(),
                cli::describe_scene(loaded.scene).c_str());
    scenes.push_back({loaded.path.filename().string(), std::move(loaded.scene)});
  }
  if (options.tile_copies > 0) {
    const auto largest = std::max_element(scenes.begin(), scenes.end(), [](const auto& a, const auto& b) {
      return a.scene.size() < b.scene.size();
    });
    tilesplat::scaling::Scene tiled{largest->name + " x" + std::to_string(options.tile_copies) + " (tiled)",
                                    tilesplat::scaling::tile_scene(largest->scene, options.tile_copies)};
    std::printf("scene   %s: %s\n", tiled.name.c_str(), cli::describe_scene(tiled.scene).c_str());
    scenes.push_back(std::move(tiled));
  }
  std::fflush(stdout);
  tilesplat::scaling::Run run;
  {
    cli::FrameProgress progress(kProgram, tilesplat::scaling::work_units(scenes, scaling_options),
                                cli::progress_style(false));
    run = tilesplat::scaling::measure(
        cli::renderer_options(options.common), scenes, scaling_options,
        [&](int done, int, const std::string& what) { progress.update(done, what); });
  }
  const std::vector<tilesplat::scaling::Fit> fits = tilesplat::scaling::fit(run.points);
  std::printf("device  %s (driver %s)\n\n%s", run.device.name.c_str(), run.device.driver.c_str(),
              tilesplat::scaling::text_report(run, fits).c_str());
  std::fflush(stdout);
  std::vector<std::pair<std::string, std::function<std::string()>>> files = {
      {options.markdown, [&] { return tilesplat::scaling::markdown(run, fits, options.command); }},
      {options.csv,
       [&] { return cli::with_provenance_columns(tilesplat::scaling::csv(run), options.command); }},
      {options.plot, [&] { return tilesplat::scaling::svg_time_vs_gaussians(run); }}};
  if (!options.plot.empty()) {
    files.push_back({plot_with_suffix(options.plot, "pixels"),
                     [&] { return tilesplat::scaling::svg_time_vs_pixels(run); }});
    files.push_back(
        {plot_with_suffix(options.plot, "memory"), [&] { return tilesplat::scaling::svg_memory(run); }});
  }
  const std::string written = write_outputs(files, run.validation_messages);
  std::fprintf(stderr, "%s: scaling, %zu scenes x %zu sizes%s\n", kProgram, scenes.size(),
               scaling_options.sizes.size(), written.c_str());
  return cli::kExitOk;
}

// The views the format report compares images at: those asked for, else two that see the scene
// from different sides (the first and the middle view of its cameras, or two opposite orbit views).
std::vector<Case> plan_format_views(BenchOptions options, const BenchScene& reference) {
  const bool chosen =
      options.common.view_given || !options.views.empty() || options.all_views || options.orbit > 0;
  if (!chosen) {
    const cli::SceneViews own = cli::scene_views(reference.loaded);
    const size_t count =
        !reference.cameras.empty() ? cli::load_camera_views(reference.cameras).size() : own.views.size();
    if (count > 0) {
      options.views = {0};
      if (count > 1) options.views.push_back(int(count / 2));
    } else {
      options.orbit = 2;
    }
  }
  return plan_cases(options, reference, 0, {{options.common.width, options.common.height}});
}

int run_formats_report(const BenchOptions& options) {
  check_outputs(options, scene_and_camera_inputs(options));
  const std::string& command = options.command;

  BenchScene reference;
  reference.loaded = cli::load_scene_file(options.common.scenes.front(), options.common.strict, kProgram,
                                          cli::SceneHolding::kMerged, options.common.lod);
  if (!options.common.cameras_files.empty()) reference.cameras = options.common.cameras_files.front();
  tilesplat::formats::Options format_options;
  std::string view_names;
  for (const Case& c : plan_format_views(options, reference)) {
    format_options.views.push_back(c.camera.camera);
    format_options.view_names.push_back(c.view_label);
    view_names += (view_names.empty() ? "" : ", ") + c.view_label;
  }
  reference.loaded.scene = {};  // measure() loads every file itself, the reference included
  format_options.warmup = options.warmup;
  format_options.repeat = options.repeat;
  if (!options.common.sorts.empty()) format_options.settings.sort = options.common.sorts.front();
  if (!options.common.modes.empty()) format_options.settings.accuracy = options.common.modes.front();
  cli::apply_training_options(options.common, format_options.settings);

  const std::vector<fs::path> files(options.common.scenes.begin() + 1, options.common.scenes.end());
  const auto renderer = tilesplat::Renderer::create(cli::renderer_options(options.common));
  tilesplat::formats::Report report;
  {
    const int total = tilesplat::formats::work_units(files.size(), format_options);
    cli::FrameProgress progress(kProgram, total, cli::progress_style(false), "steps");
    report = tilesplat::formats::measure(
        *renderer, options.common.scenes.front(), files, format_options,
        [&](int done, int, const std::string& what) { progress.update(done, what); });
  }
  report.views_label =
      view_names + " at " +
      cli::format_size(format_options.views.front().width, format_options.views.front().height);
  std::printf("device  %s (driver %s)\n\n%s", report.device.name.c_str(), report.device.driver.c_str(),
              tilesplat::formats::text_table(report).c_str());
  std::fflush(stdout);
  const std::string written = write_outputs(
      {{options.markdown, [&] { return tilesplat::formats::markdown(report, command); }},
       {options.csv, [&] { return cli::with_provenance_columns(tilesplat::formats::csv(report), command); }},
       {options.plot, [&] { return tilesplat::formats::size_psnr_svg(report); }}},
      report.validation_messages);
  std::fprintf(stderr, "%s: format costs, %zu files against %s%s\n", kProgram, files.size(),
               report.reference_name.c_str(), written.c_str());
  return cli::kExitOk;
}

int run_sample_curve(const BenchOptions& options) {
  check_outputs(options, scene_and_camera_inputs(options));
  BenchScene scene;
  scene.loaded = cli::load_scene_file(options.common.scenes.front(), options.common.strict, kProgram,
                                      cli::SceneHolding::kMerged, options.common.lod);
  scene.name = scene.loaded.path.filename().string();
  if (!options.common.cameras_files.empty()) scene.cameras = options.common.cameras_files.front();
  namespace curve = tilesplat::sample_curve;
  curve::Options curve_options;
  curve_options.effect = *options.sample_curve;
  curve_options.counts = options.sample_counts;
  curve_options.views = report_views(options, scene);
  const tilesplat::Bounds bounds = scene.loaded.bounds();
  curve_options.centre = {bounds.center[0], bounds.center[1], bounds.center[2]};
  curve_options.warmup = std::max(options.warmup, 1);  // llvmpipe compiles each variant on first use
  curve_options.repeat = options.repeat;
  if (!options.common.sorts.empty()) curve_options.sort = options.common.sorts.front();
  curve_options.settings = cli::base_render_settings(options.common, scene.loaded);
  std::printf("scene   %s: %s, %s, %zu views, %s samples\n", scene.name.c_str(),
              cli::describe_scene(scene.loaded).c_str(),
              cli::format_size(curve_options.views.front().width, curve_options.views.front().height).c_str(),
              curve_options.views.size(), curve::effect_name(curve_options.effect).c_str());
  std::fflush(stdout);
  std::vector<curve::Row> rows;
  curve::Run run;
  {
    cli::FrameProgress progress(kProgram, curve::work_units(curve_options), cli::progress_style(false));
    run = curve::measure(cli::renderer_options(options.common), scene.loaded.scene, curve_options, rows,
                         [&](int done, int, const std::string& what) { progress.update(done, what); });
  }
  std::printf("device  %s (driver %s)\n\n%s", run.device.name.c_str(), run.device.driver.c_str(),
              curve::text_table(rows).c_str());
  std::fflush(stdout);
  const curve::Effect effect = curve_options.effect;
  const std::string written =
      write_outputs({{options.markdown,
                      [&] { return curve::markdown(rows, effect, scene.name, run.device, options.command); }},
                     {options.csv,
                      [&] {
                        return cli::with_provenance_columns(curve::csv(rows, effect, scene.name, run.device),
                                                            options.command);
                      }},
                     {options.plot, [&] { return curve::svg(rows, effect, scene.name, run.device); }}},
                    run.validation_messages);
  std::fprintf(stderr, "%s: sample curve, %zu rows%s\n", kProgram, rows.size(), written.c_str());
  return cli::kExitOk;
}

int run_lod_report(const BenchOptions& options) {
  check_outputs(options, scene_and_camera_inputs(options));
  BenchScene scene;
  const fs::path& path = options.common.scenes.front();
  const bool tree = tilesplat::is_lod_tree(path);
  // A tree is opened as one where a level is asked for (the report draws its own levels and budgets).
  cli::LodOptions as_tree;
  as_tree.level = 0;
  scene.loaded = cli::load_scene_file(path, options.common.strict, kProgram, cli::SceneHolding::kMerged,
                                      tree ? as_tree : cli::LodOptions{});
  if (!scene.loaded.lod && !scene.loaded.lod_tree)
    throw cli::UsageError("--lod-curve measures a LOD set (lod-meta.json) or a .rad LOD tree; " +
                          cli::single_quoted(scene.loaded.path.string()) + " is neither");
  scene.name = scene.loaded.path.filename().string();
  if (!options.common.cameras_files.empty()) scene.cameras = options.common.cameras_files.front();
  tilesplat::lod_report::Options lod_options;
  lod_options.views = report_views(options, scene);
  lod_options.warmup = std::max(options.warmup, 1);  // llvmpipe compiles each variant on first use
  lod_options.repeat = options.repeat;
  if (!options.common.sorts.empty()) lod_options.sort = options.common.sorts.front();
  if (!options.common.modes.empty()) lod_options.settings.accuracy = options.common.modes.front();
  cli::apply_training_options(options.common, lod_options.settings);

  const tilesplat::lod_report::Source source = scene.loaded.lod
                                                  ? tilesplat::lod_report::source_of(*scene.loaded.lod->set)
                                                  : tilesplat::lod_report::source_of(*scene.loaded.lod_tree->tree);
  std::vector<tilesplat::lod_report::Row> rows = tilesplat::lod_report::plan_rows(source, options.lod_budgets);
  std::printf("scene   %s: %s, %s, %zu views\n", scene.name.c_str(),
              cli::describe_scene(scene.loaded).c_str(),
              cli::format_size(lod_options.views.front().width, lod_options.views.front().height).c_str(),
              lod_options.views.size());
  std::fflush(stdout);
  scene.loaded.scene = {};  // the report reads every level from the set itself
  tilesplat::lod_report::Run run;
  {
    cli::FrameProgress progress(kProgram, tilesplat::lod_report::work_units(rows, lod_options),
                                cli::progress_style(false));
    run = tilesplat::lod_report::measure(
        cli::renderer_options(options.common), source, rows, lod_options,
        [&](int done, int, const std::string& what) { progress.update(done, what); });
  }
  std::printf("device  %s (driver %s)\n\n%s", run.device.name.c_str(), run.device.driver.c_str(),
              tilesplat::lod_report::text_table(rows).c_str());
  std::fflush(stdout);
  const std::string written = write_outputs(
      {{options.markdown,
        [&] { return tilesplat::lod_report::markdown(rows, scene.name, run.device, options.command); }},
       {options.csv,
        [&] {
          return cli::with_provenance_columns(tilesplat::lod_report::csv(rows, scene.name, run.device),
                                              options.command);
        }},
       {options.plot, [&] { return tilesplat::lod_report::svg(rows, scene.name, run.device); }}},
      run.validation_messages);
  std::fprintf(stderr, "%s: LOD report, %zu rows%s\n", kProgram, rows.size(), written.c_str());
  return cli::kExitOk;
}

}  // namespace tilesplat::bench
