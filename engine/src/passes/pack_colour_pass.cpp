#include "passes/pack_colour_pass.h"

#include <stdexcept>

#include "shader_io.h"

namespace tilesplat {

namespace {
using shader_io::PackColourPush;  // compute/shader_io.h

// pack_colour.comp's FORMAT.
uint32_t shader_format(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R16G16B16A16_SFLOAT:
      return 0;
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB:  // the same bytes: the colours are sRGB-encoded already
      return 1;
    default:
      throw std::logic_error("pack_colour: unsupported format");
  }
}
}  // namespace

uint32_t PackColourPass::texel_bytes(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R16G16B16A16_SFLOAT:
      return 8;
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB:
      return 4;
    default:
      return 0;
  }
}

void PackColourPass::record(VkCommandBuffer cmd, VkFormat format, const vk::Buffer& rgba,
                            const vk::Buffer& packed, VkDeviceAddress counters, uint32_t width,
                            uint32_t height) {
  const vk::ComputePipeline& pipeline = pipelines_.get(format, [&] {
    return vk::ComputePipeline(ctx_, "pack_colour", sizeof(PackColourPush), {{0, shader_format(format)}});
  });
  pipeline.bind(cmd, PackColourPush{rgba.address(), packed.address(), counters, width, height});
  pipeline.dispatch(cmd, vk::div_ceil(width, 16), vk::div_ceil(height, 16));
}

}  // namespace tilesplat
