// tilesplat-bench --scaling: how the frame's cost and device memory grow with the Gaussian count and
// the image size, per pass.
//
// Every scene (and, with --tile-copies, a synthetic one made of copies of the largest) is rendered
// from the orbit camera that frames it at every size. A non-negative least-squares fit over all
// those frames then splits each pass's median time into a part per Gaussian, per (Gaussian, tile)
// pair and per pixel, plus a fixed part, and the device memory into bytes per Gaussian, per pair and
// per pixel: how each pass's cost grows, and which pass dominates at which scale. The frames are
// interleaved (size after size, scene after scene, repeat after repeat) so that a CPU driver's
// drifting speed affects every point alike.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat::scaling {

struct Size {
  int width = 0;
  int height = 0;
  uint64_t pixels() const { return uint64_t(width) * uint64_t(height); }
};

struct Scene {
  std::string name;  // the file name, or "NAME x4 (tiled)"
  GaussianScene scene;
};

// `copies` copies of `scene` side by side in a square grid across the horizontal (x, z) plane, one
// bounds-extent apart: a larger scene with the same splats, for the Gaussian counts no file has.
GaussianScene tile_scene(const GaussianScene& scene, int copies);

struct Point {
  std::string scene;
  uint64_t gaussians = 0;
  Size size;
  // Medians over the repeats.
  double frame_ms = 0;
  std::vector<PassTiming> passes;  // per pass, in frame order
  uint64_t visible = 0;
  uint64_t pairs = 0;
  uint64_t device_bytes = 0;
};

struct Options {
  std::vector<Size> sizes;
  int warmup = 1;
  int repeat = 3;
  std::string sort = "radix";
  Compositor compositor = Compositor::kSorted;  // tilesplat-bench --compositor
};

struct Run {
  std::vector<Point> points;  // scene-major, then size
  DeviceInfo device;
  uint64_t validation_messages = 0;
};

// Renders every scene at every size (one renderer, the scenes' own settings off: SH as stored, no
// lights, colour + depth + splat count, as tilesplat-render writes them). progress(done, total, what).
Run measure(const RendererOptions& renderer_options, const std::vector<Scene>& scenes, const Options& options,
            const std::function<void(int, int, const std::string&)>& progress);
int work_units(const std::vector<Scene>& scenes, const Options& options);

// y ~ per_gaussian * gaussians + per_pair * pairs + per_pixel * pixels + fixed, every coefficient >= 0,
// least squares over the points. r2: the share of the variance it explains.
struct Fit {
  std::string what;  // a pass, "gpu frame" or "device memory"
  double per_gaussian = 0, per_pair = 0, per_pixel = 0, fixed = 0;
  double r2 = 0;
};
// One fit per pass (ms), one for the frame (ms) and one for device memory (bytes).
std::vector<Fit> fit(const std::vector<Point>& points);
// The pass with the largest median at a point.
std::string dominant_pass(const Point& point);

std::string text_report(const Run& run, const std::vector<Fit>& fits);
std::string markdown(const Run& run, const std::vector<Fit>& fits, const std::string& command);
std::string csv(const Run& run);
// Three charts side by side in one SVG document is not what plot:: draws; one chart per file:
// per-pass time against Gaussians (at the size nearest 1920x1080), per-pass time against pixels (the
// largest scene), device memory against Gaussians (per size).
std::string svg_time_vs_gaussians(const Run& run);
std::string svg_time_vs_pixels(const Run& run);
std::string svg_memory(const Run& run);

}  // namespace tilesplat::scaling
