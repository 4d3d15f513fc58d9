// tilesplat-bench --lod-curve BUDGETS: what a LOD set's or a .rad LOD tree's levels and splat budgets cost,
// and how far each image is from the finest level's.
//
// One LOD set (lod-meta.json) or tree (.rad), rendered at the chosen views: its levels whole (a set's every
// level; a tree's level 0 and each level with at most half the Gaussians of the one listed before it), then
// what each view calls for under each splat budget (select_lod_levels, SplatLodTree::select). Per row: the Gaussians drawn, the GPU
// frame time (median over repeats, then views), the host's time to choose and gather the levels, and
// the image's PSNR and largest error against level 0 from the same view (the mean PSNR over the views).
// The frames of all rows are interleaved (row after row, repeat after repeat) so that a CPU driver's
// drifting speed affects every row alike.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/lod_set.h"
#include "tilesplat/lod_tree.h"
#include "tilesplat/renderer.h"

namespace tilesplat::lod_report {

struct Row {
  int level = -1;       // a level drawn whole, or -1 for a splat budget
  uint64_t budget = 0;  // the budget of a budget row
  // Measured: means (splats, PSNR) or medians (times) over the views.
  double splats = 0;
  double gpu_ms = 0;
  double select_ms = 0;  // choosing the levels and gathering the chunks on the host (budget rows)
  double psnr_db = 0;    // against level 0 from the same view; +inf where every view is identical
  double max_abs = 0;    // the largest over the views
};
std::string row_label(const Row& row);  // "level 2", "budget 10,000"

// What the report draws from: a set's or a tree's levels, and what a view chooses under a budget.
struct Source {
  std::vector<int> levels;  // the levels measured whole, level 0 first
  std::function<GaussianScene(int level)> load_level;
  std::function<GaussianScene(const Camera& view, uint64_t budget)> choose;
};
Source source_of(const LodSet& set);
Source source_of(const SplatLodTree& tree);

// The source's levels, then one row per budget (ascending).
std::vector<Row> plan_rows(const Source& source, std::vector<uint64_t> budgets);

struct Options {
  std::vector<Camera> views;
  int warmup = 1;
  int repeat = 5;
  std::string sort = "radix";
  RenderSettings settings;  // what every row shares besides the sort
};

struct Run {
  DeviceInfo device;
  uint64_t validation_messages = 0;
};
int work_units(const std::vector<Row>& rows, const Options& options);
// Renders every row at every view and fills in the measurements. progress(done, total, what) as it goes.
Run measure(const RendererOptions& renderer_options, const Source& source, std::vector<Row>& rows,
            const Options& options, const std::function<void(int, int, const std::string&)>& progress);

std::string text_table(const std::vector<Row>& rows);
std::string markdown(const std::vector<Row>& rows, const std::string& scene, const DeviceInfo& device,
                     const std::string& command);
std::string csv(const std::vector<Row>& rows, const std::string& scene, const DeviceInfo& device);
// PSNR against the Gaussians drawn, levels and budgets as two series.
std::string svg(const std::vector<Row>& rows, const std::string& scene, const DeviceInfo& device);

}  // namespace tilesplat::lod_report
