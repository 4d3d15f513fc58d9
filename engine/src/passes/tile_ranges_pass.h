// Tile ranges: [start, end) of each tile's run in the sorted keys.
#pragma once

#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

class TileRangesPass {
 public:
  explicit TileRangesPass(vk::Context& ctx);
  // ranges must hold one uvec2 per tile, zero-filled. The tile id is the key, or its high 32 bits
  // with 64-bit keys (tile << 32 | depth bits).
  void record(VkCommandBuffer cmd, const vk::Buffer& sorted_keys, bool wide_keys, vk::Buffer& ranges,
              const vk::Buffer& counters, VkDeviceSize ranges_args_offset, uint32_t tiles);

 private:
  bool texel_buffers_;                     // CPU drivers: tile_ranges_texel (vk::texel_buffers_wanted)
  vk::ComputePipeline pipeline_[2];        // [wide keys]
  vk::ComputePipeline texel_pipeline_[2];  // [wide keys]
};

}  // namespace tilesplat
