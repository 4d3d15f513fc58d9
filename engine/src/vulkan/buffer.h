// Device buffers addressed from shaders by 64-bit device address (no descriptor sets, no binding-range
// limit: a buffer may be larger than maxStorageBufferRange, which lavapipe caps at 128 MiB).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "vulkan/context.h"

namespace tilesplat::vk {

enum class MemoryUse {
  Device,    // GPU-only data; host-visible on unified-memory devices (lavapipe) and then mapped
  Upload,    // host writes, GPU reads (staging)
  Readback,  // GPU writes, host reads
};

class Buffer {
 public:
  Buffer() = default;
  // Every buffer can be a storage, texel, indirect and transfer buffer with a device address;
  // `extra_usage` adds others (a host's vertex buffer).
  Buffer(Context& ctx, VkDeviceSize size, MemoryUse use, std::string name,
         VkBufferUsageFlags extra_usage = 0);
  ~Buffer() { reset(); }
  Buffer(Buffer&& other) noexcept { *this = std::move(other); }
  Buffer& operator=(Buffer&& other) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  void reset();
  explicit operator bool() const { return buffer_ != VK_NULL_HANDLE; }

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  VkDeviceAddress address() const { return address_; }
  const std::string& name() const { return name_; }
  // Non-null when the memory is host visible (always for Upload/Readback).
  void* mapped() const { return mapped_; }
  template <typename T>
  T* mapped_as() const { return static_cast<T*>(mapped_); }
  // The whole buffer as texel buffer of `format` (texel_bytes per texel), made on first use and kept
  // as long as the buffer; VK_NULL_HANDLE where it has more texels than the device allows.
  VkBufferView texel_view(VkFormat format, uint32_t texel_bytes) const;

 private:
  Context* ctx_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  VkDeviceAddress address_ = 0;
  void* mapped_ = nullptr;
  std::string name_;
  mutable std::vector<std::pair<VkFormat, VkBufferView>> texel_views_;
};

// Copies host data into a Device buffer: directly when it is mapped, else through a staging buffer.
void upload(Context& ctx, Buffer& dst, const void* data, VkDeviceSize size, VkDeviceSize dst_offset = 0);

}  // namespace tilesplat::vk
