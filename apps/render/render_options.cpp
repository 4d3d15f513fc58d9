#include "render_options.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <utility>

#include "frame_sequence.h"

namespace tilesplat::render_app {

namespace cli = tilesplat::cli;
namespace fs = std::filesystem;

bool renders_sequence(const cli::ArgParser& parser) {
  return parser.seen("--views") || parser.seen("--orbit") || parser.seen("--path");
}

namespace {

using cli::single_quoted;

// The flag mistakes of a many-frame run, before anything is loaded.
void check_sequence_flags(const cli::ArgParser& parser, const RenderOptions& options) {
  const int sources = int(parser.seen("--views")) + int(parser.seen("--orbit")) + int(parser.seen("--path"));
  if (sources > 1)
    throw cli::UsageError("--views, --orbit and --path each choose the frames: give one of them");
  if (parser.seen("--frames") != parser.seen("--path"))
    throw cli::UsageError(parser.seen("--path")
                              ? "--path needs --frames N: how many frames to render along it"
                              : "--frames applies to --path KEYS.json");
  if (!renders_sequence(parser)) {
    for (const char* flag : {"--shard", "--shard-count", "--force"})
      if (parser.seen(flag))
        throw cli::UsageError(std::string(flag) + " applies to many frames (--views, --orbit or --path)");
    return;
  }
  if (parser.seen("--view"))
    throw cli::UsageError("--view renders one view; --views chooses several, not both");
  if (!options.common.cameras.empty() && !parser.seen("--views"))
    throw cli::UsageError(
        "--cameras gives the views that --views chooses from; --orbit and --path make their own");
  if (parser.seen("--path"))
    for (const char* orbit_flag : {"--azimuth", "--elevation", "--fov", "--distance"})
      if (parser.seen(orbit_flag))
        throw cli::UsageError(std::string(orbit_flag) +
                              " shapes the orbit; the keyframes of --path set the camera");
  if (options.stats)
    throw cli::UsageError(
        "--stats prints one frame's statistics; with many frames the manifest records each one's GPU ms");
  if (parser.seen("--shard-count") && parser.seen("--shard"))
    throw cli::UsageError("--shard-count is for Kubernetes Indexed Jobs; --shard I/N names the count itself");
}

}  // namespace

void add_render_options(cli::ArgParser& parser, RenderOptions& options) {
  cli::add_common_options(parser, options.common, cli::SortChoice::kOne);

  parser.section("output");
  parser.add_string(
      "--output", "OUT.exr",
      "the EXR to write (required): R G B A, plus Z (expected depth) and 'splats' (blended "
      "splats per pixel) unless turned off; for a scene file, the channels its \"outputs\" list",
      &options.output, "-o");
  parser.add_string(
      "--png", "FILE.png",
      "also write an 8-bit sRGB preview: the trained colours, round(255 c), as other viewers show "
      "them",
      &options.png);
  parser.add_value(
      "--exposure", "STOPS",
      "brighten (or darken, if negative) the --png preview by 2^STOPS of linear light, -20 to 20 "
      "(default: the scene file's, else 0)",
      [&options](const std::string& text) {
        const double stops = cli::parse_double("--exposure", text);
        if (!(std::abs(stops) <= 20))
          throw cli::UsageError("--exposure must be from -20 to 20 stops, got " + single_quoted(text));
        options.preview.exposure_stops = stops;
      });
  parser.add_value(
      "--tone-map", "CURVE",
      "the --png preview's tone curve, on linear light: none (clip at 1), aces (filmic) or reinhard "
      "(x / (1 + x)) (default: the scene file's, else none)",
      [&options](const std::string& text) {
        if (text == "none")
          options.preview.tone_map = tilesplat::ToneMap::kNone;
        else if (text == "aces")
          options.preview.tone_map = tilesplat::ToneMap::kAces;
        else if (text == "reinhard")
          options.preview.tone_map = tilesplat::ToneMap::kReinhard;
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
  parser.add_value(
      "--exr-colour", "ENCODING",
      "what the EXR's R G B hold: linear (default: scene-linear Rec.709, the sRGB decoding of the "
      "trained colours, as compositing tools expect) or display (the trained colours as rendered, "
      "bit for bit); the header's colorInteropID says which (docs/colour.md)",
      [&options](const std::string& text) {
        if (text == "linear")
          options.exr_colour = tilesplat::ColourEncoding::kSceneLinear;
        else if (text == "display")
          options.exr_colour = tilesplat::ColourEncoding::kSrgbDisplay;
        else
          throw cli::UsageError("--exr-colour must be linear or display, got " + single_quoted(text));
      });
  parser.add_switch("--no-depth", "do not compute or store the depth channel (Z)", &options.no_depth);
  parser.add_switch("--no-count", "do not compute or store the per-pixel splat count", &options.no_count);

  parser.section("rendering");
  parser.add_value(
      "--background", "R,G,B",
      "background colour, in the trained colours' display values (default: the scene file's, else "
      "0,0,0)",
      [&options](const std::string& text) { options.background = cli::parse_rgb("--background", text); });
  parser.add_int(
      "--stochastic", "N",
      "composite without a depth sort: each splat kept per pixel with probability alpha, nearest kept "
      "wins, the mean of N such frames (1 to 4096; converges to the sorted image as 1/sqrt(N))",
      &options.stochastic_frames, 1, 4096);
  parser.add_value(
      "--stochastic-sampler", "NAME",
      "how the stochastic compositor draws its thresholds: hash (independent frames, the default) "
      "or stratified (each splat's N thresholds at a pixel one per stratum of [0, 1): faster "
      "convergence) or sobol (stratified at powers of two, and progressive: the effects' Owen-scrambled "
      "sequence)",
      [&options](const std::string& text) {
        try {
          options.stochastic_sampler = tilesplat::parse_stochastic_sampler(text);
        } catch (const std::invalid_argument&) {
          throw cli::UsageError("--stochastic-sampler must be hash, stratified or sobol, got " +
                                cli::single_quoted(text));
        }
      });
  parser.add_switch("--reference",
                    "render with the float64 CPU reference instead of the GPU (slow; for checking)",
                    &options.reference);

  cli::add_lens_options(parser, options.lens,
                        "pinhole frames averaged over the aperture (1 to 4096, default 32)");
  parser.add_value(
      "--sample-pattern", "PATTERN",
      "where the lens positions and the shutter's times lie: even (the default: the golden-angle spiral and "
      "the middles of equal slices, spread for the count) or sobol (a progressive sequence: the first N "
      "samples of a longer frame are the frame of N; docs/effects.md)",
      [&options](const std::string& text) {
        try {
          options.lens.pattern = options.shutter.pattern = tilesplat::parse_sample_pattern(text);
        } catch (const std::invalid_argument&) {
          throw cli::UsageError("--sample-pattern must be even or sobol, got " + cli::single_quoted(text));
        }
      });
  parser.section("motion blur (with --orbit or --path: the mean of frames over each frame's motion)");
  parser.add_value(
      "--shutter", "DEG",
      "the shutter angle: open from each frame's time for DEG/360 of the way to the next frame "
      "(180: half of it, as a film camera; up to 360)",
      [&options](const std::string& text) {
        const double degrees = cli::parse_double("--shutter", text);
        if (!(degrees > 0 && degrees <= 360))
          throw cli::UsageError("--shutter must be in (0, 360] degrees, got " + single_quoted(text));
        options.shutter.angle_deg = degrees;
      });
  parser.add_int("--shutter-samples", "N",
                 "times averaged over the open shutter, or a rolling shutter's bands (1 to 4096, default 16)",
                 &options.shutter.samples, 1, kMaxShutterSamples);
  parser.add_value("--rolling-shutter", "SCAN",
                   "read the image out in --shutter-samples bands, each exposed at its time instead of "
                   "averaged: top-to-bottom, bottom-to-top, left-to-right or right-to-left",
                   [&options](const std::string& text) {
                     try {
                       options.shutter.scan = parse_shutter_scan(text);
                     } catch (const std::invalid_argument&) {
                       throw cli::UsageError(
                           "--rolling-shutter must be top-to-bottom, bottom-to-top, "
                           "left-to-right or right-to-left, got " +
                           single_quoted(text));
                     }
                     if (options.shutter.scan == ShutterScan::kGlobal)
                       throw cli::UsageError(
                           "--rolling-shutter takes a direction; a global shutter is --shutter "
                           "alone");
                   });

  cli::add_camera_model_options(parser, options.camera_model);
  parser.add_switch(
      "--stats",
      "print the frame statistics to stdout: GPU ms per pass, frame ms, visible Gaussians, "
      "intersections, retries, device memory and its peak, scene parts, image bands, peak resident memory",
      &options.stats);
  cli::add_memory_budget_option(
      parser, options.memory_budget,
      "--stats prints the parts and peaks; without a budget, a frame past the device's limits still renders "
      "in parts; ");
  parser.add_switch(
      "--read-in-parts",
      "read a binary PLY, an SPZ or a SOG part by part as the frame draws it, never whole as floats: only "
      "the Gaussians' positions stay on the host, and an SPZ's packed bytes or a SOG's texels (a scene whose "
      "floats would take more than half of the host's memory is read so without it); the frames are the "
      "same, to the bit",
      &options.read_in_parts);
  cli::add_splat_budget_option(parser, options.common);
  parser.add_value("--region", "X,Y,WxH",
                   "render only these pixels of each frame (e.g. 0,540,1920x64), each the whole frame's to "
                   "the bit: the EXR holds them as its data window inside the whole image's display window, "
                   "where compositing tools place it; only the tiles the region meets are binned and sorted",
                   [&options](const std::string& text) {
                     try {
                       options.region = parse_pixel_region(text);
                     } catch (const std::invalid_argument& error) {
                       throw cli::UsageError(std::string("--region: ") + error.what());
                     }
                   });

  parser.section("many frames (one process; -o and --png then take a frame number: out/view_%04d.exr)");
  parser.add_string(
      "--views", "SELECTION",
      "render these views of the cameras: all, a list such as 0,3,8-11, or every:K (0, K, 2K, ...; "
      "every:8 is the 3DGS evaluation split); the frame number is the view index",
      &options.views);
  parser.add_int("--orbit", "N",
                 "render N frames around the scene (from --azimuth, 360/N degrees apart, at --elevation, "
                 "--fov, --distance)",
                 &options.orbit_frames, 1, 1000000);
  parser.add_string("--path", "KEYS.json",
                    "render --frames N frames along a keyframed camera path (Catmull-Rom positions, slerped "
                    "rotations; the format is docs/camera-paths.md)",
                    &options.path_file);
  parser.add_int("--frames", "N", "how many frames --path renders", &options.path_frames, 1, 1000000);
  parser.add_value("--shard", "I/N",
                   "render only frames k with k mod N == I (default: from a Slurm job array's "
                   "SLURM_ARRAY_TASK_ID/COUNT/MIN, or a Kubernetes Indexed Job's JOB_COMPLETION_INDEX)",
                   [&options](const std::string& text) { options.shard = text; });
  parser.add_value("--shard-count", "N",
                   "the number of shards of a Kubernetes Indexed Job (its completions; default: "
                   "TILESPLAT_SHARD_COUNT)",
                   [&options](const std::string& text) {
                     options.shard_count = cli::parse_int("--shard-count", text, 1, 1000000);
                   });
  parser.add_switch("--force",
                    "render every frame again, even those the manifest lists as done with matching files",
                    &options.force);
  parser.add_switch("--quiet", "no progress bar or progress lines (errors and warnings still print)",
                    &options.quiet);
  parser.add_string("--merge-manifests", "FOLDER",
                    "check that the shards' manifests in FOLDER cover every frame exactly once with intact "
                    "files, and write their union to FOLDER/manifest.jsonl (no rendering)",
                    &options.merge_folder);
}

void check_render_flags(const cli::ArgParser& parser, const RenderOptions& options) {
  cli::check_common_options(parser, options.common);
  check_sequence_flags(parser, options);
  if (options.output.empty())
    throw cli::UsageError("missing -o OUT.exr: where to write the image (see --help)");
  if (!cli::has_extension(options.output, ".exr"))
    throw cli::UsageError("-o expects an .exr file, got " + single_quoted(options.output) +
                          " (use --png for a PNG preview)");
  if (!options.png.empty() && !cli::has_extension(options.png, ".png"))
    throw cli::UsageError("--png expects a .png file, got " + single_quoted(options.png));
  for (const char* preview_flag : {"--exposure", "--tone-map"})
    if (parser.seen(preview_flag) && options.png.empty())
      throw cli::UsageError(std::string(preview_flag) +
                            " applies to the --png preview, and no --png was given");
  cli::check_distinct_paths({{"SCENE", options.common.scene},
                             {"--cameras", options.common.cameras},
                             {"-o", options.output},
                             {"--png", options.png}});
  const bool stochastic =
      parser.seen("--stochastic") || options.common.compositor == tilesplat::Compositor::kStochastic;
  if (options.reference && options.memory_budget > 0)
    throw cli::UsageError(
        "--memory-budget bounds the GPU renderer's device memory; the --reference renderer renders on the "
        "host");
  if (parser.seen("--lod") && parser.seen("--splat-budget"))
    throw cli::UsageError(
        "--lod draws one level of a LOD set and --splat-budget chooses the levels per frame: one of them");
  if (parser.seen("--stochastic-sampler") && !stochastic)
    throw cli::UsageError("--stochastic-sampler is the stochastic compositor's: add --stochastic N");
  if (options.reference && stochastic)
    throw cli::UsageError(
        "the stochastic compositor is the GPU's; the --reference renderer has the sorted and raster rules");
  if (parser.seen("--stochastic") && options.common.compositor &&
      *options.common.compositor != tilesplat::Compositor::kStochastic)
    throw cli::UsageError(
        "--stochastic N is the stochastic compositor; it cannot be combined with --compositor " +
        tilesplat::to_string(*options.common.compositor));
  cli::check_camera_model_options(options.camera_model);
  if (options.camera_model.enabled() && options.lens.enabled())
    throw cli::UsageError("depth of field (--aperture, --f-stop) needs a pinhole camera, not " +
                          std::string(options.camera_model.fisheye_fov_deg ? "--fisheye"
                                      : options.camera_model.view_height   ? "--orthographic"
                                                                           : "--equirectangular"));
  // --shutter-samples and --sample-pattern may shape the scene file's shutter or lens instead, which the
  // scene's load tells (reshape_scene_effects).
  if (parser.seen("--rolling-shutter") && !options.shutter.enabled())
    throw cli::UsageError("--rolling-shutter shapes the shutter, and no --shutter gave one");
  if (options.shutter.enabled() && !parser.seen("--orbit") && !parser.seen("--path"))
    throw cli::UsageError(
        "--shutter blurs the camera's motion from one frame to the next: it needs --orbit or "
        "--path");
  cli::check_lens_options(parser, options.lens);
  if (options.shutter.pattern != SamplePattern::kEven && options.shutter.scan != ShutterScan::kGlobal)
    throw cli::UsageError(
        "--rolling-shutter exposes its bands at the even pattern's times, in order: drop --sample-pattern");
  const bool sequence = renders_sequence(parser);
  // Fail before the (possibly long) load and render when the outputs cannot be written.
  if (sequence)
    for (const auto& [flag, pattern] : {std::pair{"-o", options.output}, std::pair{"--png", options.png}}) {
      if (pattern.empty()) continue;
      cli::frame_file(flag, pattern, 0);  // throws for a malformed pattern
      if (cli::has_frame_number(fs::path(pattern).parent_path().string()))
        throw cli::UsageError(
            std::string(flag) + " " + single_quoted(pattern) +
            ": the frame number belongs in the file name, not the folder (the folder holds the "
            "manifest)");
    }
}

Shutter shutter_for_frame(const ShutterFlags& flags, const std::optional<Camera>& next) {
  if (!flags.enabled() || !next) return {};
  return {.open = 0,
          .close = *flags.angle_deg / 360.0,
          .samples = flags.samples,
          .end_camera = next,
          .scan = flags.scan,
          .pattern = flags.pattern};
}

std::string shutter_text(const ShutterFlags& flags) {
  if (!flags.enabled()) return {};
  char angle[32];
  const auto end = std::to_chars(angle, angle + sizeof angle, *flags.angle_deg).ptr;  // shortest exact
  std::string text = std::string(angle, end) + "deg:samples:" + std::to_string(flags.samples);
  if (flags.scan != ShutterScan::kGlobal) text += std::string(":rolling:") + shutter_scan_name(flags.scan);
  if (flags.pattern != SamplePattern::kEven)
    text += std::string(":pattern:") + sample_pattern_name(flags.pattern);
  return text;
}

}  // namespace tilesplat::render_app
