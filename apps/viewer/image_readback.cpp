#include "image_readback.h"

namespace tilesplat::viewer {

HostBuffer::HostBuffer(const WindowDevice& device, VkDeviceSize bytes) : device_(device.device()) {
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = bytes;
  info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  vk_check(vkCreateBuffer(device_, &info, nullptr, &buffer_), "vkCreateBuffer (a readback)");
  try {
    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(device_, buffer_, &requirements);
    VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    allocate.allocationSize = requirements.size;
    allocate.memoryTypeIndex = device.memory_type(
        requirements.memoryTypeBits,
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, 0, "a readback");
    vk_check(vkAllocateMemory(device_, &allocate, nullptr, &memory_), "vkAllocateMemory (a readback)");
    vk_check(vkBindBufferMemory(device_, buffer_, memory_, 0), "vkBindBufferMemory (a readback)");
    vk_check(vkMapMemory(device_, memory_, 0, bytes, 0, &mapped_), "vkMapMemory (a readback)");
  } catch (...) {
    destroy();  // a throwing constructor runs no destructor
    throw;
  }
}

HostBuffer::~HostBuffer() {
  destroy();
}

void HostBuffer::destroy() {
  if (mapped_) vkUnmapMemory(device_, memory_);
  if (buffer_) vkDestroyBuffer(device_, buffer_, nullptr);
  if (memory_) vkFreeMemory(device_, memory_, nullptr);
  mapped_ = nullptr;
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
}

}  // namespace tilesplat::viewer
