#include "passes/tile_ranges_pass.h"

namespace tilesplat {

namespace {
struct RangesPush {
  VkDeviceAddress keys, ranges, counters;
  uint32_t tiles, pad;
};
}  // namespace

TileRangesPass::TileRangesPass(vk::Context& ctx) {
  for (uint32_t wide : {0u, 1u}) pipeline_[wide] = vk::ComputePipeline(ctx, "tile_ranges", sizeof(RangesPush), {{0, wide}});
}

void TileRangesPass::record(VkCommandBuffer cmd, const vk::Buffer& sorted_keys, bool wide_keys, vk::Buffer& ranges,
                            const vk::Buffer& counters, VkDeviceSize ranges_args_offset, uint32_t tiles) {
  const vk::ComputePipeline& pipeline = pipeline_[wide_keys ? 1 : 0];
  pipeline.bind(cmd, RangesPush{sorted_keys.address(), ranges.address(), counters.address(), tiles, 0});
  pipeline.dispatch_indirect(cmd, counters.handle(), ranges_args_offset);
}

}  // namespace tilesplat
