#include "passes/composite_backward_pass.h"

#include <bit>

#include "passes/tile_composite_layout.h"
#include "shader_io.h"

namespace tilesplat {

using shader_io::CompositeBackwardPush;

CompositeBackwardPass::CompositeBackwardPass(vk::Context& ctx)
    : ctx_(ctx),
      float_atomics_(ctx.features().buffer_float32_atomic_add),
      // A column of 16 on CPU drivers as composite.comp's; 1 pixel an invocation on GPUs.
      pixels_per_invocation_(composite_pixels_per_invocation(ctx) > 1 ? 16 : 1) {}

void CompositeBackwardPass::record(VkCommandBuffer cmd, const Inputs& in, vk::Buffer& splat_gradients) {
  const uint32_t max_alpha_bits = std::bit_cast<uint32_t>(in.max_alpha);
  const vk::ComputePipeline& pipeline = pipelines_.get(max_alpha_bits, [&] {
    return vk::ComputePipeline(
        ctx_, float_atomics_ ? "composite_backward" : "composite_backward_cas", sizeof(CompositeBackwardPush),
        {{2, max_alpha_bits}, {3, 16 / pixels_per_invocation_}, {4, pixels_per_invocation_}});
  });
  CompositeBackwardPush push{};
  push.splats = in.splats.address();
  push.sorted_indices = in.sorted_indices.address();
  push.ranges = in.ranges.address();
  push.pixel_rgba_gradients = in.pixel_rgba_gradients.address();
  push.pixel_depth_gradients = in.pixel_depth_gradients.address();
  push.splat_gradients = splat_gradients.address();
  push.background = {in.background[0], in.background[1], in.background[2], 0.0f};
  push.width = in.tiles.width;
  push.height = in.tiles.height;
  push.tiles_x = in.tiles.tiles_x;
  pipeline.bind(cmd, push);
  pipeline.dispatch(cmd, in.tiles.tiles_x, in.tiles.tiles_y);
}

}  // namespace tilesplat
