#include "backward/backward_plan.h"

#include <stdexcept>

namespace tilesplat {

const char* timed_name(BackwardPass pass) {
  switch (pass) {
    case BackwardPass::kClearGradients:
      return nullptr;
    case BackwardPass::kCompositeBackward:
      return "composite_backward";
    case BackwardPass::kProjectionBackward:
      return "projection_backward";
  }
  return nullptr;
}

BackwardPlan plan_backward(const FramePlan& forward, const SceneShape& scene, bool float_atomics) {
  // What check_differentiable refuses from the settings, held here against the plan itself: a backward
  // recorded over another frame would read lists it does not understand.
  if (forward.compositor != Compositor::kSorted || forward.resort_window != 0 ||
      forward.projection.seam_copies() != 1 || forward.part != ScenePart{} || forward.host.enabled ||
      forward.sample_sums || forward.tiles.first_x != 0 || forward.tiles.first_y != 0)
    throw std::logic_error("plan_backward: the forward frame is not one the backward covers");
  BackwardPlan plan;
  plan.tiles = forward.tiles;
  plan.background = forward.outputs.background;
  plan.max_alpha = forward.outputs.max_alpha;
  plan.antialiasing = forward.lists.antialiasing;
  plan.gaussians = scene.count;
  plan.sh_degree = scene.sh_degree;
  plan.float_atomics = float_atomics;
  plan.passes = {BackwardPass::kClearGradients, BackwardPass::kCompositeBackward,
                 BackwardPass::kProjectionBackward};
  return plan;
}

}  // namespace tilesplat
