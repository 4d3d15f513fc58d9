// What the viewer shows and how: the float image the renderer writes, and the window's swapchain,
// into which each frame is blitted (float to 8-bit, the format conversion done by the blit).
//
// Colours (docs/colour.md): the renderer's values are the trained display values, already sRGB-encoded,
// so the window must receive them as they are, byte = round(255 * c). A _UNORM swapchain does that
// through the blit. An _SRGB one would encode them a second time (washed out); where the surface offers
// only those, the blit writes a _UNORM image of the same layout whose bytes are then copied unchanged.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tilesplat/vulkan_interop.h"
#include "vulkan/handle.h"
#include "vulkan/image.h"
#include "window_device.h"

namespace tilesplat::viewer {

// A 2D image in device memory that transfers read and write (TRANSFER_SRC and _DST), kept in one
// layout between uses.
class TransferImage {
 public:
  // Created and moved into `layout` once, where every use then finds it. Throws std::runtime_error when
  // the format lacks any of `features` (optimal tiling).
  TransferImage(const WindowDevice& device, VkFormat format, VkFormatFeatureFlags features,
                VkImageLayout layout, uint32_t width, uint32_t height);

  VkImage image() const { return image_.handle(); }
  uint32_t width() const { return image_.width(); }
  uint32_t height() const { return image_.height(); }

 private:
  vk::Image image_;
};

// An R32G32B32A32_SFLOAT image the renderer writes with render_to_image (TRANSFER_DST) and the
// swapchain blits from (TRANSFER_SRC), in device memory. It lives in TRANSFER_SRC_OPTIMAL, the
// layout of the blit; render_to_image leaves it in the layout it found it in.
class FloatImage {
 public:
  FloatImage(const WindowDevice& device, uint32_t width, uint32_t height);

  static constexpr VkImageLayout kLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;

  ExternalImage target() const {
    return {image_.image(), image_.width(), image_.height(), VK_FORMAT_R32G32B32A32_SFLOAT, kLayout};
  }
  VkImage image() const { return image_.image(); }

 private:
  TransferImage image_;
};

// "B8G8R8A8_UNORM" and so on, for the formats a swapchain may be given.
std::string format_name(VkFormat format);

// The window's pixels as presented: RGB bytes, row 0 at the top, as the swapchain image held them.
struct WindowPixels {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgb;
};

class Swapchain {
 public:
  explicit Swapchain(const WindowDevice& device);
  ~Swapchain();  // waits for the device to be idle; the handles then release themselves
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  // (Re)creates the images to fit the surface; `width` x `height` (the framebuffer) is used where the
  // surface leaves the size to the application. Waits for the device to be idle first. The extent
  // may be 0x0 (a minimized window): then there are no images and nothing can be presented.
  void recreate(uint32_t width, uint32_t height);
  VkExtent2D extent() const { return extent_; }
  VkFormat format() const { return format_; }

  // Blits `source` (the swapchain's extent, in `source_layout`) into the next image and presents it,
  // FIFO (vsync). Returns when the blit has read the source, so the caller may render into it again. Returns
  // false when nothing was shown (VK_ERROR_OUT_OF_DATE_KHR, or no images): recreate, present again.
  // Either way, stale() says whether the swapchain no longer fits the surface (also after
  // VK_SUBOPTIMAL_KHR, when the frame was shown): recreate it before the next frame.
  // With `shown`, the presented image's bytes are also copied back into it (needs TRANSFER_SRC on the
  // window's images; std::runtime_error where the surface does not offer it).
  bool present(VkImage source, VkImageLayout source_layout, VkExtent2D source_extent,
               WindowPixels* shown = nullptr);
  bool stale() const { return stale_; }

 private:
  void record_blit(VkImage source, VkImageLayout source_layout, VkImage target);

  const WindowDevice& device_;
  vk::UniqueSwapchain swapchain_;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkExtent2D extent_{0, 0};
  std::vector<VkImage> images_;  // the swapchain's
  // Signalled by the blit's submission and waited on by the presentation of that image. One per
  // image: the presentation engine may still hold an image's semaphore while another is acquired.
  std::vector<vk::UniqueSemaphore> blit_done_;
  vk::UniqueSemaphore image_acquired_;
  vk::UniqueFence blit_fence_;
  vk::UniqueCommandPool command_pool_;
  VkCommandBuffer commands_ = VK_NULL_HANDLE;  // from command_pool_, freed with it
  bool stale_ = true;  // no images yet
  bool can_read_back_ = false;  // the window's images were created with TRANSFER_SRC
  // An _SRGB swapchain's _UNORM twin, which the blit writes and whose bytes are copied into the
  // window's image unchanged; null for a _UNORM swapchain.
  std::unique_ptr<TransferImage> unencoded_;
};

}  // namespace tilesplat::viewer
