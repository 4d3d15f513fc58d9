// tilesplat-bench's options: the flags of every mode and the checks that span several of them.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "accuracy_report.h"
#include "cli.h"
#include "sample_curve.h"

namespace tilesplat::bench {

inline constexpr const char* kProgram = "tilesplat-bench";
inline constexpr const char* kUsage = "tilesplat-bench SCENE.ply|SCENE.json [SCENE...] [options]";
inline constexpr const char* kDescription =
    "Renders 3D Gaussian Splatting scenes repeatedly and prints the GPU time of every pass "
    "(median, min, max over the measured frames) for each sort strategy, with the frame's "
    "CPU time, visible Gaussians, intersections and device memory. Every scene is measured "
    "at every size (--resolutions) from every camera of its path (--views of --cameras, or "
    "--orbit); a progress bar on stderr counts the frames of the whole run.";

struct BenchOptions {
  tilesplat::cli::CommonOptions common;
  int warmup = 2;
  int repeat = 10;
  std::string csv;
  std::string json;
  std::string plot;
  std::vector<tilesplat::cli::ImageSize>
      resolutions;         // --resolutions; empty: the one size of --width/--height
  std::vector<int> views;  // --views; empty: --view alone (or every view, with all_views)
  bool all_views = false;
  int orbit = 0;  // --orbit N: N orbit cameras; 0: the one at --azimuth
  tilesplat::cli::CameraModelFlags camera_model;  // --fisheye, --orthographic, --equirectangular
  bool sort_bench = false;
  bool accuracy = false;  // --accuracy: the error/time report
  bool effects = false;   // --effects: the per-effect cost table
  bool formats = false;   // --formats: what each file of a scene costs against its lossless PLY
  bool scaling = false;   // --scaling: frame time and memory against Gaussian count and image size
  int tile_copies = 0;    // --tile-copies N: with --scaling, also N copies of the largest scene
  std::vector<uint64_t> lod_budgets;  // --lod-curve: a LOD set's levels and these splat budgets
  // --sample-curve EFFECT[:N,...]: an averaged effect's sample counts against error and time
  std::optional<tilesplat::sample_curve::Effect> sample_curve;
  std::vector<int> sample_counts = tilesplat::sample_curve::kDefaultCounts;
  uint64_t memory_budget = 0;  // --memory-budget: frames under RenderSettings::memory_budget (0: none)
  bool backward =
      false;  // --backward: each measured frame is a training step, forward then Renderer::backward
  std::string markdown;
  accuracy::CameraPath path = accuracy::CameraPath::kPan;
  int path_frames = 6;
  double path_step = 0.0005;
  double consistency_angle = 0.08;
  std::vector<int> sort_sizes{10, 12, 14, 16, 18, 20, 22, 24};  // log2 of the key counts
  std::vector<int> key_bits{32, 64};
  std::string command;  // the command as typed, recorded in every output
};

// Declares every flag of tilesplat-bench (add_common_options and the modes' own).
void add_bench_options(tilesplat::cli::ArgParser& parser, BenchOptions& options);

// "--views 0,2,5": the distinct integers of a comma list, each in [min, max]. Throws UsageError.
std::vector<int> parse_int_list(std::string_view flag, const std::string& text, int min, int max);

// What the parser cannot check flag by flag, for the frame benchmark and the reports. Throws UsageError.
void check_frame_options(const tilesplat::cli::ArgParser& parser, const BenchOptions& options);

// Every check of a parsed command line that needs no file, for whichever mode it asks for
// (--sort-bench, a report, or the frame benchmark: check_frame_options). Throws UsageError.
void check_bench_flags(const tilesplat::cli::ArgParser& parser, const BenchOptions& options);

// Before any work: no output may overwrite an input or another output, the plot must be an SVG, and
// every output's directory must exist, so that a long run never ends in a file it cannot write.
void check_outputs(const BenchOptions& options,
                   const std::vector<std::pair<std::string, std::filesystem::path>>& inputs);

// Every SCENE and --cameras file, which no output may overwrite.
std::vector<std::pair<std::string, std::filesystem::path>> scene_and_camera_inputs(
    const BenchOptions& options);

// Writes the output files that were asked for (each atomically), warns about the run's validation
// messages, and returns " -> a.csv, b.json" for the closing line.
std::string write_outputs(const std::vector<std::pair<std::string, std::function<std::string()>>>& files,
                          uint64_t validation_messages);

}  // namespace tilesplat::bench
