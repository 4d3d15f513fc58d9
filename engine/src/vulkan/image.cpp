#include "vulkan/image.h"

#include <stdexcept>
#include <utility>

#include "vulkan/vk_check.h"

namespace tilesplat::vk {

Image::Image(Context& ctx, VkFormat format, uint32_t width, uint32_t height, VkImageUsageFlags usage,
             std::string name)
    : ctx_(&ctx), format_(format), width_(width), height_(height), name_(std::move(name)) {
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {width, height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkResult result = vkCreateImage(ctx.device(), &info, nullptr, &image_);
  if (result != VK_SUCCESS)
    throw std::runtime_error("cannot create image '" + name_ + "' (" + std::to_string(width) + "x" +
                             std::to_string(height) + "): " + result_name(result));
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(ctx.device(), image_, &req);
  if (req.size > ctx.limits().max_allocation_size) {
    reset();
    throw std::runtime_error("image '" + name_ + "' needs " + std::to_string(req.size) +
                             " bytes, more than the device's largest allocation");
  }
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = ctx.find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  result = vkAllocateMemory(ctx.device(), &alloc, nullptr, &memory_);
  if (result != VK_SUCCESS) {
    reset();
    throw std::runtime_error("cannot allocate " + std::to_string(req.size) + " bytes for image '" + name_ +
                             "': " + result_name(result));
  }
  bytes_ = req.size;
  TS_VK_CHECK(vkBindImageMemory(ctx.device(), image_, memory_, 0));
  // A view only where the usage allows one (an image that is only copied and blitted has none).
  constexpr VkImageUsageFlags kViewed =
      VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
      VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT;
  if (!(usage & kViewed)) return;
  VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view.image = image_;
  view.viewType = VK_IMAGE_VIEW_TYPE_2D;
  view.format = format;
  view.subresourceRange = {aspect(), 0, 1, 0, 1};
  TS_VK_CHECK(vkCreateImageView(ctx.device(), &view, nullptr, &view_));
}

Image& Image::operator=(Image&& other) noexcept {
  if (this != &other) {
    reset();
    ctx_ = std::exchange(other.ctx_, nullptr);
    image_ = std::exchange(other.image_, VK_NULL_HANDLE);
    view_ = std::exchange(other.view_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    format_ = std::exchange(other.format_, VK_FORMAT_UNDEFINED);
    width_ = std::exchange(other.width_, 0);
    height_ = std::exchange(other.height_, 0);
    bytes_ = std::exchange(other.bytes_, 0);
    name_ = std::move(other.name_);
  }
  return *this;
}

void Image::reset() {
  if (!ctx_) return;
  VkDevice device = ctx_->device();
  if (view_) vkDestroyImageView(device, view_, nullptr);
  if (image_) vkDestroyImage(device, image_, nullptr);
  if (memory_) vkFreeMemory(device, memory_, nullptr);
  view_ = VK_NULL_HANDLE;
  image_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  bytes_ = 0;
}

VkImageAspectFlags Image::aspect() const {
  return format_ == VK_FORMAT_D32_SFLOAT ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
}

bool format_supports(const Context& ctx, VkFormat format, VkFormatFeatureFlags features) {
  VkFormatProperties properties;
  vkGetPhysicalDeviceFormatProperties(ctx.physical_device(), format, &properties);
  return (properties.optimalTilingFeatures & features) == features;
}

}  // namespace tilesplat::vk
