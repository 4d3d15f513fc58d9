#include "host_images.h"

#include <stdexcept>
#include <string>

#include "passes/pack_colour_pass.h"
#include "vulkan/barriers.h"

namespace tilesplat {

namespace {

constexpr VkAccessFlags kAnyAccess = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;

VkBufferImageCopy whole_image(VkImageAspectFlags aspect, uint32_t width, uint32_t height) {
  VkBufferImageCopy region{};
  region.imageSubresource = {aspect, 0, 0, 1};
  region.imageExtent = {width, height, 1};
  return region;
}

}  // namespace

void check_colour_target(const ExternalImage& target, const Camera& camera) {
  if (target.image == VK_NULL_HANDLE) throw std::invalid_argument("render_to_image: no image");
  if (target.width != uint32_t(camera.width) || target.height != uint32_t(camera.height))
    throw std::invalid_argument("render_to_image: image is " + std::to_string(target.width) + "x" +
                                std::to_string(target.height) + " but the camera renders " +
                                std::to_string(camera.width) + "x" + std::to_string(camera.height));
  if (target.format != VK_FORMAT_R32G32B32A32_SFLOAT && PackColourPass::texel_bytes(target.format) == 0)
    throw std::invalid_argument(
        "render_to_image: the colour image must be VK_FORMAT_R32G32B32A32_SFLOAT, R16G16B16A16_SFLOAT, "
        "R8G8B8A8_UNORM or R8G8B8A8_SRGB");
}

void check_depth_image(const ExternalDepthImage& depth, const ExternalImage& target,
                       const RenderSettings& settings) {
  auto fail = [](const std::string& why) {
    throw std::invalid_argument("render_to_image: depth image: " + why);
  };
  if (depth.image == VK_NULL_HANDLE) fail("no image");
  if (depth.width != target.width || depth.height != target.height)
    fail(std::to_string(depth.width) + "x" + std::to_string(depth.height) + " but the colour image is " +
         std::to_string(target.width) + "x" + std::to_string(target.height));
  if (depth.format != VK_FORMAT_D32_SFLOAT && depth.format != VK_FORMAT_R32_SFLOAT)
    fail("only VK_FORMAT_D32_SFLOAT and VK_FORMAT_R32_SFLOAT are supported");
  if (depth.layout == VK_IMAGE_LAYOUT_UNDEFINED)
    fail("its layout is UNDEFINED, so it holds no depth to test against");
  if (!settings.host) fail("RenderSettings::host must say the image's depth convention");
  if (!settings.host->depth.empty())
    fail("RenderSettings::host already has depth values; the image replaces them");
}

void check_images(const ExternalImage& target, const ExternalDepthImage* depth, const Camera& camera,
                  const RenderSettings& settings) {
  check_colour_target(target, camera);
  if (!settings.region.whole())
    throw std::invalid_argument("render_to_image: RenderSettings::region " + to_string(settings.region) +
                                ": the frame fills the host's image, of the camera's size; render a region "
                                "with Renderer::render");
  if (depth)
    check_depth_image(*depth, target, settings);
  else if (settings.host && settings.host->write_depth)
    throw std::invalid_argument(
        "render_to_image: HostDepth::write_depth needs the host's depth image to write into: pass an "
        "ExternalDepthImage");
}

VkImageAspectFlags depth_aspect(const ExternalDepthImage& depth) {
  return depth.format == VK_FORMAT_D32_SFLOAT ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
}

void copy_buffer_to_image(VkCommandBuffer cmd, const vk::Buffer& buffer, VkImage image,
                          VkImageAspectFlags aspect, VkImageLayout layout, uint32_t width, uint32_t height) {
  vk::transition(cmd, {image, aspect, layout, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                       VK_ACCESS_MEMORY_WRITE_BIT, VK_ACCESS_TRANSFER_WRITE_BIT});
  const VkBufferImageCopy region = whole_image(aspect, width, height);
  vkCmdCopyBufferToImage(cmd, buffer.handle(), image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  const VkImageLayout final_layout = layout == VK_IMAGE_LAYOUT_UNDEFINED ? VK_IMAGE_LAYOUT_GENERAL : layout;
  vk::transition(cmd, {image, aspect, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, final_layout,
                       VK_ACCESS_TRANSFER_WRITE_BIT, kAnyAccess});
}

void copy_image_to_buffer(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout layout,
                          const vk::Buffer& buffer, uint32_t width, uint32_t height) {
  vk::transition(cmd, {image, aspect, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                       VK_ACCESS_MEMORY_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT});
  const VkBufferImageCopy region = whole_image(aspect, width, height);
  vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer.handle(), 1, &region);
  vk::transition(cmd, {image, aspect, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout,
                       VK_ACCESS_TRANSFER_READ_BIT, kAnyAccess});
}

}  // namespace tilesplat
