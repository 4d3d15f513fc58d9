#include "passes/composite_resort_pass.h"

#include <bit>

#include "passes/tile_composite_layout.h"
#include "shader_io.h"
#include "tilesplat/camera.h"
#include "tilesplat/reference.h"

namespace tilesplat {

namespace {
using shader_io::CompositeResortPush;  // composite_resort.comp's push constants
static_assert(sizeof(CompositeResortPush) <= 128, "Vulkan guarantees 128 bytes of push constants");
}  // namespace

// The layouts of CompositePass: one pixel an invocation on GPUs, a 16-pixel column on CPU drivers,
// where each staged splat is then read once per column and offered only to the rows it reaches
// (TILESPLAT_COMPOSITE_PIXELS other than 1 picks the column, 1 the GPU layout).
CompositeResortPass::CompositeResortPass(vk::Context& ctx)
    : ctx_(ctx), pixels_per_invocation_(composite_pixels_per_invocation(ctx) == 1 ? 1 : kTileSize) {}

uint32_t CompositeResortPass::max_tile_splats() const {
  if (!ctx_.is_cpu_device()) return 0xffffffffu;
  // llvmpipe ends an invocation after 65535 loop iterations in all (composite_pass.cpp). A column
  // spends at most ~560 per batch of 256 splats (staging 16, listing 32, two bands of 256), one
  // pixel an invocation ~260 per batch.
  return pixels_per_invocation_ == 1 ? 32768u : 16384u;
}

void CompositeResortPass::record(VkCommandBuffer cmd, const CompositeInputs& in, const vk::Buffer& ray_depth,
                                 const Camera& camera, uint32_t window, VkDeviceAddress counters) {
  OutputBuffers& out = in.out;
  const Variant variant{in.write_depth, in.write_count, in.cutoffs, window};
  const vk::ComputePipeline& pipeline = pipelines_.get(variant, [&] {
    std::vector<vk::SpecConstant> spec = composite_spec_constants(
        variant.write_depth, variant.write_count, pixels_per_invocation_, variant.cutoffs.alpha);
    spec.insert(spec.end(), {{6, std::bit_cast<uint32_t>(variant.cutoffs.transmittance)},
                             {7, variant.window},
                             {8, std::bit_cast<uint32_t>(variant.cutoffs.max_alpha)}});
    return vk::ComputePipeline(ctx_, "composite_resort", sizeof(CompositeResortPush), spec);
  });
  const uint32_t tiles_x = vk::div_ceil(out.width, kTileSize);
  const uint32_t tiles_y = vk::div_ceil(out.height, kTileSize);
  CompositeResortPush push{in.splats.address(),
                           ray_depth.address(),
                           in.tile_lists.address(),
                           in.ranges.address(),
                           out.rgba.address(),
                           in.write_depth ? out.depth.address() : 0,
                           in.write_count ? out.count.address() : 0,
                           out.width,
                           out.height,
                           {in.background[0], in.background[1], in.background[2], 0.0f},
                           {float(camera.fx), float(camera.fy), float(camera.cx), float(camera.cy)},
                           tiles_x,
                           max_tile_splats(),
                           counters,
                           out.first_tile};
  pipeline.bind(cmd, push);
  pipeline.dispatch(cmd, tiles_x, tiles_y);
}

}  // namespace tilesplat
