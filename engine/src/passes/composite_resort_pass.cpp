#include "passes/composite_resort_pass.h"

#include <bit>

#include "tilesplat/camera.h"
#include "tilesplat/reference.h"

namespace tilesplat {

namespace {
struct CompositeResortPush {
  VkDeviceAddress splats, ray_depth, sorted_indices, ranges, out_rgba, out_depth, out_count;
  uint32_t width, height;
  float background[4];
  float intrinsics[4];  // fx, fy, cx, cy
  uint32_t tiles_x, max_splats;
  VkDeviceAddress counters;
};
static_assert(offsetof(CompositeResortPush, background) == 64);
}  // namespace

// One pixel an invocation everywhere: its window lives in registers. On lavapipe 4 pixels an
// invocation (fewer reads of each staged splat, as CompositePass does with 16) measured 1.4x
// slower than 1 on playbot_lod3 at 480x270: four windows spill.
CompositeResortPass::CompositeResortPass(vk::Context& ctx) : ctx_(ctx), pixels_per_invocation_(1) {}

void CompositeResortPass::record(VkCommandBuffer cmd, const vk::Buffer& splats, const vk::Buffer& ray_depth,
                                 const vk::Buffer& sorted_indices, const vk::Buffer& ranges, OutputBuffers& out,
                                 const Camera& camera, const std::array<float, 3>& background, bool write_depth,
                                 bool write_count, const CompositePass::Cutoffs& cutoffs, uint32_t window,
                                 VkDeviceAddress counters) {
  auto key = std::make_tuple(write_depth, write_count, cutoffs, window);
  auto it = pipelines_.find(key);
  if (it == pipelines_.end())
    it = pipelines_
             .emplace(key, vk::ComputePipeline(ctx_, "composite_resort", sizeof(CompositeResortPush),
                                               {{0, write_depth ? 1u : 0u},
                                                {1, write_count ? 1u : 0u},
                                                {2, pixels_per_invocation_},
                                                {3, kTileSize / pixels_per_invocation_},
                                                {4, std::bit_cast<uint32_t>(cutoffs.alpha)},
                                                {6, std::bit_cast<uint32_t>(cutoffs.transmittance)},
                                                {7, window}}))
             .first;
  const uint32_t tiles_x = vk::div_ceil(out.width, kTileSize);
  const uint32_t tiles_y = vk::div_ceil(out.height, kTileSize);
  CompositeResortPush push{splats.address(),
                           ray_depth.address(),
                           sorted_indices.address(),
                           ranges.address(),
                           out.rgba.address(),
                           write_depth ? out.depth.address() : 0,
                           write_count ? out.count.address() : 0,
                           out.width,
                           out.height,
                           {background[0], background[1], background[2], 0.0f},
                           {float(camera.fx), float(camera.fy), float(camera.cx), float(camera.cy)},
                           tiles_x,
                           max_tile_splats(),
                           counters};
  it->second.bind(cmd, push);
  it->second.dispatch(cmd, tiles_x, tiles_y);
}

}  // namespace tilesplat
