// The backward of a frame as a plan (docs/gradients.md): what Renderer::backward records after the
// forward frame it differentiates, decided before any Vulkan call from the forward's own plan, and tested
// without a device (tests/test_frame_plan.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "frame/frame_plan.h"
#include "passes/tile_grid.h"
#include "tilesplat/render_settings.h"

namespace tilesplat {

// One step of a backward, in the order BackwardPlan::passes lists them.
enum class BackwardPass {
  kClearGradients,      // the splats' and the scene's gradient sums and the counters to zero
  kCompositeBackward,   // each pixel's gradient to the splats it blended (composite_backward.comp)
  kProjectionBackward,  // each splat's gradient to its Gaussian's parameters (projection_backward.comp)
};
// The pass's name in FrameStats::passes, or nullptr for a step that is not timed.
const char* timed_name(BackwardPass pass);

struct BackwardPlan {
  TileGrid tiles;  // the forward's: the whole image
  std::array<float, 3> background = {0, 0, 0};
  float max_alpha = 0.99f;
  Antialiasing antialiasing = Antialiasing::kClassic;
  uint32_t gaussians = 0;  // the scene's count: one projected record each (the pinhole's)
  int sh_degree = 0;
  bool float_atomics = false;  // the composite backward sums with float atomic adds (else compare-and-swap)
  std::vector<BackwardPass> passes;
};

// The backward of `forward`, a frame of the sorted compositor in the reference's modes on the whole image
// (check_differentiable has refused the others). Throws std::logic_error for a plan that is not one.
BackwardPlan plan_backward(const FramePlan& forward, const SceneShape& scene, bool float_atomics);

}  // namespace tilesplat
