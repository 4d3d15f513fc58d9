#include "bench_options.h"

#include <limits>

#include "bench_results.h"

namespace tilesplat::bench {

namespace cli = tilesplat::cli;
namespace fs = std::filesystem;

std::vector<int> parse_int_list(std::string_view flag, const std::string& text, int min, int max) {
  std::vector<int> values;
  for (const auto& part : cli::split(text, ',')) add_unique(values, cli::parse_int(flag, part, min, max));
  if (values.empty()) throw cli::UsageError(std::string(flag) + " needs at least one value");
  return values;
}

void add_bench_options(cli::ArgParser& parser, BenchOptions& options) {
  cli::add_common_options(parser, options.common, cli::SortChoice::kList, cli::SceneChoice::kList);

  parser.section("camera path and sizes");
  parser.add_value(
      "--views", "N[,N...]|all",
      "several views of --cameras, comma-separated, or 'all': a row of results per view, then the "
      "median, min and max over the views of each view's median (default: --view alone)",
      [&options](const std::string& text) {
        options.all_views = text == "all";
        options.views.clear();
        if (!options.all_views)
          options.views = parse_int_list("--views", text, 0, std::numeric_limits<int>::max());
      });
  parser.add_int("--orbit", "N",
                 "N orbit cameras evenly spaced in azimuth, from --azimuth on (0, 360/N, ... by default), "
                 "with --elevation, --fov and --distance as given; not with --cameras",
                 &options.orbit, 1, 3600);
  parser.add_value("--resolutions", "WxH[,WxH...]",
                   "image sizes to measure each camera at, e.g. 1920x1080,1280x720 (instead of --width and "
                   "--height)",
                   [&options](const std::string& text) {
                     options.resolutions = cli::parse_resolutions("--resolutions", text);
                   });

  cli::add_camera_model_options(parser, options.camera_model);

  parser.section("benchmark");
  parser.add_int("--warmup", "N",
                 "frames rendered and discarded before measuring, per camera and sort (default 2)",
                 &options.warmup, 0, 1000000);
  parser.add_int("--repeat", "N",
                 "frames measured per camera and sort (default 10): the median, min and max are over these",
                 &options.repeat, 1, 1000000);
  cli::add_memory_budget_option(
      parser, options.memory_budget,
      "the table adds the parts and the peak device memory; frame benchmark only; ");
  parser.add_switch("--backward",
                    "time training steps: each measured frame is the forward frame and then its backward "
                    "(Renderer::backward of a fixed random colour gradient, on the forward's lists), whose "
                    "passes composite_backward and projection_backward join the table; frame benchmark only, "
                    "pinhole views of the sorted compositor in the reference's modes",
                    &options.backward);
  parser.add_string(
      "--csv", "FILE.csv",
      "also write the results as CSV: one line per scene, size, view, sort and metric; with several "
      "views also view 'all', the statistics over the views of each view's median",
      &options.csv);
  parser.add_string("--json", "FILE.json", "also write the results, every sample included, as JSON",
                    &options.json);
  parser.add_string(
      "--plot", "FILE.svg",
      "also draw an SVG chart: the median GPU time of each pass as stacked bars, one per scene, "
      "size and sort; with --sort-bench, Mkeys/s against key count per sort and key width; with "
      "--accuracy, per scene PSNR against time and, beside it, the view inconsistency against time "
      "(..._consistency.svg) and the warped popping along the path (..._popping.svg)",
      &options.plot);

  parser.section("accuracy report");
  parser.add_switch(
      "--accuracy",
      "measure what each accuracy mode costs: per --mode combination (default: each approximation "
      "alone and the combinations that matter), the GPU time per pass and frame and the error "
      "against the float64 CPU reference (PSNR, SSIM, max abs) and against its exact per-pixel "
      "ray-depth order at each view, the popping along a short camera path from the first view "
      "(--path; also each frame warped onto the next by its rendered depth) and the view consistency "
      "under a turn (--consistency-angle); --plot draws the Pareto charts",
      &options.accuracy);
  parser.add_string(
      "--markdown", "FILE.md",
      "with --accuracy, --effects, --formats or --scaling: also write the report as Markdown tables",
      &options.markdown);
  parser.add_value("--path", "dolly|pan|orbit",
                   "with --accuracy: the camera path the popping is measured on, from the first view: 'pan' "
                   "(turning in place, default), 'orbit' (around the scene centre) or 'dolly' (sideways; "
                   "centre-depth order never changes on it, so the reference cannot pop there)",
                   [&options](const std::string& text) {
                     const auto path = tilesplat::accuracy::parse_camera_path(text);
                     if (!path) throw cli::UsageError("--path: '" + text + "' is not dolly, pan or orbit");
                     options.path = *path;
                   });
  parser.add_int("--path-frames", "N",
                 "with --accuracy: frames of the camera path the popping is measured on (default 6; 0: none)",
                 &options.path_frames, 0, 1000);
  parser.add_value(
      "--consistency-angle", "RAD",
      "with --accuracy: the view-consistency pair turns the first view in place by RAD radians "
      "(default 0.08; 0: no pair), rendered at twice its size, and measures what does not follow the "
      "rotation: the popping per-pixel re-sorting removes",
      [&options](const std::string& text) {
        options.consistency_angle = cli::parse_double("--consistency-angle", text);
        if (!(options.consistency_angle >= 0 && options.consistency_angle <= 0.5))
          throw cli::UsageError("--consistency-angle: " + text + " is not in [0, 0.5]");
      });
  parser.add_value(
      "--path-step", "F",
      "with --accuracy: the path's step per frame: radians for the orbit and the pan, a fraction of "
      "the distance to the scene centre for the dolly (default 0.0005), in (0, 0.1]",
      [&options](const std::string& text) {
        options.path_step = cli::parse_double("--path-step", text);
        if (!(options.path_step > 0 && options.path_step <= 0.1))
          throw cli::UsageError("--path-step: " + text + " is not in (0, 0.1]");
      });

  parser.section("effect costs");
  parser.add_switch(
      "--effects",
      "measure what each scene effect costs: GPU time per pass with one effect changed at a time "
      "from all off (SH degree 0..3, relighting, antialiasing modes, depth and splat-count outputs), "
      "and beside the 'off' rows a scene that never had the effect (SH stored at degree 0, no "
      "normals); one SCENE, --views or --orbit cameras; --markdown and --csv write the table",
      &options.effects);

  parser.section("format costs");
  parser.add_switch(
      "--formats",
      "measure what each file format costs: the first SCENE is the lossless reference (a PLY), the "
      "others the same scene in other formats; per file its size and bytes per Gaussian, load time "
      "(median of --repeat loads after --warmup) and peak memory, the largest error of every decoded "
      "attribute, and the image PSNR and max abs error against the reference's at each view (default: "
      "the first and the middle view of --cameras, else two orbit views); --markdown, --csv and --plot "
      "(bytes per Gaussian against PSNR) write the report",
      &options.formats);

  parser.section("LOD report");
  parser.add_value(
      "--lod-curve", "N[,N...]",
      "measure a LOD set (lod-meta.json) or a .rad LOD tree (one SCENE): its levels whole, then each "
      "splat budget N (what each view calls for, docs/big-scenes.md); per row the Gaussians drawn, the GPU time, the "
      "host's time to choose and gather, and PSNR and max abs against level 0; --markdown, --csv and "
      "--plot (PSNR against Gaussians drawn) write the report",
      [&options](const std::string& text) {
        options.lod_budgets.clear();
        for (const int budget : parse_int_list("--lod-curve", text, 1, std::numeric_limits<int>::max()))
          options.lod_budgets.push_back(uint64_t(budget));
      });

  parser.section("sample curve");
  parser.add_value(
      "--sample-curve", "EFFECT[:N,...]",
      "measure an averaged effect's sample count against error and time on one SCENE: 'lens' (depth of "
      "field, aperture 0.05 of the view depth of the scene's centre, focused there) or 'time' (motion blur "
      "while the camera turns 5 degrees about the centre), with N samples (default 1,2,4,...,128); per "
      "row the GPU time, the time per sample, and PSNR and max abs against 1,024 samples of the same "
      "effect (docs/effects.md); 'lens-sobol' and 'time-sobol' the same with the progressive sample "
      "pattern; 'stochastic', 'stochastic-stratified' or 'stochastic-sobol': the stochastic compositor's "
      "frames with either sampler, against the sorted frame; --markdown, --csv and --plot (PSNR against "
      "samples) write the report",
      [&options](const std::string& text) {
        const size_t colon = text.find(':');
        const std::string name = text.substr(0, colon);
        options.sample_curve = tilesplat::sample_curve::parse_effect(name);
        if (!options.sample_curve)
          throw cli::UsageError(
              "--sample-curve takes 'lens' or 'time' (or 'lens-sobol', 'time-sobol', 'stochastic', "
              "'stochastic-stratified', 'stochastic-sobol'), optionally "
              "with ':N,N,...', got " +
              cli::single_quoted(text));
        if (colon != std::string::npos)
          options.sample_counts =
              parse_int_list("--sample-curve", text.substr(colon + 1), 1, tilesplat::kMaxLensSamples);
      });

  parser.section("scaling report");
  parser.add_switch(
      "--scaling",
      "measure how the frame's cost and device memory grow: every SCENE from the orbit camera that "
      "frames it at every size of --resolutions (default 960x540,1920x1080,2560x1440,3840x2160), "
      "GPU time per pass, pairs and device memory, then a non-negative least-squares fit of each "
      "pass's time and of the memory per Gaussian, per pair and per pixel; --markdown, --csv and "
      "--plot (PLOT.svg time against Gaussians, PLOT_pixels.svg against image size, PLOT_memory.svg) "
      "write the report",
      &options.scaling);
  parser.add_value(
      "--tile-copies", "N",
      "with --scaling: also measure a scene of N copies of the largest SCENE side by side (2 to 64), "
      "for Gaussian counts no file has",
      [&options](const std::string& text) {
        options.tile_copies = cli::parse_int("--tile-copies", text, 2, 64);
      });

  parser.section("sort micro-benchmark");
  parser.add_switch("--sort-bench",
                    "time the sort strategies alone on random keys (no SCENE), with std::sort and a CPU "
                    "radix sort on the same keys for comparison; --warmup and --repeat count sorts",
                    &options.sort_bench);
  parser.add_value("--sort-sizes", "E[,E...]",
                   "key counts as powers of two, each 0 to 26 (default 10,12,14,16,18,20,22,24)",
                   [&options](const std::string& text) {
                     options.sort_sizes = parse_int_list("--sort-sizes", text, 0, 26);
                   });
  parser.add_value(
      "--key-bits", "B[,B...]", "key widths in bits, each 1 to 64 (default 32,64)",
      [&options](const std::string& text) { options.key_bits = parse_int_list("--key-bits", text, 1, 64); });
}

void check_outputs(const BenchOptions& options, const std::vector<std::pair<std::string, fs::path>>& inputs) {
  if (!options.plot.empty() && !cli::has_extension(options.plot, ".svg"))
    throw cli::UsageError("--plot writes SVG: its file name must end in .svg, got '" + options.plot + "'");
  const std::vector<std::pair<std::string, fs::path>> outputs = {{"--csv", options.csv},
                                                                 {"--json", options.json},
                                                                 {"--plot", options.plot},
                                                                 {"--markdown", options.markdown}};
  cli::check_distinct_paths(outputs);
  // Inputs may repeat (one cameras.json for every scene); only an output may not be one of them.
  for (const auto& input : inputs) {
    auto paths = outputs;
    paths.insert(paths.begin(), input);
    cli::check_distinct_paths(paths);
  }
  for (const auto& [flag, path] : outputs)
    if (!path.empty()) cli::check_output_path(path, flag);
}

std::vector<std::pair<std::string, fs::path>> scene_and_camera_inputs(const BenchOptions& options) {
  std::vector<std::pair<std::string, fs::path>> inputs;
  for (const auto& scene : options.common.scenes) inputs.emplace_back("SCENE", scene);
  for (const auto& cameras : options.common.cameras_files) inputs.emplace_back("--cameras", cameras);
  return inputs;
}

std::string write_outputs(const std::vector<std::pair<std::string, std::function<std::string()>>>& files,
                          uint64_t validation_messages) {
  std::string written;
  for (const auto& [path, make] : files) {
    if (path.empty()) continue;
    tilesplat::write_file_atomically(path, make());
    written += (written.empty() ? " -> " : ", ") + path;
  }
  if (validation_messages > 0)
    cli::print_warning(kProgram,
                       std::to_string(validation_messages) + " Vulkan validation messages (see above)");
  return written;
}

// What the parser cannot check flag by flag. Throws UsageError.
void check_frame_options(const cli::ArgParser& parser, const BenchOptions& options) {
  for (const char* flag : {"--sort-sizes", "--key-bits"})
    if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " applies only with --sort-bench");
  const bool lod_curve = !options.lod_budgets.empty();
  const bool sample_curve = options.sample_curve.has_value();
  if (int(options.accuracy) + int(options.effects) + int(options.formats) + int(options.scaling) +
          int(lod_curve) + int(sample_curve) >
      1)
    throw cli::UsageError(
        "--accuracy, --effects, --formats, --scaling, --lod-curve and --sample-curve are separate runs");
  if (parser.seen("--tile-copies") && !options.scaling)
    throw cli::UsageError("--tile-copies applies only with --scaling");
  if (parser.seen("--memory-budget") && (options.accuracy || options.effects || options.formats ||
                                         options.scaling || lod_curve || sample_curve))
    throw cli::UsageError("--memory-budget applies only to the frame benchmark");
  if (!options.accuracy) {
    if (parser.seen("--path-frames")) throw cli::UsageError("--path-frames applies only with --accuracy");
    if (parser.seen("--markdown") && !options.effects && !options.formats && !options.scaling && !lod_curve &&
        !sample_curve)
      throw cli::UsageError(
          "--markdown applies only with --accuracy, --effects, --formats, --scaling, --lod-curve or "
          "--sample-curve");
    if (options.common.modes.size() > 1)
      throw cli::UsageError(
          "several --mode combinations are compared by --accuracy; the frame benchmark takes one");
  }
  cli::check_common_options(parser, options.common);
  const size_t cameras = options.common.cameras_files.size();
  const size_t scenes = options.common.scenes.size();
  if (cameras > 1 && cameras != scenes)
    throw cli::UsageError("--cameras was given " + std::to_string(cameras) + " times for " +
                          std::to_string(scenes) +
                          " scenes: give it once for every scene, or once per scene in "
                          "the order of the scenes");
  if (parser.seen("--views")) {
    if (cameras == 0 && !cli::any_scene_file(options.common))
      throw cli::UsageError(
          "--views needs --cameras FILE.json (without it the cameras orbit the scene: see --orbit)");
    if (parser.seen("--view")) throw cli::UsageError("--view and --views cannot be combined");
  }
  if (parser.seen("--orbit") && cameras > 0)
    throw cli::UsageError("--orbit applies only to the orbit camera and cannot be combined with --cameras");
  if (parser.seen("--resolutions"))
    for (const char* flag : {"--width", "--height"})
      if (parser.seen(flag))
        throw cli::UsageError(std::string("--resolutions and ") + flag +
                              " cannot be combined: give every size in --resolutions");
}

void check_bench_flags(const cli::ArgParser& parser, const BenchOptions& options) {
  if (options.sort_bench) {
    if (!options.common.scenes.empty())
      throw cli::UsageError("--sort-bench sorts random keys and takes no SCENE");
    for (const char* flag : {"--cameras", "--view", "--views", "--orbit", "--width", "--height",
                             "--resolutions", "--azimuth", "--elevation", "--fov", "--distance", "--strict",
                             "--fisheye", "--orthographic", "--equirectangular"})
      if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " does not apply to --sort-bench");
    return;
  }
  check_frame_options(parser, options);
  cli::check_camera_model_options(options.camera_model);
  if (options.camera_model.enabled() && (options.effects || options.scaling))
    throw cli::UsageError(
        std::string(options.effects ? "--effects" : "--scaling") +
        " measures pinhole views (--effects times every camera model itself); "
        "--fisheye, --orthographic and --equirectangular apply to the frame benchmark and the "
        "other reports");
  if (options.backward && (options.accuracy || options.effects || options.formats || options.scaling ||
                           !options.lod_budgets.empty() || options.sample_curve || options.memory_budget > 0))
    throw cli::UsageError(
        "--backward times the frame benchmark's training steps; it does not apply to the reports or "
        "--memory-budget");
  if (options.accuracy) {
    for (const char* flag : {"--resolutions", "--orbit", "--json"})
      if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " does not apply to --accuracy");
    if (options.common.sorts.size() > 1)
      throw cli::UsageError("--accuracy measures with one --sort strategy (the modes do not depend on it)");
  } else if (options.effects) {
    for (const char* flag : {"--resolutions", "--json", "--plot"})
      if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " does not apply to --effects");
    if (options.common.scenes.size() != 1) throw cli::UsageError("--effects measures one SCENE");
    if (options.common.sorts.size() > 1) throw cli::UsageError("--effects measures with one --sort strategy");
    if (parser.seen("--antialiasing"))
      throw cli::UsageError("--antialiasing does not apply to --effects (it measures every mode)");
  } else if (options.sample_curve) {
    for (const char* flag : {"--resolutions", "--json", "--fisheye", "--orthographic", "--equirectangular"})
      if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " does not apply to --sample-curve");
    if (options.common.scenes.size() != 1) throw cli::UsageError("--sample-curve measures one SCENE");
    if (options.common.sorts.size() > 1)
      throw cli::UsageError("--sample-curve measures with one --sort strategy");
  } else if (!options.lod_budgets.empty()) {
    for (const char* flag : {"--resolutions", "--json", "--lod"})
      if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " does not apply to --lod-curve");
    if (options.common.scenes.size() != 1)
      throw cli::UsageError("--lod-curve measures one SCENE, a LOD set (lod-meta.json)");
    if (options.common.sorts.size() > 1)
      throw cli::UsageError("--lod-curve measures with one --sort strategy");
  } else if (options.scaling) {
    for (const char* flag : {"--json", "--view", "--views", "--orbit", "--cameras", "--width", "--height"})
      if (parser.seen(flag))
        throw cli::UsageError(std::string(flag) +
                              " does not apply to --scaling (it measures each scene from the "
                              "orbit camera that frames it, at every --resolutions size)");
    if (options.common.sorts.size() > 1) throw cli::UsageError("--scaling measures with one --sort strategy");
  } else if (options.formats) {
    for (const char* flag : {"--resolutions", "--json"})
      if (parser.seen(flag)) throw cli::UsageError(std::string(flag) + " does not apply to --formats");
    if (options.common.scenes.size() < 2)
      throw cli::UsageError(
          "--formats compares files with a reference: give the lossless PLY first, then one or more "
          "files of the same scene");
    if (options.common.sorts.size() > 1) throw cli::UsageError("--formats renders with one --sort strategy");
    if (options.common.cameras_files.size() > 1)
      throw cli::UsageError("--formats takes one --cameras for all its files");
  }
}

}  // namespace tilesplat::bench
