// tilesplat-bench --accuracy: what each approximation costs in error and buys in time.
//
// For each scene, each accuracy mode combination is rendered at the chosen views (timed over
// repeats) and compared with the float64 CPU reference of the same view: PSNR, SSIM and max abs
// error. Along a short camera path (an orbit, a pan or a sideways dolly from the first view) the frame-to-frame change
// that the reference does not have is measured: popping. The results go to a table on stdout and,
// as asked, Markdown, CSV and one Pareto plot (error against time) per scene.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/renderer.h"

namespace tilesplat::accuracy {

// The modes measured when none are given: each approximation alone, then combinations that matter.
std::vector<AccuracyModes> default_modes();

// Whether a mode combination changes anything for a scene of this SH degree (an SH cap at or above
// the scene's degree does not; such rows are left out of a report rather than shown as free).
bool applies_to(const AccuracyModes& modes, int scene_sh_degree);

// The camera path the popping is measured on, each a small step per frame from the first view:
enum class CameraPath {
  kDolly,  // sideways along the camera's x axis: view-space depths only shift, so centre-depth order never flips
  kPan,    // turning in place about the camera's y axis: depths along each ray stay, centre depths do not
  kOrbit,  // around the scene centre about the camera's y axis: what a viewer's user does
};
const char* to_string(CameraPath path);
std::optional<CameraPath> parse_camera_path(const std::string& text);  // "dolly", "pan", "orbit"

// `frames` cameras from `start`. A step moves the dolly by step_fraction times the distance from the
// camera to `centre`, and turns the pan and the orbit by step_fraction radians (so that the scene centre
// moves across the view by about the same amount on each path).
std::vector<Camera> camera_path(CameraPath kind, const Camera& start, const std::array<double, 3>& centre, int frames,
                                double step_fraction);

struct PassTime {
  std::string name;
  double ms = 0;  // median over the repeats, then over the views
};

struct ModeResult {
  AccuracyModes modes;
  Compositor compositor = Compositor::kSorted;
  std::string name;     // to_string(modes), after the compositor's name when it is not the sorted one
  double frame_ms = 0;  // median GPU frame time: median over repeats per view, median over views
  std::vector<PassTime> passes;
  uint64_t intersections = 0;  // at the first view
  double psnr_db = 0;          // against the float64 reference, mean over the views
  double ssim = 0;             // mean over the views
  double max_abs = 0;          // largest over the views
  // Another compositor than the sorted one: PSNR against the sorted compositor's image of the same
  // modes, mean over the views (what the compositor costs by itself); NaN for the sorted rows.
  double psnr_vs_sorted_db = 0;
  double sorted_frame_ms = 0;  // and the sorted compositor's frame time, timed alike in the same run
  // The raster compositor: PSNR against the float64 reference's raster rule (render_reference with
  // Compositor::kRaster), mean over the views: the GPU held to its own definition; NaN for the others.
  double psnr_vs_rule_db = 0;
  // PSNR against the float64 reference's exact per-pixel order (ReferenceOrder::kRayDepth), mean over
  // the views: what per-pixel re-sorting approaches; NaN where a view's camera is not a pinhole.
  double psnr_vs_ray_order_db = 0;
  // Along the camera path, per consecutive pair of frames (means over the pairs):
  double frame_change = 0;     // mean |frame t+1 - frame t|
  double flicker = 0;          // fraction of pixels whose change exceeds kFlickerThreshold: pops
  double excess = 0;           // temporal_excess().mean_abs: change the float64 reference does not have
  // Per consecutive triple of frames (means over the triples), popping(): the second difference,
  // which smooth motion cancels and order flips do not.
  double pops = 0;             // fraction of pixels whose second difference exceeds kFlickerThreshold
  double pop_mean = 0;         // mean second difference over pixels and RGB
  // Per consecutive pair of frames, depth_warp_difference(): frame t warped onto frame t + 1 by the
  // rendered depth (what the motion reveals or hides left out), over blocks of kWarpBlock pixels.
  double warp_pops = 0;  // fraction of blocks whose difference exceeds kWarpThreshold
  double warp_mean = 0;  // mean difference over the blocks and RGB
  std::vector<double> warp_pops_per_step;  // the fraction for each pair, frames 0-1, 1-2, ...
  // Between the first view and the same camera turned by Options::consistency_angle, both rendered at
  // kConsistencyScale times its size: rotation_inconsistency() over blocks of kConsistencyScale * 4
  // pixels, what re-sorting along each pixel's ray is for.
  double inconsistency = 0;       // fraction of blocks whose difference exceeds kConsistencyThreshold
  double inconsistency_mean = 0;  // mean difference over the blocks and RGB
};

// A pixel "pops" between two frames of the slow path when a channel changes by more than this.
constexpr double kFlickerThreshold = 0.05;

// The view-consistency pair is rendered at this many times the first view's size and compared over
// blocks of kConsistencyBlock pixels: one block per 4x4 pixels of the view.
constexpr int kConsistencyScale = 2;
constexpr int kConsistencyBlock = 4 * kConsistencyScale;
constexpr double kConsistencyThreshold = 0.01;

// The depth-warped popping of the path compares blocks of this many pixels of the view's size.
constexpr int kWarpBlock = 4;
constexpr double kWarpThreshold = 0.01;

struct SceneReport {
  std::string scene;  // file name
  std::string description;  // "31,000 Gaussians (SH2)"
  std::string views;        // "views 0, 3 of cameras.json at 480x270"
  CameraPath path = CameraPath::kPan;
  int path_frames = 0;
  double path_step = 0;
  double reference_change = 0;   // the float64 reference's own mean frame-to-frame change on the path
  double reference_flicker = 0;  // and its fraction of popping pixels
  double reference_pops = 0;     // its popping() fraction (it blends in centre-depth order: it pops too)
  double reference_warp_pops = 0;  // its depth_warp_difference() fraction (ModeResult::warp_pops)
  std::vector<double> reference_warp_pops_per_step;
  double consistency_angle = 0;  // radians; 0: not measured
  double reference_inconsistency = 0;       // the float64 reference's (centre-depth order: not 0)
  double reference_inconsistency_mean = 0;
  // The same pair rendered by the float64 reference in the exact ray order (ReferenceOrder::kRayDepth); NaN
  // where the view is not a pinhole's. Not 0 either: where two splats' ray depths cross within a pixel the
  // blend order flips, an edge the turned view's resampling does not reproduce (docs/accuracy.md).
  double exact_order_inconsistency = std::numeric_limits<double>::quiet_NaN();
  double exact_order_inconsistency_mean = std::numeric_limits<double>::quiet_NaN();
  std::vector<ModeResult> modes;
};

struct Options {
  std::vector<AccuracyModes> modes;  // empty: default_modes()
  // The compositor of every row (tilesplat-bench --compositor); none: the sorted one (report_rows).
  std::optional<Compositor> compositor;
  std::vector<Camera> views;         // the measured views (the first one starts the path)
  std::vector<std::string> view_names;
  int warmup = 1;
  int repeat = 3;
  CameraPath path = CameraPath::kPan;
  int path_frames = 6;              // frames of the path (0: no temporal measurement)
  double path_step = 0.0005;        // per frame (see camera_path())
  double consistency_angle = 0.08;  // radians the camera turns in place for the view-consistency pair; 0: none
  std::string sort = "radix";
};

// One row of a report: a mode combination drawn by a compositor.
struct Row {
  AccuracyModes modes;
  Compositor compositor = Compositor::kSorted;
};
// The rows of a report on a scene of this SH degree: Options::modes (or default_modes()) that apply,
// by Options::compositor (the sorted one when none is given), leaving out the modes a compositor cannot
// draw (re-sorting for the raster and the stochastic one, approximate depth keys for the stochastic
// one); the default report (neither modes nor a compositor given) ends with the raster compositor's
// row of the reference modes.
std::vector<Row> report_rows(const Options& options, int scene_sh_degree);
std::string row_name(const Row& row);  // "depth16", "raster", "raster+depth16"

// Measures one scene. progress(done, total, what) is called as it goes.
SceneReport measure_scene(Renderer& renderer, const GaussianScene& scene, const Options& options,
                          const std::function<void(int, int, const std::string&)>& progress);
int work_units(const Options& options, int scene_sh_degree);  // progress() totals

std::string markdown(const std::vector<SceneReport>& reports, const DeviceInfo& device, const std::string& command);
std::string csv(const std::vector<SceneReport>& reports, const DeviceInfo& device);
std::string pareto_svg(const SceneReport& report, const DeviceInfo& device);
// The same modes' rotation_inconsistency() fraction against time (lower is better), when measured.
std::string consistency_svg(const SceneReport& report, const DeviceInfo& device);
// The depth-warped popping (ModeResult::warp_pops_per_step) along the path, a line per mode and the
// float64 reference's dashed, when the path has two frames or more.
std::string popping_svg(const SceneReport& report, const DeviceInfo& device);
// The stdout table of one scene.
std::string text_table(const SceneReport& report);

}  // namespace tilesplat::accuracy
