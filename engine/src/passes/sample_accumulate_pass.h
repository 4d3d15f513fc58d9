// Sample accumulate: a lens or shutter sample frame added to the sums of the samples before it, its
// outputs replaced by the mean of all (RenderSettings::accumulate_samples; sample_accumulate.comp).
#pragma once

#include <optional>

#include "passes/composite_pass.h"
#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

class SampleAccumulatePass {
 public:
  explicit SampleAccumulatePass(vk::Context& ctx) : ctx_(ctx) {}
  // Bytes of the sums for an image of `pixels`: two halves of 32 bytes a pixel.
  static VkDeviceSize sums_bytes(size_t pixels) { return VkDeviceSize(pixels) * 64; }
  struct Frame {
    uint32_t samples_before = 0;  // samples already in `sums`
    bool write_depth = false, write_count = false;
    bool opaque = false;  // blended over a background (LinearFrameMean's over_background)
  };
  // Linear colours past float's range are saturated and counted into COUNTER_SATURATED_MEAN of `counters`.
  void record(VkCommandBuffer cmd, const OutputBuffers& out, const vk::Buffer& sums, const vk::Buffer& counters,
              const Frame& frame);

 private:
  vk::Context& ctx_;
  std::optional<vk::ComputePipeline> pipeline_;  // made on first use (most renderers never accumulate)
};

}  // namespace tilesplat
