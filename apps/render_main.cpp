// tilesplat-render: renders one view of a scene to an EXR (and optionally a PNG preview).
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "cli.h"
#include "sha256.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace {

namespace cli = tilesplat::cli;
namespace fs = std::filesystem;

constexpr const char* kProgram = "tilesplat-render";

struct RenderOptions {
  cli::CommonOptions common;
  std::string output;
  std::string png;
  std::array<float, 3> background = {0, 0, 0};
  tilesplat::PreviewOptions preview;
  bool half = false;
  tilesplat::ExrCompression compression = tilesplat::ExrCompression::kZip;
  bool no_depth = false;
  bool no_count = false;
  bool reference = false;
  int stochastic_frames = 0;  // --stochastic N: the sort-free compositor averaging N frames; 0 = sorted
  bool stats = false;
};

std::string single_quoted(const std::string& text) { return "'" + text + "'"; }

// What the EXR's renderSettings attribute records: everything that changes the image.
std::string settings_text(const tilesplat::RenderSettings& settings) {
  std::string text = "sort=" + settings.sort;
  text += " accuracy=" + tilesplat::to_string(settings.accuracy);
  text += " antialiasing=" + tilesplat::to_string(settings.antialiasing);
  text += " compositor=" + tilesplat::to_string(settings.compositor);
  if (settings.compositor == tilesplat::Compositor::kStochastic)
    text += " frames=" + std::to_string(settings.stochastic.frames) +
            " seed=" + std::to_string(settings.stochastic.seed);
  text += " lights=" + std::to_string(settings.lighting.lights.size());
  text += " background=";
  for (size_t c = 0; c < 3; ++c) {
    char digits[32];
    const auto end =
        std::to_chars(digits, digits + sizeof(digits), settings.background[c]).ptr;  // shortest exact
    if (c > 0) text += ',';
    text.append(digits, end);
  }
  return text;
}

// Library writers name the file in their messages; this keeps that true whatever they say.
std::string write_failure(const fs::path& path, const std::exception& error) {
  const std::string message = cli::one_line(error.what());
  if (message.find(path.filename().string()) != std::string::npos) return message;
  return "cannot write " + single_quoted(path.string()) + ": " + message;
}

void print_row(const std::string& name, const std::string& value, const std::string& unit) {
  if (unit.empty())
    std::printf("%-22s %14s\n", name.c_str(), value.c_str());
  else
    std::printf("%-22s %14s %s\n", name.c_str(), value.c_str(), unit.c_str());
}

void print_frame_stats(const tilesplat::FrameStats& stats, const tilesplat::DeviceInfo& device) {
  std::printf("device: %s (driver %s), subgroup size %u\n", device.name.c_str(), device.driver.c_str(),
              device.subgroup_size);
  for (const auto& pass : stats.passes) print_row(pass.name, cli::format_fixed(pass.gpu_ms, 3), "ms");
  print_row("gpu frame", cli::format_fixed(stats.gpu_ms, 3), "ms");
  print_row("cpu frame", cli::format_fixed(stats.cpu_ms, 3), "ms");
  print_row("gaussians", std::to_string(stats.gaussians), "");
  print_row("visible", std::to_string(stats.visible), "");
  print_row("intersections", std::to_string(stats.intersections), "");
  print_row("sort bits", std::to_string(stats.sort_bits), "");
  print_row("retries", std::to_string(stats.retries), "");
  print_row("device memory", cli::format_fixed(double(stats.device_bytes) / (1024.0 * 1024.0), 2), "MiB");
}

void add_render_options(cli::ArgParser& parser, RenderOptions& options) {
  cli::add_common_options(parser, options.common, cli::SortChoice::kOne);

  parser.section("output");
  parser.add_string("--output", "OUT.exr",
                    "the EXR to write (required): R G B A, plus Z (expected depth) and 'splats' (blended "
                    "splats per pixel) unless turned off; for a scene file, the channels its \"outputs\" list",
                    &options.output, "-o");
  parser.add_string("--png", "FILE.png", "also write an 8-bit sRGB preview of the colours", &options.png);
  parser.add_value("--exposure", "STOPS",
                   "brighten (or darken, if negative) the --png preview by 2^STOPS, -20 to 20 (default: the "
                   "scene file's, else 0)",
                   [&options](const std::string& text) {
                     const double stops = cli::parse_double("--exposure", text);
                     if (!(std::abs(stops) <= 20))
                       throw cli::UsageError("--exposure must be from -20 to 20 stops, got " + single_quoted(text));
                     options.preview.exposure_stops = stops;
                   });
  parser.add_value("--tone-map", "CURVE",
                   "the --png preview's tone curve: none (clip at 1), aces (filmic) or reinhard (x / (1 + x)) "
                   "(default: the scene file's, else none)",
                   [&options](const std::string& text) {
                     if (text == "none") options.preview.tone_map = tilesplat::ToneMap::kNone;
                     else if (text == "aces") options.preview.tone_map = tilesplat::ToneMap::kAces;
                     else if (text == "reinhard") options.preview.tone_map = tilesplat::ToneMap::kReinhard;
                     else
                       throw cli::UsageError("--tone-map must be none, aces or reinhard, got " + single_quoted(text));
                   });
  parser.add_switch("--half", "store the EXR channels as 16-bit HALF instead of 32-bit FLOAT", &options.half);
  parser.add_value(
      "--exr-compression", "METHOD",
      "zip (default, lossless), piz (lossless wavelet), dwaa (lossy on R G B, small files for review; A and "
      "Z stay lossless), or none",
      [&options](const std::string& text) {
        using tilesplat::ExrCompression;
        for (const ExrCompression c :
             {ExrCompression::kZip, ExrCompression::kPiz, ExrCompression::kDwaa, ExrCompression::kNone})
          if (text == tilesplat::to_string(c)) {
            options.compression = c;
            return;
          }
        throw cli::UsageError("--exr-compression must be zip, piz, dwaa or none, got " + single_quoted(text));
      });
  parser.add_switch("--no-depth", "do not compute or store the depth channel (Z)", &options.no_depth);
  parser.add_switch("--no-count", "do not compute or store the per-pixel splat count", &options.no_count);

  parser.section("rendering");
  parser.add_value("--background", "R,G,B", "linear background colour (default: the scene file's, else 0,0,0)",
                   [&options](const std::string& text) {
                     options.background = cli::parse_rgb("--background", text);
                   });
  parser.add_int("--stochastic", "N",
                 "composite without a depth sort: each splat kept per pixel with probability alpha, nearest kept "
                 "wins, the mean of N such frames (1 to 4096; converges to the sorted image as 1/sqrt(N))",
                 &options.stochastic_frames, 1, 4096);
  parser.add_switch("--reference",
                    "render with the float64 CPU reference instead of the GPU (slow; for checking)",
                    &options.reference);
  parser.add_switch("--stats",
                    "print the frame statistics to stdout: GPU ms per pass, frame ms, visible Gaussians, "
                    "intersections, retries",
                    &options.stats);
}

int run(int argc, char** argv) {
  cli::load_sort_plugins(argc, argv);  // before the parser lists and checks the sort names
  RenderOptions options;
  cli::ArgParser parser(kProgram, "tilesplat-render SCENE.ply|SCENE.json -o OUT.exr [options]",
                        "Renders one view of a 3D Gaussian Splatting scene with the Vulkan compute renderer "
                        "and writes it as an EXR. The camera comes from the trainer's cameras.json "
                        "(--cameras, --view), from the scene file's cameras (--view), or orbits the scene "
                        "(--azimuth, --elevation, --fov). A scene file's background and outputs apply unless "
                        "--background, --no-depth or --no-count say otherwise.");
  add_render_options(parser, options);
  if (cli::parse_and_handle_info_flags(parser, argc, argv, options.common)) return cli::kExitOk;
  cli::check_common_options(parser, options.common);
  if (options.output.empty()) throw cli::UsageError("missing -o OUT.exr: where to write the image (see --help)");
  if (!cli::has_extension(options.output, ".exr"))
    throw cli::UsageError("-o expects an .exr file, got " + single_quoted(options.output) +
                          " (use --png for a PNG preview)");
  if (!options.png.empty() && !cli::has_extension(options.png, ".png"))
    throw cli::UsageError("--png expects a .png file, got " + single_quoted(options.png));
  for (const char* preview_flag : {"--exposure", "--tone-map"})
    if (parser.seen(preview_flag) && options.png.empty())
      throw cli::UsageError(std::string(preview_flag) + " applies to the --png preview, and no --png was given");
  cli::check_distinct_paths({{"SCENE", options.common.scene},
                             {"--cameras", options.common.cameras},
                             {"-o", options.output},
                             {"--png", options.png}});
  if (options.reference) {
    if (parser.seen("--stochastic"))
      throw cli::UsageError("--stochastic is a GPU compositor; the --reference renderer blends sorted lists");
    for (const char* gpu_flag : {"--device", "--validation", "--sort", "--mode"})
      if (parser.seen(gpu_flag))
        cli::print_warning(kProgram, std::string(gpu_flag) + " has no effect with --reference (CPU renderer)");
  }
  // Fail before the (possibly long) load and render when the outputs cannot be written.
  cli::check_output_path(options.output, "-o");
  if (!options.png.empty()) cli::check_output_path(options.png, "--png");

  const cli::LoadedScene loaded = cli::load_scene_and_camera(options.common, kProgram);

  tilesplat::RenderSettings settings;
  if (!options.common.sorts.empty()) settings.sort = options.common.sorts.front();
  if (!options.common.modes.empty()) settings.accuracy = options.common.modes.front();
  cli::apply_scene_settings(loaded, settings);
  // The flags override the scene file.
  if (parser.seen("--background") || !loaded.description) settings.background = options.background;
  if (options.no_depth) settings.depth = false;
  if (options.no_count) settings.splat_count = false;
  if (options.common.antialiasing) settings.antialiasing = *options.common.antialiasing;
  if (options.stochastic_frames > 0) {
    settings.compositor = tilesplat::Compositor::kStochastic;
    settings.stochastic.frames = static_cast<uint32_t>(options.stochastic_frames);
  }
  tilesplat::PreviewOptions preview;
  if (loaded.description) {
    preview.exposure_stops = loaded.description->effects.exposure_stops;
    preview.tone_map = loaded.description->effects.tone_map;
  }
  if (parser.seen("--exposure")) preview.exposure_stops = options.preview.exposure_stops;
  if (parser.seen("--tone-map")) preview.tone_map = options.preview.tone_map;

  tilesplat::RenderImage image;
  std::string timing;
  if (options.reference) {
    const auto start = std::chrono::steady_clock::now();
    image = tilesplat::render_reference(loaded.scene, loaded.camera, settings);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    timing = "CPU reference " + cli::format_fixed(ms, 1) + " ms";
    if (options.stats) {
      print_row("cpu reference", cli::format_fixed(ms, 3), "ms");
      print_row("gaussians", std::to_string(loaded.scene.size()), "");
    }
  } else {
    const auto renderer = tilesplat::Renderer::create(cli::renderer_options(options.common));
    renderer->set_scene(loaded.scene);
    image = renderer->render(loaded.camera, settings);
    const tilesplat::FrameStats& stats = renderer->last_frame_stats();
    timing = "GPU " + cli::format_fixed(stats.gpu_ms, 2) + " ms, frame " + cli::format_fixed(stats.cpu_ms, 2) +
             " ms";
    if (options.stats) print_frame_stats(stats, renderer->device_info());
    if (const auto messages = renderer->validation_messages(); messages > 0)
      cli::print_warning(kProgram, std::to_string(messages) + " Vulkan validation messages (see above)");
  }
  if (image.width != loaded.camera.width || image.height != loaded.camera.height ||
      image.rgba.size() != image.pixels() * 4)
    throw std::runtime_error("the renderer returned a " + std::to_string(image.width) + "x" +
                             std::to_string(image.height) + " image for a " + std::to_string(loaded.camera.width) +
                             "x" + std::to_string(loaded.camera.height) + " camera");
  if (!settings.depth) image.depth.clear();
  if (!settings.splat_count) image.splat_count.clear();

  // The EXR first: a preview must never exist without the image it previews.
  tilesplat::ExrWriteOptions exr_options;
  exr_options.half = options.half;
  exr_options.alpha = !loaded.description || loaded.description->outputs.alpha;
  exr_options.attributes["commandLine"] = cli::command_line(kProgram, argc, argv);
  exr_options.camera = loaded.camera;  // worldToCamera, worldToNDC and the exact camera
  exr_options.compression = options.compression;
  exr_options.attributes["scene"] = loaded.path.string();
  exr_options.attributes["view"] = loaded.camera_description;
  if (loaded.view_index) {
    exr_options.attributes["viewIndex"] = std::to_string(*loaded.view_index);
    exr_options.attributes["viewName"] = loaded.view_name;
  }
  exr_options.attributes["sceneSha256"] = cli::sha256_file_hex(loaded.path);
  exr_options.attributes["renderSettings"] = settings_text(settings);
  try {
    tilesplat::write_exr(options.output, image, exr_options);
  } catch (const std::exception& error) {
    throw std::runtime_error(write_failure(options.output, error));
  }
  std::string written = options.output;
  if (!options.png.empty()) {
    try {
      tilesplat::write_png_preview(options.png, image, preview);
    } catch (const std::exception& error) {
      throw std::runtime_error(write_failure(options.png, error));
    }
    written += ", " + options.png;
  }

  std::fflush(stdout);
  const std::string summary = std::string(kProgram) + ": " + loaded.path.filename().string() + ", " +
                              cli::describe_scene(loaded.scene) + ", " + std::to_string(image.width) + "x" +
                              std::to_string(image.height) + ", " + loaded.camera_description + ", " + timing +
                              " -> " + written + "\n";
  std::fputs(summary.c_str(), stderr);
  return cli::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  return cli::run_app(kProgram, [argc, argv] { return run(argc, argv); });
}
