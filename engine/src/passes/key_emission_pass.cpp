#include "passes/key_emission_pass.h"

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
struct EmitPush {
  VkDeviceAddress splats, rects, tile_counts, offsets, keys, values;
  uint32_t count, tiles_x, capacity, tiles, pad[2];
};
}  // namespace

KeyEmissionPass::KeyEmissionPass(vk::Context& ctx)
    : frame_setup_(ctx, "frame_setup", sizeof(SetupPush)),
      scatter_offsets_(ctx, "scatter_offsets", sizeof(ScatterPush)) {
  for (uint32_t wide : {0u, 1u}) emit_keys_[wide] = vk::ComputePipeline(ctx, "key_emission", sizeof(EmitPush), {{0, wide}});
}

void KeyEmissionPass::record(VkCommandBuffer cmd, const ProjectedBuffers& projected, const vk::Buffer* depth_order,
                             KeyBuffers& keys, uint32_t gaussians, uint32_t tiles_x, uint32_t tiles,
                             VkDeviceAddress counters) {
  frame_setup_.bind(cmd, SetupPush{counters, keys.capacity, 0});
  frame_setup_.dispatch(cmd, 1);
  if (depth_order) {
    scatter_offsets_.bind(cmd, ScatterPush{depth_order->address(), projected.depth_offsets.address(),
                                           projected.offsets.address(), gaussians, 0});
    scatter_offsets_.dispatch(cmd, vk::div_ceil(gaussians, 256));
  }
  vk::barrier(cmd);
  const vk::ComputePipeline& emit_keys = emit_keys_[keys.wide_keys ? 1 : 0];
  emit_keys.bind(cmd, EmitPush{projected.splats.address(), projected.rects.address(),
                                projected.tile_counts.address(), projected.offsets.address(), keys.keys.address(),
                                keys.values.address(), gaussians, tiles_x, keys.capacity, tiles, {0, 0}});
  emit_keys.dispatch(cmd, vk::div_ceil(gaussians, 256));
}

}  // namespace tilesplat
