// Composite backward (compute/composite_backward.comp): each pixel's gradient of the frame's outputs
// carried to the splats it blended, summed per projected record (SPLAT_GRADIENT_FLOATS each).
#pragma once

#include <array>
#include <cstdint>

#include "passes/tile_grid.h"
#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"
#include "vulkan/pipeline_variants.h"

namespace tilesplat {

class CompositeBackwardPass {
 public:
  explicit CompositeBackwardPass(vk::Context& ctx);

  // What the forward left and what the loss says, per pixel.
  struct Inputs {
    const vk::Buffer& splats;          // the forward's projected records
    const vk::Buffer& sorted_indices;  // its tile lists
    const vk::Buffer& ranges;
    const vk::Buffer& pixel_rgba_gradients;   // vec4 per pixel: dL/d(r, g, b, alpha)
    const vk::Buffer& pixel_depth_gradients;  // vec2 per pixel: dL/d(expected, accumulated depth)
    std::array<float, 3> background;
    TileGrid tiles;  // the whole image's (the backward covers no region)
    float max_alpha;
  };
  // Adds into `splat_gradients`, which the caller zero-fills.
  void record(VkCommandBuffer cmd, const Inputs& in, vk::Buffer& splat_gradients);
  // Whether the sums use float atomic adds (VK_EXT_shader_atomic_float), else compare-and-swap loops.
  bool float_atomics() const { return float_atomics_; }

 private:
  vk::Context& ctx_;
  bool float_atomics_;
  uint32_t pixels_per_invocation_;            // 16 on CPU drivers (a tile's column), 1 on GPUs
  vk::PipelineVariants<uint32_t> pipelines_;  // by the bits of max_alpha
};

}  // namespace tilesplat
