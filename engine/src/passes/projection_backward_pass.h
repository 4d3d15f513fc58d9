// Projection backward (compute/projection_backward.comp): each drawn Gaussian's screen-space gradient
// (CompositeBackwardPass's sums) carried back through its projection to its parameters.
#pragma once

#include <cstdint>

#include "passes/projection_pass.h"
#include "tilesplat/camera.h"
#include "tilesplat/render_settings.h"
#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"
#include "vulkan/pipeline_variants.h"

namespace tilesplat {

class ProjectionBackwardPass {
 public:
  explicit ProjectionBackwardPass(vk::Context& ctx);
  // The frame's camera as the forward projected it (its CameraParams); outside any command buffer.
  void set_camera(const Camera& camera, double near_plane, const TileGrid& tiles);
  // Writes the scene's gradients into `gradients` (laid out as projection_backward.comp says: positions,
  // log scales, rotations, logits, SH, means2d, |means2d|), which the caller zero-fills, and counts the
  // Gaussians whose gradient was not finite at BACKWARD_COUNTER_UNFORMED of `counters`.
  void record(VkCommandBuffer cmd, const SceneBuffers& scene, const ProjectedBuffers& projected,
              const vk::Buffer& splat_gradients, Antialiasing antialiasing, vk::Buffer& gradients,
              vk::Buffer& counters);

 private:
  struct Variant {
    int sh_degree;
    Antialiasing antialiasing;
    auto operator<=>(const Variant&) const = default;
  };
  vk::Context& ctx_;
  vk::Buffer camera_params_;
  vk::PipelineVariants<Variant> pipelines_;
};

}  // namespace tilesplat
