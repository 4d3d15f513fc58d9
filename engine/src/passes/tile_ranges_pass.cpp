#include "passes/tile_ranges_pass.h"

namespace tilesplat {

namespace {
struct RangesPush {
  VkDeviceAddress keys, ranges, counters;
  uint32_t tiles, pad;
};
}  // namespace

TileRangesPass::TileRangesPass(vk::Context& ctx) : pipeline_(ctx, "tile_ranges", sizeof(RangesPush)) {}

void TileRangesPass::record(VkCommandBuffer cmd, const vk::Buffer& sorted_keys, vk::Buffer& ranges,
                            const vk::Buffer& counters, VkDeviceSize ranges_args_offset, uint32_t tiles) {
  pipeline_.bind(cmd, RangesPush{sorted_keys.address(), ranges.address(), counters.address(), tiles, 0});
  pipeline_.dispatch_indirect(cmd, counters.handle(), ranges_args_offset);
}

}  // namespace tilesplat
