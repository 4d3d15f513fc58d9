// A device-local 2D image with one view: the raster compositor's colour attachments and its depth
// attachment (VK_FORMAT_D32_SFLOAT, whose view and copies take the depth aspect), and the viewer's images.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>

#include "vulkan/context.h"

namespace tilesplat::vk {

class Image {
 public:
  Image() = default;
  // Throws std::runtime_error naming the image when the device cannot make or back it.
  Image(Context& ctx, VkFormat format, uint32_t width, uint32_t height, VkImageUsageFlags usage,
        std::string name);
  ~Image() { reset(); }
  Image(Image&& other) noexcept { *this = std::move(other); }
  Image& operator=(Image&& other) noexcept;
  Image(const Image&) = delete;
  Image& operator=(const Image&) = delete;
  void reset();

  explicit operator bool() const { return image_ != VK_NULL_HANDLE; }
  VkImage handle() const { return image_; }
  VkImageView view() const { return view_; }  // null for an image only copied (no view usage)
  VkFormat format() const { return format_; }
  VkImageAspectFlags aspect() const;  // depth for VK_FORMAT_D32_SFLOAT, else colour
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  VkDeviceSize bytes() const { return bytes_; }  // the memory it holds

 private:
  Context* ctx_ = nullptr;
  VkImage image_ = VK_NULL_HANDLE;
  VkImageView view_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  uint32_t width_ = 0, height_ = 0;
  VkDeviceSize bytes_ = 0;
  std::string name_;
};

// Whether the device's optimal-tiling images of `format` have all of `features`.
bool format_supports(const Context& ctx, VkFormat format, VkFormatFeatureFlags features);

}  // namespace tilesplat::vk
