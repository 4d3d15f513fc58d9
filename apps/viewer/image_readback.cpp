#include "viewer/image_readback.h"

#include <cstring>
#include <glm/gtc/packing.hpp>
#include <stdexcept>
#include <utility>

namespace tilesplat::viewer {

std::vector<float> read_rgba(const WindowDevice& device, VkImage image, VkFormat format, VkImageLayout layout,
                             uint32_t width, uint32_t height) {
  if (format != VK_FORMAT_R32G32B32A32_SFLOAT && format != VK_FORMAT_R16G16B16A16_SFLOAT)
    throw std::logic_error("read_rgba: unsupported format");
  const bool half = format == VK_FORMAT_R16G16B16A16_SFLOAT;
  const size_t values = size_t(width) * height * 4;
  const VkDeviceSize bytes = values * (half ? 2 : 4);
  VkDevice vk = device.device();

  // A host-visible buffer for this one copy, released on return.
  struct Staging {
    VkDevice vk;
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    ~Staging() {
      if (buffer) vkDestroyBuffer(vk, buffer, nullptr);
      if (memory) vkFreeMemory(vk, memory, nullptr);
    }
  } r{vk};
  VkBufferCreateInfo buffer{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  buffer.size = bytes;
  buffer.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  vk_check(vkCreateBuffer(vk, &buffer, nullptr, &r.buffer), "vkCreateBuffer (screenshot)");
  VkMemoryRequirements requirements;
  vkGetBufferMemoryRequirements(vk, r.buffer, &requirements);
  VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  allocate.allocationSize = requirements.size;
  allocate.memoryTypeIndex = device.memory_type(
      requirements.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
      0, "a screenshot");
  vk_check(vkAllocateMemory(vk, &allocate, nullptr, &r.memory), "vkAllocateMemory (screenshot)");
  vk_check(vkBindBufferMemory(vk, r.buffer, r.memory, 0), "vkBindBufferMemory");
  device.submit_and_wait([&](VkCommandBuffer cmd) {
    VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    barrier.oldLayout = layout;
    barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    barrier.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image;
    barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                         nullptr, 0, nullptr, 1, &barrier);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {width, height, 1};
    vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, r.buffer, 1, &region);
    std::swap(barrier.oldLayout, barrier.newLayout);
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    barrier.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0,
                         nullptr, 0, nullptr, 1, &barrier);
    VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0,
                         nullptr, 0, nullptr);
  });

  void* mapped = nullptr;
  vk_check(vkMapMemory(vk, r.memory, 0, bytes, 0, &mapped), "vkMapMemory");
  std::vector<float> rgba(values);
  if (half) {
    const auto* halves = static_cast<const uint16_t*>(mapped);
    for (size_t i = 0; i < values; ++i) rgba[i] = glm::unpackHalf1x16(halves[i]);
  } else {
    std::memcpy(rgba.data(), mapped, bytes);
  }
  vkUnmapMemory(vk, r.memory);
  return rgba;
}

}  // namespace tilesplat::viewer
