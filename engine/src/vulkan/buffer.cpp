#include "vulkan/buffer.h"

#include <algorithm>
#include <utility>

#include "vulkan/vk_check.h"

namespace tilesplat::vk {

Buffer::Buffer(Context& ctx, VkDeviceSize size, MemoryUse use, std::string name,
               VkBufferUsageFlags extra_usage)
    : ctx_(&ctx), size_(size), name_(std::move(name)) {
  if (size == 0) size = 16;  // zero-sized buffers are invalid; keep a valid address for empty scenes
  if (size > ctx.limits().max_allocation_size)
    throw std::runtime_error("buffer '" + name_ + "' needs " + std::to_string(size) +
                             " bytes, more than the device's largest allocation (" +
                             std::to_string(ctx.limits().max_allocation_size) + " bytes)");
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
               VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
               VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT |
               VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT | extra_usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  TS_VK_CHECK(vkCreateBuffer(ctx.device(), &info, nullptr, &buffer_));

  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(ctx.device(), buffer_, &req);
  uint32_t type = 0;
  switch (use) {
    case MemoryUse::Device:
      type = ctx.find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
      break;
    case MemoryUse::Upload:
      type = ctx.find_memory_type(req.memoryTypeBits,
                                  VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
      break;
    case MemoryUse::Readback:
      type = ctx.find_memory_type(req.memoryTypeBits,
                                  VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                  VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
      break;
  }
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.pNext = &flags;
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = type;
  VkResult result = vkAllocateMemory(ctx.device(), &alloc, nullptr, &memory_);
  if (result != VK_SUCCESS) {
    reset();
    throw std::runtime_error("cannot allocate " + std::to_string(req.size) + " bytes for buffer '" + name_ +
                             "': " + result_name(result));
  }
  TS_VK_CHECK(vkBindBufferMemory(ctx.device(), buffer_, memory_, 0));
  VkBufferDeviceAddressInfo address{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  address.buffer = buffer_;
  address_ = vkGetBufferDeviceAddress(ctx.device(), &address);
  const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  if ((ctx.memory_type_flags(type) & host) == host)
    TS_VK_CHECK(vkMapMemory(ctx.device(), memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
}

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    reset();
    ctx_ = std::exchange(other.ctx_, nullptr);
    buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    size_ = std::exchange(other.size_, 0);
    address_ = std::exchange(other.address_, 0);
    mapped_ = std::exchange(other.mapped_, nullptr);
    name_ = std::move(other.name_);
    texel_views_ = std::exchange(other.texel_views_, {});
  }
  return *this;
}

VkBufferView Buffer::texel_view(VkFormat format, uint32_t texel_bytes) const {
  for (const auto& [f, view] : texel_views_)
    if (f == format) return view;
  if (!ctx_ || size_ / texel_bytes > ctx_->limits().max_texel_buffer_elements) return VK_NULL_HANDLE;
  VkBufferViewCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
  info.buffer = buffer_;
  info.format = format;
  info.range = (std::max<VkDeviceSize>(size_, texel_bytes) / texel_bytes) * texel_bytes;
  VkBufferView view = VK_NULL_HANDLE;
  TS_VK_CHECK(vkCreateBufferView(ctx_->device(), &info, nullptr, &view));
  texel_views_.emplace_back(format, view);
  return view;
}

void Buffer::reset() {
  if (!ctx_) return;
  for (const auto& [format, view] : texel_views_) vkDestroyBufferView(ctx_->device(), view, nullptr);
  texel_views_.clear();
  if (buffer_) vkDestroyBuffer(ctx_->device(), buffer_, nullptr);
  if (memory_) vkFreeMemory(ctx_->device(), memory_, nullptr);  // unmaps implicitly
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
  address_ = 0;
  size_ = 0;
  ctx_ = nullptr;
}

void upload(Context& ctx, Buffer& dst, const void* data, VkDeviceSize size, VkDeviceSize dst_offset) {
  if (size == 0) return;
  ctx.count_upload(size);
  if (dst.mapped()) {
    std::memcpy(static_cast<char*>(dst.mapped()) + dst_offset, data, size);
    return;
  }
  Buffer staging(ctx, size, MemoryUse::Upload, dst.name() + " (staging)");
  std::memcpy(staging.mapped(), data, size);
  ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, dst_offset, size};
    vkCmdCopyBuffer(cmd, staging.handle(), dst.handle(), 1, &region);
  });
}

}  // namespace tilesplat::vk
