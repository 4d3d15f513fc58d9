// tilesplat-bench --effects: what each scene effect costs per pass, and that an effect turned off
// costs what never having it costs.
//
// One scene, rendered at the chosen views with one effect changed at a time from a base that has
// every effect off (the scene's SH degree, classic antialiasing, no lights, colour and alpha only):
// SH degree 0..3 (a scene below SH3 padded with zero bands for the sh3 row), relighting, the
// antialiasing modes, the depth and splat-count outputs, the stochastic compositor, the camera
// models (each view through OpenCV distortion, a fisheye, an orthographic and an equirectangular
// camera of its size), and the averaged frames (a thin lens, a shutter). Two rows
// render a scene that never had the effect (its SH stored at degree 0; its normals removed) next to
// the row that turns the effect off, so the table shows "off" and "never" side by side. The frames
// of all rows are interleaved (row after row, repeat after repeat) so that a CPU driver's drifting
// speed affects every row alike.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat::effects {

// The scene a row renders: the measured scene itself, or a copy of it.
enum class SceneVariant {
  kScene,
  kStoredSh0,  // "never had it": the SH stored at degree 0
  kNoNormals,  // "never had it": the normals removed
  kPaddedSh3,  // a scene below degree 3 given zero bands up to 3, to time degree 3 on its geometry
};
std::string to_string(SceneVariant variant);  // "", "stored SH0", "no normals", "padded to SH3"
// The copy of `scene` a variant renders.
GaussianScene make_variant(const GaussianScene& scene, SceneVariant variant);

struct Row {
  std::string name;  // "sh1", "lights 2", "mip", "+depth", ...
  SceneVariant scene_variant = SceneVariant::kScene;
  RenderSettings settings;
  // Depth-test against a host's plane through the scene (plane_through_scene) and, with host_depth_out,
  // write depth out; settings.host is filled per view.
  bool host_plane = false;
  bool host_depth_out = true;
  // The row's frame of a view: its camera (another model of the view, say) and what its settings need
  // of the view (a lens focused on the scene's centre, a shutter's end camera). Empty: the view as is.
  std::function<Camera(const Camera&)> camera;
  std::function<void(RenderSettings&, const Camera&)> for_view;
  // Measured: medians over the repeats, then over the views.
  double frame_ms = 0;
  std::vector<PassTiming> passes;
  uint64_t device_bytes = 0;  // at the first view
};

struct Options {
  std::vector<Camera> views;
  int warmup = 1;
  int repeat = 5;
  std::string sort = "radix";
};

// The rows for a scene of this SH degree. `base` carries what the run shares (sort, accuracy,
// background); every row starts from it with all effects off.
std::vector<Row> plan_rows(const GaussianScene& scene, const RenderSettings& base);

struct Run {
  DeviceInfo device;
  uint64_t validation_messages = 0;  // summed over the run's renderers
};
// Renders every row (interleaved) and fills in the measurements. progress(done, total) as it goes.
Run measure(const RendererOptions& renderer_options, const GaussianScene& scene, std::vector<Row>& rows,
            const Options& options, const std::function<void(int, int, const std::string&)>& progress);
int work_units(const std::vector<Row>& rows, const Options& options);

// A host's depth image of a plane through the scene's centre, tilted 35 degrees about the camera's y
// axis: what a host that drew a wall cutting the scene leaves in its depth buffer (window depths in
// `convention`; its far value where the plane is behind the camera).
std::vector<float> plane_through_scene(const GaussianScene& scene, const Camera& camera,
                                       const DepthConvention& convention);
// The convention the bench's host plane uses: a Vulkan projection with near 0.05 and far 200.
DepthConvention bench_depth_convention();

// Two lights that reach most of the scene: a directional light from above and the camera's side,
// and a point light near the scene's centre, scaled to its extent.
Lighting bench_lighting(const GaussianScene& scene);

std::string text_table(const std::vector<Row>& rows);
std::string markdown(const std::vector<Row>& rows, const std::string& scene, const DeviceInfo& device,
                     const std::string& command);
std::string csv(const std::vector<Row>& rows, const std::string& scene, const DeviceInfo& device);

}  // namespace tilesplat::effects
