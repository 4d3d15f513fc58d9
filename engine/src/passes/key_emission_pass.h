// Frame setup + key emission: caps the key count at the buffers' capacity, sizes the indirect
// dispatches, then writes one (tile << 32 | depth bits, Gaussian index) pair per touched tile.
#pragma once

#include "passes/projection_pass.h"
#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

// The key/value pairs the sort orders, double-buffered for the sort's ping-pong.
struct KeyBuffers {
  vk::Buffer keys, values, keys_alt, values_alt;
  uint32_t capacity = 0;
};

class KeyEmissionPass {
 public:
  explicit KeyEmissionPass(vk::Context& ctx);
  void record(VkCommandBuffer cmd, const ProjectedBuffers& projected, KeyBuffers& keys, uint32_t gaussians,
              uint32_t tiles_x, uint32_t tiles, VkDeviceAddress counters);

 private:
  vk::ComputePipeline frame_setup_;
  vk::ComputePipeline emit_keys_;
};

}  // namespace tilesplat
