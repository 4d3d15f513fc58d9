// The backward passes of a frame and the buffers they write (docs/gradients.md): what Renderer::backward
// records after the forward frame it differentiates, which left its projected records, tile lists and
// ranges in FrameResources.
#pragma once

#include <vector>

#include "backward/backward_plan.h"
#include "frame/frame_resources.h"
#include "passes/composite_backward_pass.h"
#include "passes/projection_backward_pass.h"
#include "tilesplat/gradients.h"
#include "tilesplat/renderer.h"
#include "vulkan/buffer.h"
#include "vulkan/context.h"
#include "vulkan/gpu_timer.h"

namespace tilesplat {

class FrameBackward {
 public:
  FrameBackward(vk::Context& ctx, vk::GpuTimer& timer);

  // Uploads the loss's gradients (check_frame_gradients has checked them), records the plan's passes over
  // what the forward of `camera` left in `resources`, runs them and reads the scene's gradients back.
  // `passes` receives the passes' GPU times.
  SceneGradients run(const BackwardPlan& plan, const Camera& camera, double near_plane,
                     const FrameResources& resources, const FrameGradients& gradients,
                     std::vector<PassTiming>& passes);
  uint64_t device_bytes() const;

 private:
  void upload_pixel_gradients(const FrameGradients& gradients, size_t pixels);
  // The buffer, made anew when it holds fewer than `bytes`.
  void reserve(vk::Buffer& buffer, uint64_t bytes, const char* name);

  vk::Context& ctx_;
  vk::GpuTimer& timer_;
  CompositeBackwardPass composite_;
  ProjectionBackwardPass projection_;
  vk::Buffer pixel_rgba_;       // dL/d(r, g, b, alpha) per pixel
  vk::Buffer pixel_depth_;      // dL/d(expected depth, accumulated depth) per pixel
  vk::Buffer splat_gradients_;  // SPLAT_GRADIENT_FLOATS per record
  vk::Buffer scene_gradients_;  // projection_backward.comp's outputs
  vk::Buffer counters_;         // BACKWARD_COUNTER_UNFORMED
};

}  // namespace tilesplat
