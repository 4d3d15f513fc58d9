// tilesplat-render's command line: its options, their declarations and the checks that need no
// file. The library part of the app, so that a test can parse every documented command as the app does.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "cli.h"
#include "lens_options.h"
#include "tilesplat/image.h"
#include "tilesplat/lens.h"
#include "tilesplat/renderer.h"
#include "tilesplat/shutter.h"

namespace tilesplat::render_app {

using cli::lens_for_frame;
using cli::lens_text;
using cli::LensFlags;

inline constexpr const char* kProgram = "tilesplat-render";
inline constexpr const char* kUsage = "tilesplat-render SCENE.ply|SCENE.json -o OUT.exr [options]";
inline constexpr const char* kDescription =
    "Renders a view of a 3D Gaussian Splatting scene with the Vulkan compute renderer "
    "and writes it as an EXR. The camera comes from a camera set (--cameras: the "
    "trainer's cameras.json, a transforms.json or a COLMAP model; --view), from the scene "
    "file's cameras (--view), or orbits the scene (--azimuth, --elevation, --fov). "
    "--views, --orbit N and --path render many frames in one process, resumably "
    "(out/manifest.jsonl) and in shards (--shard). A scene file's background and outputs "
    "apply unless --background, --no-depth or --no-count say otherwise.";

// --shutter and --shutter-samples: motion blur over a sequence's camera motion. The shutter opens at a
// frame's time and stays open for DEG/360 of the interval to the next frame (a film camera's shutter
// angle: 180 is half the interval).
struct ShutterFlags {
  std::optional<double> angle_deg;  // --shutter DEG, in (0, 360]
  int samples = 16;                 // --shutter-samples N
  ShutterScan scan = ShutterScan::kGlobal;  // --rolling-shutter DIRECTION
  SamplePattern pattern = SamplePattern::kEven;  // --sample-pattern
  bool enabled() const { return angle_deg.has_value(); }
};
// The shutter of a frame whose next frame's camera is `next`: off without --shutter, and for the last
// frame of a path (which has no next frame: it holds still).
Shutter shutter_for_frame(const ShutterFlags& flags, const std::optional<Camera>& next);
// "180deg:samples:16" for the EXR's renderSettings; empty when off.
std::string shutter_text(const ShutterFlags& flags);

struct RenderOptions {
  tilesplat::cli::CommonOptions common;
  std::string output;
  std::string png;
  std::array<float, 3> background = {0, 0, 0};
  PreviewOptions preview;
  bool half = false;
  ExrCompression compression = ExrCompression::kZip;
  ColourEncoding exr_colour = ColourEncoding::kSceneLinear;
  bool no_depth = false;
  bool no_count = false;
  bool reference = false;
  int stochastic_frames = 0;  // --stochastic N: the sort-free compositor averaging N frames; 0 = sorted
  tilesplat::StochasticSampler stochastic_sampler =
      tilesplat::StochasticSampler::kHash;  // --stochastic-sampler
  LensFlags lens;
  cli::CameraModelFlags camera_model;  // --fisheye, --orthographic, --equirectangular
  ShutterFlags shutter;
  bool stats = false;
  uint64_t memory_budget = 0;  // --memory-budget: RenderSettings::memory_budget (0: the device's limits)
  bool read_in_parts = false;  // --read-in-parts: a PLY, SPZ or SOG read in parts (else when large)
  PixelRegion region;          // --region: RenderSettings::region (whole: the image)
  // Many frames in one run.
  std::string views;      // --views: a selection of the camera set's views
  int orbit_frames = 0;   // --orbit N
  std::string path_file;  // --path KEYFRAMES.json
  int path_frames = 0;    // --frames N (with --path)
  std::optional<std::string> shard;
  std::optional<int> shard_count;
  bool force = false;
  bool quiet = false;
  std::string merge_folder;  // --merge-manifests
};

// Declares every flag of tilesplat-render.
void add_render_options(tilesplat::cli::ArgParser& parser, RenderOptions& options);

// Whether the flags ask for a sequence of frames rather than one view.
bool renders_sequence(const tilesplat::cli::ArgParser& parser);

// The mistakes a parsed command line can show before any file is read: flags that do not go together,
// a missing or misnamed -o, --png or frame pattern, an output that is also an input. Throws UsageError.
void check_render_flags(const tilesplat::cli::ArgParser& parser, const RenderOptions& options);

}  // namespace tilesplat::render_app
