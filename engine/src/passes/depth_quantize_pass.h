// Depth quantization: turns the projection's depth float bits into 16-bit keys over the frame's
// visible depth range (AccuracyModes::depth_key_bits = 16). Runs only in that mode.
#pragma once

#include "passes/projection_pass.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

class DepthQuantizePass {
 public:
  explicit DepthQuantizePass(vk::Context& ctx);
  void record(VkCommandBuffer cmd, ProjectedBuffers& projected, uint32_t gaussians, VkDeviceAddress counters);

 private:
  vk::ComputePipeline pipeline_;
};

}  // namespace tilesplat
