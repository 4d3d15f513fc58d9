// Pack colour: the frame's float RGBA into the texels of a host image of another format
// (R16G16B16A16_SFLOAT, R8G8B8A8_UNORM, R8G8B8A8_SRGB), for render_to_image to copy (pack_colour.comp).
#pragma once

#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"
#include "vulkan/pipeline_variants.h"

namespace tilesplat {

class PackColourPass {
 public:
  explicit PackColourPass(vk::Context& ctx) : ctx_(ctx) {}
  // Bytes a texel of `format` takes; 0 for a format the pass does not pack.
  static uint32_t texel_bytes(VkFormat format);
  // Records the packing of `rgba` (vec4 per pixel) into `packed` (texel_bytes(format) per pixel). The values
  // saturated to half's range are added to COUNTER_SATURATED of `counters`.
  void record(VkCommandBuffer cmd, VkFormat format, const vk::Buffer& rgba, const vk::Buffer& packed,
              VkDeviceAddress counters, uint32_t width, uint32_t height);

 private:
  vk::Context& ctx_;
  vk::PipelineVariants<VkFormat> pipelines_;  // one per format (a specialization constant)
};

}  // namespace tilesplat
