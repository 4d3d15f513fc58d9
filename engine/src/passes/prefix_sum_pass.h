// Exclusive prefix sum of uint32 values, any length: reduce-then-scan over blocks of 1024, recursing on
// the block totals until one block remains. The total lands at a caller-given device address.
#pragma once

#include <vector>

#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

class PrefixSumPass {
 public:
  static constexpr uint32_t kBlock = 1024;  // SCAN_BLOCK in compute/workgroup_scan.glsl

  explicit PrefixSumPass(vk::Context& ctx);
  // dst[i] = src[0] + ... + src[i-1] for i < count (dst may alias src); *total = sum of all.
  // With an order (uint indices), the values are taken as src[order[0]], src[order[1]], ... instead;
  // dst must not alias src then.
  void record(VkCommandBuffer cmd, VkDeviceAddress src, VkDeviceAddress dst, uint32_t count, VkDeviceAddress total,
              VkDeviceAddress order = 0);
  uint64_t device_bytes() const;

 private:
  vk::Context& ctx_;
  vk::ComputePipeline scan_blocks_;
  vk::ComputePipeline add_offsets_;
  std::vector<vk::Buffer> level_sums_;  // block totals of each level, grown on demand
};

}  // namespace tilesplat
