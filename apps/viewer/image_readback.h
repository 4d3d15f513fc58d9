// Device data back in host memory: a buffer that a copy writes and the host reads, for a screenshot of
// what the window shows.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "window_device.h"

namespace tilesplat::viewer {

// A host-visible, coherent buffer that transfers write into, mapped for its lifetime.
class HostBuffer {
 public:
  HostBuffer(const WindowDevice& device, VkDeviceSize bytes);
  ~HostBuffer();
  HostBuffer(const HostBuffer&) = delete;
  HostBuffer& operator=(const HostBuffer&) = delete;

  VkBuffer buffer() const { return buffer_; }
  const void* map() const { return mapped_; }

 private:
  void destroy();

  VkDevice device_;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  void* mapped_ = nullptr;
};

}  // namespace tilesplat::viewer
