#include "passes/composite_resort_pass.h"

#include <bit>

#include "shader_io.h"
#include "tilesplat/camera.h"
#include "tilesplat/reference.h"

namespace tilesplat {

namespace {
using shader_io::CompositeResortPush;  // composite_resort.comp's push constants
static_assert(sizeof(CompositeResortPush) <= 128, "Vulkan guarantees 128 bytes of push constants");
}  // namespace

// One pixel an invocation everywhere: its window lives in registers. On lavapipe 4 pixels an
// invocation (fewer reads of each staged splat, as CompositePass does with 16) measured 1.4x
// slower than 1 on playbot_lod3 at 480x270: four windows spill.
CompositeResortPass::CompositeResortPass(vk::Context& ctx) : ctx_(ctx), pixels_per_invocation_(1) {}

void CompositeResortPass::record(VkCommandBuffer cmd, const CompositeInputs& in, const vk::Buffer& ray_depth,
                                 const Camera& camera, uint32_t window, VkDeviceAddress counters) {
  OutputBuffers& out = in.out;
  const Variant variant{in.write_depth, in.write_count, in.cutoffs, window};
  auto it = pipelines_.find(variant);
  if (it == pipelines_.end())
    it = pipelines_
             .emplace(variant,
                      vk::ComputePipeline(ctx_, "composite_resort", sizeof(CompositeResortPush),
                                          {{0, variant.write_depth ? 1u : 0u},
                                           {1, variant.write_count ? 1u : 0u},
                                           {2, pixels_per_invocation_},
                                           {3, kTileSize / pixels_per_invocation_},
                                           {4, std::bit_cast<uint32_t>(variant.cutoffs.alpha)},
                                           {6, std::bit_cast<uint32_t>(variant.cutoffs.transmittance)},
                                           {7, variant.window},
                                           {8, std::bit_cast<uint32_t>(variant.cutoffs.max_alpha)}}))
             .first;
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
  it->second.bind(cmd, push);
  it->second.dispatch(cmd, tiles_x, tiles_y);
}

}  // namespace tilesplat
