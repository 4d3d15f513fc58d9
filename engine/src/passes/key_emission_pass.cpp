#include "passes/key_emission_pass.h"

#include <bit>
#include <utility>
#include <vector>

#include "passes/frame_counters.h"

namespace tilesplat {

namespace {
struct SetupPush {
  VkDeviceAddress counters;
  uint32_t capacity, pad;
};
struct ScatterPush {
  VkDeviceAddress depth_order, depth_offsets, offsets;
  uint32_t count, pad;
};
// key_emission.comp and key_emission_big.comp.
struct EmitPush {
  VkDeviceAddress splats, rects, tile_counts, offsets, keys, values, depth_keys, big_splats, counters;
  uint32_t count, tiles_x, capacity, tiles;
};
}  // namespace

KeyEmissionPass::KeyEmissionPass(vk::Context& ctx)
    : ctx_(ctx),
      frame_setup_(ctx, "frame_setup", sizeof(SetupPush)),
      scatter_offsets_(ctx, "scatter_offsets", sizeof(ScatterPush)) {}

void KeyEmissionPass::record(VkCommandBuffer cmd, const ProjectedBuffers& projected, const vk::Buffer* depth_order,
                             KeyBuffers& keys, uint32_t gaussians, uint32_t tiles_x, uint32_t tiles,
                             const vk::Buffer& counters_buffer, bool square_tiles, float alpha_inv) {
  const VkDeviceAddress counters = counters_buffer.address();
  frame_setup_.bind(cmd, SetupPush{counters, keys.capacity, 0});
  frame_setup_.dispatch(cmd, 1);
  if (depth_order) {
    scatter_offsets_.bind(cmd, ScatterPush{depth_order->address(), projected.depth_offsets.address(),
                                           projected.offsets.address(), gaussians, 0});
    scatter_offsets_.dispatch(cmd, vk::div_ceil(gaussians, 256));
  }
  vk::barrier(cmd);
  const auto variant = std::make_tuple(keys.wide_keys, square_tiles, alpha_inv);
  auto it = emit_keys_.find(variant);
  if (it == emit_keys_.end()) {
    const std::vector<vk::SpecConstant> spec = {
        {0, keys.wide_keys}, {1, square_tiles}, {2, std::bit_cast<uint32_t>(alpha_inv)}};
    it = emit_keys_
             .emplace(variant, std::make_pair(vk::ComputePipeline(ctx_, "key_emission", sizeof(EmitPush), spec),
                                              vk::ComputePipeline(ctx_, "key_emission_big", sizeof(EmitPush), spec)))
             .first;
  }
  const auto& [emit_keys, emit_big_splat_keys] = it->second;
  const EmitPush push{projected.splats.address(), projected.rects.address(), projected.tile_counts.address(),
                      projected.offsets.address(), keys.keys.address(), keys.values.address(),
                      projected.depth_order.keys.address(), projected.big_splats.address(), counters,
                      gaussians, tiles_x, keys.capacity, tiles};
  emit_keys.bind(cmd, push);
  emit_keys.dispatch(cmd, vk::div_ceil(gaussians, 256));
  vk::barrier(cmd);
  emit_big_splat_keys.bind(cmd, push);
  emit_big_splat_keys.dispatch_indirect(cmd, counters_buffer.handle(), kBigSplatsOffset);
}

}  // namespace tilesplat
