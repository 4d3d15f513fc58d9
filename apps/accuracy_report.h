// tilesplat-bench --accuracy: what each approximation costs in error and buys in time.
//
// For each scene, each accuracy mode combination is rendered at the chosen views (timed over
// repeats) and compared with the float64 CPU reference of the same view: PSNR, SSIM and max abs
// error. Along a short camera path (a sideways dolly from the first view) the frame-to-frame change
// that the reference does not have is measured: popping. The results go to a table on stdout and,
// as asked, Markdown, CSV and one Pareto plot (error against time) per scene.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
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

struct PassTime {
  std::string name;
  double ms = 0;  // median over the repeats, then over the views
};

struct ModeResult {
  AccuracyModes modes;
  std::string name;  // to_string(modes)
  double frame_ms = 0;  // median GPU frame time: median over repeats per view, median over views
  std::vector<PassTime> passes;
  uint64_t intersections = 0;  // at the first view
  double psnr_db = 0;          // against the float64 reference, mean over the views
  double ssim = 0;             // mean over the views
  double max_abs = 0;          // largest over the views
  // Along the camera path, per consecutive pair of frames (means over the pairs):
  double frame_change = 0;     // mean |frame t+1 - frame t|
  double flicker = 0;          // fraction of pixels whose change exceeds kFlickerThreshold: pops
  double excess = 0;           // temporal_excess().mean_abs: change the float64 reference does not have
  // Per consecutive triple of frames (means over the triples), popping(): the second difference,
  // which smooth motion cancels and order flips do not.
  double pops = 0;             // fraction of pixels whose second difference exceeds kFlickerThreshold
  double pop_mean = 0;         // mean second difference over pixels and RGB
};

// A pixel "pops" between two frames of the slow dolly when a channel changes by more than this.
constexpr double kFlickerThreshold = 0.05;

struct SceneReport {
  std::string scene;  // file name
  std::string description;  // "31,000 Gaussians (SH2)"
  std::string views;        // "views 0, 3 of cameras.json at 480x270"
  int path_frames = 0;
  double reference_change = 0;   // the float64 reference's own mean frame-to-frame change on the path
  double reference_flicker = 0;  // and its fraction of popping pixels
  double reference_pops = 0;     // its popping() fraction (it blends in centre-depth order: it pops too)
  std::vector<ModeResult> modes;
};

struct Options {
  std::vector<AccuracyModes> modes;  // empty: default_modes()
  std::vector<Camera> views;         // the measured views (the first one starts the path)
  std::vector<std::string> view_names;
  int warmup = 1;
  int repeat = 3;
  int path_frames = 6;              // frames of the dolly path (0: no temporal measurement)
  double path_step = 0.0005;        // dolly step, as a fraction of the camera's distance to the scene centre
  std::string sort = "radix";
};

// The dolly path: `frames` cameras moving sideways (along the camera's x axis) from `start` in
// steps of step_fraction times the distance from the camera to `centre`.
std::vector<Camera> dolly_path(const Camera& start, const std::array<double, 3>& centre, int frames,
                               double step_fraction);

// Measures one scene. progress(done, total, what) is called as it goes.
SceneReport measure_scene(Renderer& renderer, const GaussianScene& scene, const Options& options,
                          const std::function<void(int, int, const std::string&)>& progress);
int work_units(const Options& options, int scene_sh_degree);  // progress() totals

std::string markdown(const std::vector<SceneReport>& reports, const DeviceInfo& device, const std::string& command);
std::string csv(const std::vector<SceneReport>& reports, const DeviceInfo& device);
std::string pareto_svg(const SceneReport& report, const DeviceInfo& device);
// The stdout table of one scene.
std::string text_table(const SceneReport& report);

}  // namespace tilesplat::accuracy
