// tilesplat-render: renders a view of a scene to an EXR (and optionally a PNG preview), or many
// frames in one process (the views of a camera set, an orbit, a keyframed path) with a manifest
// that makes the run resumable and lets shards of it run as separate processes.
#include <algorithm>
#include <array>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cli.h"
#include "frame_renderer.h"
#include "frame_sequence.h"
#include "frame_stats_report.h"
#include "render_options.h"
#include "render_sequence.h"
#include "sha256.h"
#include "tilesplat/camera.h"
#include "tilesplat/camera_path.h"
#include "tilesplat/image.h"
#include "tilesplat/lod_set.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace {

namespace cli = tilesplat::cli;
namespace fs = std::filesystem;

using namespace tilesplat::render_app;



using cli::single_quoted;

// The shortest text that reads back as exactly `value` (std::to_chars).
template <typename Number>
std::string shortest_exact(Number value) {
  char digits[32];
  return std::string(digits, std::to_chars(digits, digits + sizeof(digits), value).ptr);
}

// --shutter-samples and --sample-pattern without --shutter (--aperture, --f-stop) shape the scene file's
// shutters (lenses) for the views rendered; a UsageError when there is nothing for them to shape.
void reshape_scene_effects(const cli::ArgParser& parser, const RenderOptions& options,
                           std::vector<Frame>& frames) {
  const bool samples = parser.seen("--shutter-samples"), pattern = parser.seen("--sample-pattern");
  bool shutters = false, lenses = false;
  for (Frame& frame : frames) {
    if (!options.shutter.enabled() && frame.shutter.opens()) {
      shutters = true;
      if (samples) frame.shutter.samples = options.shutter.samples;
      if (pattern) frame.shutter.pattern = options.shutter.pattern;
    }
    if (!options.lens.enabled() && frame.lens.enabled()) {
      lenses = true;
      if (pattern) frame.lens.pattern = options.lens.pattern;
    }
  }
  if (samples && !options.shutter.enabled() && !shutters)
    throw cli::UsageError(
        "--shutter-samples shapes the shutter, and no --shutter gave one (nor the scene file, for the views "
        "rendered)");
  if (pattern && !options.lens.enabled() && !options.shutter.enabled() && !shutters && !lenses)
    throw cli::UsageError(
        "--sample-pattern places lens and shutter samples: add --aperture, --f-stop or --shutter (or a scene "
        "file whose views have a lens or a shutter)");
}

// What the EXR's renderSettings attribute records: everything that changes the image.
std::string settings_text(const tilesplat::RenderSettings& settings, const LensFlags& lens,
                          const ShutterFlags& shutter, const std::optional<cli::LoadedLodSet>& lod) {
  std::string text = "sort=" + settings.sort;
  if (lod)
    text += lod->splat_budget > 0 ? " lod=budget:" + std::to_string(lod->splat_budget)
                                  : " lod=level:" + std::to_string(lod->level);
  text += " accuracy=" + tilesplat::to_string(settings.accuracy);
  text += " antialiasing=" + tilesplat::to_string(settings.antialiasing);
  if (settings.max_alpha != tilesplat::kDefaultMaxAlpha)
    text += " max_alpha=" + shortest_exact(settings.max_alpha);
  text += " compositor=" + tilesplat::to_string(settings.compositor);
  if (settings.compositor == tilesplat::Compositor::kStochastic)
    text += " frames=" + std::to_string(settings.stochastic.frames) +
            " seed=" + std::to_string(settings.stochastic.seed) +
            (settings.stochastic.sampler == tilesplat::StochasticSampler::kHash
                 ? ""
                 : " sampler=" + tilesplat::to_string(settings.stochastic.sampler));
  text += " lights=" + std::to_string(settings.lighting.lights.size());
  if (!settings.region.whole()) text += " region=" + tilesplat::to_string(settings.region);
  text += " background=";
  for (size_t c = 0; c < 3; ++c) {
    if (c > 0) text += ',';
    text += shortest_exact(settings.background[c]);
  }
  if (lens.enabled())
    text += " lens=" + lens_text(lens);
  else if (settings.lens.enabled())  // a scene file's lens for the view
    text += " lens=aperture:" + shortest_exact(settings.lens.aperture_diameter) +
            ",focus:" + shortest_exact(settings.lens.focus_distance) +
            ",samples:" + std::to_string(settings.lens.samples) +
            (settings.lens.pattern == tilesplat::SamplePattern::kEven
                 ? ""
                 : ",pattern:" + std::string(tilesplat::sample_pattern_name(settings.lens.pattern)));
  if (shutter.enabled()) {
    text += " shutter=" + shutter_text(shutter);
  } else if (settings.shutter.opens()) {  // a scene file's shutter for the view
    text += " shutter=open:" + shortest_exact(settings.shutter.open) +
            ",close:" + shortest_exact(settings.shutter.close) +
            ",samples:" + std::to_string(settings.shutter.samples) +
            ",scan:" + tilesplat::shutter_scan_name(settings.shutter.scan) +
            (settings.shutter.end_camera ? ",camera:moving" : ",camera:still") +
            (settings.shutter.pattern == tilesplat::SamplePattern::kEven
                 ? ""
                 : ",pattern:" + std::string(tilesplat::sample_pattern_name(settings.shutter.pattern)));
  }
  return text;
}


std::string png_settings_text(const tilesplat::PreviewOptions& preview) {
  return "exposure=" + cli::format_fixed(preview.exposure_stops, 3) +
         " tone_map=" + tilesplat::to_string(preview.tone_map);
}


std::optional<std::string> environment(const char* name) {
  const char* value = std::getenv(name);
  if (value == nullptr || *value == '\0') return std::nullopt;
  return std::string(value);
}


// The frames to render: the one view, or the sequence's (each camera in the --camera-model asked for), with
// the scene effects reshaped by the flags.
std::vector<Frame> plan_frames(const cli::ArgParser& parser, const RenderOptions& options,
                               const cli::LoadedScene& loaded, bool sequence) {
  std::vector<Frame> frames;
  if (sequence) {
    frames = plan_sequence(parser, options, loaded);
  } else {
    frames.push_back({0,
                      loaded.view_index.value_or(0),
                      loaded.camera,
                      loaded.camera_description,
                      loaded.view_index,
                      loaded.view_name,
                      options.output,
                      options.png,
                      {},
                      loaded.lens,
                      loaded.shutter});
  }
  for (Frame& frame : frames) {
    frame.camera = cli::camera_for_frame(options.camera_model, frame.camera);
    if (frame.next_camera)
      frame.next_camera = cli::camera_for_frame(options.camera_model, *frame.next_camera);
    if (frame.shutter.end_camera)
      frame.shutter.end_camera = cli::camera_for_frame(options.camera_model, *frame.shutter.end_camera);
  }
  reshape_scene_effects(parser, options, frames);
  return frames;
}

// The frames' RenderSettings: the scene file's, the flags over them. Every frame's image must hold the
// --region, checked before anything renders.
tilesplat::RenderSettings render_settings(const cli::ArgParser& parser, const RenderOptions& options,
                                          const cli::LoadedScene& loaded, const std::vector<Frame>& frames,
                                          bool sequence) {
  tilesplat::RenderSettings settings = cli::base_render_settings(options.common, loaded);
  // tilesplat-render's own flags override the scene file too.
  if (parser.seen("--background") || !loaded.description) settings.background = options.background;
  if (options.no_depth) settings.depth = false;
  if (options.no_count) settings.splat_count = false;
  settings.memory_budget = options.memory_budget;
  settings.region = options.region;
  for (const Frame& frame : frames) {
    try {
      tilesplat::validate(options.region, frame.camera.width, frame.camera.height);
    } catch (const std::invalid_argument& error) {
      std::string why = error.what();
      why = why.substr(why.find(": ") + 2);
      throw cli::UsageError("--region " + tilesplat::to_string(options.region) + ": " + why);
    }
  }
  if (options.stochastic_frames > 0) {  // --compositor stochastic or none (check_render_options)
    settings.compositor = tilesplat::Compositor::kStochastic;
    settings.stochastic.frames = static_cast<uint32_t>(options.stochastic_frames);
  }
  settings.stochastic.sampler = options.stochastic_sampler;
  // A scene file's lens and shutter: the view's own for one frame; for many, each frame's view has its own.
  if (!sequence) {
    settings.lens = frames.front().lens;
    settings.shutter = frames.front().shutter;
  }
  return settings;
}

// How the frames are written: the EXR's channels, compression, colour and attributes (the command line,
// the scene and its hash, the settings), and the PNG preview's grading (the scene file's, the flags over it).
FrameWriter frame_writer(const cli::ArgParser& parser, const RenderOptions& options,
                         const cli::LoadedScene& loaded, const tilesplat::RenderSettings& settings,
                         const std::vector<Frame>& frames, bool sequence, int argc, char** argv) {
  FrameWriter writer;
  if (loaded.description) {
    writer.preview.exposure_stops = loaded.description->effects.exposure_stops;
    writer.preview.tone_map = loaded.description->effects.tone_map;
  }
  if (parser.seen("--exposure")) writer.preview.exposure_stops = options.preview.exposure_stops;
  if (parser.seen("--tone-map")) writer.preview.tone_map = options.preview.tone_map;
  writer.exr.half = options.half;
  writer.exr.alpha = !loaded.description || loaded.description->outputs.alpha;
  writer.exr.attributes["commandLine"] = cli::command_line(kProgram, argc, argv);
  writer.exr.compression = options.compression;
  writer.exr.colour = options.exr_colour;
  writer.exr.region = settings.region;
  // Empty pixels far away, for depth compositing; with a background, an opaque frame (docs: README).
  writer.exr.empty_depth = tilesplat::kFarDepth;
  writer.exr.opaque_alpha = settings.background != std::array<float, 3>{0, 0, 0};
  writer.exr.attributes["scene"] = loaded.path.string();
  writer.exr.attributes["sceneSha256"] = cli::sha256_file_hex(loaded.path);
  writer.exr.attributes["renderSettings"] =
      settings_text(settings, options.lens, options.shutter, loaded.lod);
  if (sequence && !options.lens.enabled() &&
      std::any_of(frames.begin(), frames.end(), [](const Frame& f) { return f.lens.enabled(); }))
    writer.exr.attributes["renderSettings"] +=
        " lens=the scene file's, per view" +
        std::string(parser.seen("--sample-pattern") ? ", pattern:" : "") +
        (parser.seen("--sample-pattern") ? tilesplat::sample_pattern_name(options.lens.pattern) : "");
  if (sequence && !options.shutter.enabled() &&
      std::any_of(frames.begin(), frames.end(), [](const Frame& f) { return f.shutter.opens(); }))
    writer.exr.attributes["renderSettings"] +=
        " shutter=the scene file's, per view" +
        (parser.seen("--shutter-samples") ? ", samples:" + std::to_string(options.shutter.samples) : "") +
        (parser.seen("--sample-pattern")
             ? ", pattern:" + std::string(tilesplat::sample_pattern_name(options.shutter.pattern))
             : "");
  return writer;
}

// One frame rendered and written, with its statistics (--stats) and a line of summary on stderr.
int render_frame(const RenderOptions& options, const cli::LoadedScene& loaded, const Frame& frame,
                 const tilesplat::RenderSettings& settings, FrameWriter& writer) {
  FrameRenderer renderer(options, loaded);
  writer.exr.attributes["sortStrategy"] = renderer.sort_strategy(settings);
  const tilesplat::RenderImage image = renderer.render(frame.camera, settings);
  const tilesplat::SaturatedValues saturated = writer.write(frame, image);
  std::string timing;
  if (const tilesplat::Renderer* gpu = renderer.gpu()) {
    tilesplat::FrameStats stats = gpu->last_frame_stats();
    stats.saturated += saturated;  // the file's, for --stats
    timing = "GPU " + cli::format_fixed(stats.gpu_ms, 2) + " ms, frame " +
             cli::format_fixed(stats.cpu_ms, 2) + " ms";
    if (options.stats) print_frame_stats(stats, gpu->device_info());
    if (options.stats && loaded.lod && loaded.lod->splat_budget > 0)
      print_lod_selection(renderer.lod_selection());
    if (options.stats && loaded.lod_tree && loaded.lod_tree->splat_budget > 0)
      print_lod_tree_cut(*loaded.lod_tree->tree, renderer.lod_tree_cut());
    if (const auto messages = gpu->validation_messages(); messages > 0)
      cli::print_warning(kProgram, std::to_string(messages) + " Vulkan validation messages (see above)");
  } else {
    timing = "CPU reference " + cli::format_fixed(renderer.cpu_ms(), 1) + " ms";
    if (options.stats) {
      print_row("cpu reference", cli::format_fixed(renderer.cpu_ms(), 3), "ms");
      print_row("gaussians", std::to_string(loaded.gaussians()), "");
      print_row("saturated values", std::to_string(saturated.total()), "");
    }
  }
  std::string written = options.output;
  if (!options.png.empty()) written += ", " + options.png;

  std::fflush(stdout);
  const std::string summary =
      std::string(kProgram) + ": " + loaded.path.filename().string() + ", " + cli::describe_scene(loaded) +
      ", " + std::to_string(frame.camera.width) + "x" + std::to_string(frame.camera.height) +
      (settings.region.whole() ? "" : " (region " + tilesplat::to_string(settings.region) + ")") + ", " +
      loaded.camera_description + ", " + timing + " -> " + written + "\n";
  std::fputs(summary.c_str(), stderr);
  return cli::kExitOk;
}

int run(int argc, char** argv) {
  cli::load_sort_plugins(argc, argv);  // before the parser lists and checks the sort names
  RenderOptions options;
  cli::ArgParser parser(kProgram, kUsage, kDescription);
  add_render_options(parser, options);
  if (cli::parse_and_handle_info_flags(parser, argc, argv, options.common)) return cli::kExitOk;
  if (parser.seen("--merge-manifests")) return merge(options);
  check_render_flags(parser, options);
  const bool sequence = renders_sequence(parser);
  if (options.reference) {
    for (const char* gpu_flag : {"--device", "--validation", "--sort", "--mode"})
      if (parser.seen(gpu_flag))
        cli::print_warning(kProgram,
                           std::string(gpu_flag) + " has no effect with --reference (CPU renderer)");
  }
  const cli::Shard shard =
      sequence ? cli::resolve_shard(options.shard, options.shard_count, environment) : cli::Shard{};
  cli::check_output_path(sequence ? cli::frame_file("-o", options.output, 0) : options.output, "-o");
  if (!options.png.empty())
    cli::check_output_path(sequence ? cli::frame_file("--png", options.png, 0) : options.png, "--png");

  // The GPU renderer takes a scene file's models as placed copies of their files, and merges them only
  // when their frame fits the device (FrameRenderer::decide_holding); the reference merges them at load
  // unless some move (each time of a shutter places them anew).
  const cli::SceneHolding holding =
      !options.reference ? cli::SceneHolding::kInstances : cli::SceneHolding::kInstancesIfMoving;
  const cli::PartReading reading =
      options.read_in_parts ? cli::PartReading::kInParts : cli::PartReading::kInPartsWhenLarge;
  cli::LoadedScene loaded = sequence ? cli::load_scene_file(options.common.scene, options.common.strict,
                                                            kProgram, holding, options.common.lod, reading)
                                     : cli::load_scene_and_camera(options.common, kProgram, holding, reading);
  const std::vector<Frame> frames = plan_frames(parser, options, loaded, sequence);
  const tilesplat::RenderSettings settings = render_settings(parser, options, loaded, frames, sequence);
  FrameWriter writer = frame_writer(parser, options, loaded, settings, frames, sequence, argc, argv);
  if (!sequence) return render_frame(options, loaded, frames.front(), settings, writer);
  // Everything besides the camera that makes two runs' files differ, for the manifest.
  std::string settings_line =
      writer.exr.attributes["renderSettings"] + " exr=" + (options.half ? "half" : "float") + "," +
      tilesplat::to_string(options.compression) + "," + tilesplat::to_string(options.exr_colour) +
      (writer.exr.alpha ? ",A" : "") + (settings.depth ? ",Z" : "") + (settings.splat_count ? ",splats" : "");
  if (!options.png.empty()) settings_line += " png=" + png_settings_text(writer.preview);
  return render_sequence(options, frames, shard, loaded, settings, writer, settings_line);
}

}  // namespace

int main(int argc, char** argv) {
  return cli::run_app(kProgram, [argc, argv] { return run(argc, argv); });
}
