// The frame benchmark: every scene loaded once, measured from every camera of its path at every size
// with every sort strategy; its tables, CSV, JSON and chart. The reports (--accuracy, --effects,
// --formats) plan their cameras with plan_cases too.
#pragma once

#include <string>
#include <vector>

#include "bench_options.h"
#include "bench_results.h"
#include "cli.h"

namespace tilesplat::bench {

struct BenchScene {
  tilesplat::cli::LoadedScene loaded;  // the camera fields are unused: the cameras are in the run's cases
  std::string name;                    // the file name
  std::string description;             // "31,000 Gaussians (SH2)"
  uint64_t gaussians = 0;  // kept apart from loaded.scene, which is released once the scene is measured
  int sh_degree = 0;
  std::string cameras;  // --cameras for this scene; empty: the scene file's cameras, else an orbit
};

// One camera of the run, a row of the results per sort strategy.
struct Case {
  size_t scene = 0;        // index into the scenes
  size_t size = 0;         // index into the run's sizes
  std::string view_label;  // short: "view 2", "azimuth 120.0"
  tilesplat::cli::NamedCamera camera;
  std::vector<StrategyResult> results;  // one per sort, in --sort order
};

// The cases of one scene at one size (all the views of its path), and per sort strategy the
// statistics over those views of each view's median.
struct Group {
  std::vector<const Case*> cases;
  std::vector<StrategyResult> over_views;
};

// The cameras of one scene: views of its cameras.json, or orbit positions evenly spaced in azimuth,
// each at every size. Out-of-range views and sizes fail here, before anything is measured.
std::vector<Case> plan_cases(const BenchOptions& options, const BenchScene& scene, size_t scene_index,
                             const std::vector<tilesplat::cli::ImageSize>& sizes);

// The frame benchmark (tilesplat-bench without a report flag). Returns the exit code.
int run_frame_bench(const BenchOptions& options);

// With "auto" among the sorts: which strategy it stands for on this device (its rows are labelled auto).
void print_auto_choice(const Renderer& renderer, const std::vector<std::string>& sorts);

}  // namespace tilesplat::bench
