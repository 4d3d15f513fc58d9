#include "swapchain.h"

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "vulkan/barriers.h"
#include "vulkan/buffer.h"

namespace tilesplat::viewer {

namespace {

constexpr VkFormat kFloatFormat = VK_FORMAT_R32G32B32A32_SFLOAT;

bool is_srgb(VkFormat format) {
  return format == VK_FORMAT_B8G8R8A8_SRGB || format == VK_FORMAT_R8G8B8A8_SRGB;
}

// The _UNORM format with an _SRGB one's layout (and so its bytes).
VkFormat unencoded_twin(VkFormat format) {
  return format == VK_FORMAT_B8G8R8A8_SRGB   ? VK_FORMAT_B8G8R8A8_UNORM
         : format == VK_FORMAT_R8G8B8A8_SRGB ? VK_FORMAT_R8G8B8A8_UNORM
                                             : format;
}

// The renderer's colours are display values already (docs/colour.md): a _UNORM swapchain shows them
// as they are. An _SRGB one is taken only where the surface offers no _UNORM format, or where
// TILESPLAT_VIEWER_SWAPCHAIN=srgb asks for it (so that tests cover that path too); it receives the
// same bytes through a copy (Swapchain::present).
VkSurfaceFormatKHR choose_format(const WindowDevice& device) {
  uint32_t count = 0;
  vk::check(vkGetPhysicalDeviceSurfaceFormatsKHR(device.physical_device(), device.surface(), &count, nullptr),
            "vkGetPhysicalDeviceSurfaceFormatsKHR");
  std::vector<VkSurfaceFormatKHR> formats(count);
  vk::check(vkGetPhysicalDeviceSurfaceFormatsKHR(device.physical_device(), device.surface(), &count,
                                                 formats.data()),
            "vkGetPhysicalDeviceSurfaceFormatsKHR");
  const char* wanted_kind = std::getenv("TILESPLAT_VIEWER_SWAPCHAIN");
  const bool srgb_first = wanted_kind && std::string(wanted_kind) == "srgb";
  std::vector<VkFormat> preferred = {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM,
                                     VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R8G8B8A8_SRGB};
  if (srgb_first) std::rotate(preferred.begin(), preferred.begin() + 2, preferred.end());
  for (VkFormat wanted : preferred)
    for (const VkSurfaceFormatKHR& format : formats) {
      if (format.format != wanted) continue;
      // An _SRGB image is written by a copy from its twin, which the blit writes.
      const bool usable =
          is_srgb(wanted)
              ? vk::format_supports(device.context(), unencoded_twin(wanted),
                                    VK_FORMAT_FEATURE_BLIT_DST_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT)
              : vk::format_supports(device.context(), wanted, VK_FORMAT_FEATURE_BLIT_DST_BIT);
      if (usable) return format;
    }
  throw std::runtime_error(device.name() + ": the window offers no 8-bit RGBA format that a blit can write");
}

}  // namespace

std::string format_name(VkFormat format) {
  switch (format) {
    case VK_FORMAT_B8G8R8A8_UNORM:
      return "B8G8R8A8_UNORM";
    case VK_FORMAT_R8G8B8A8_UNORM:
      return "R8G8B8A8_UNORM";
    case VK_FORMAT_B8G8R8A8_SRGB:
      return "B8G8R8A8_SRGB";
    case VK_FORMAT_R8G8B8A8_SRGB:
      return "R8G8B8A8_SRGB";
    default:
      return "format " + std::to_string(int(format));
  }
}

// ---------------------------------------------------------------------------------------------
// TransferImage, FloatImage

// Device-local (the engine's images are): where a device keeps optimal-tiling images.
TransferImage::TransferImage(const WindowDevice& device, VkFormat format, VkFormatFeatureFlags features,
                             VkImageLayout layout, uint32_t width, uint32_t height) {
  if (!vk::format_supports(device.context(), format, features))
    throw std::runtime_error(device.name() + ": images of " + format_name(format) +
                             " cannot be blitted or copied as the viewer needs");
  image_ = vk::Image(device.context(), format, width, height,
                     VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "a viewer image");
  // Once, so that every use finds the image in the layout made for it.
  device.context().submit_and_wait([&](VkCommandBuffer commands) {
    vk::transition(commands, {image_.handle(), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED, layout,
                              0, 0, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT});
  });
}

FloatImage::FloatImage(const WindowDevice& device, uint32_t width, uint32_t height)
    : image_(device, kFloatFormat, VK_FORMAT_FEATURE_BLIT_SRC_BIT, kLayout, width, height) {}

// ---------------------------------------------------------------------------------------------
// Swapchain

Swapchain::Swapchain(const WindowDevice& device) : device_(device) {
  format_ = choose_format(device).format;
  const VkDevice vk = device.device();
  command_pool_ = vk::make_command_pool(vk, device.queue_family());
  commands_ = vk::allocate_command_buffer(vk, command_pool_.get());
  image_acquired_ = vk::make_semaphore(vk);
  blit_fence_ = vk::make_fence(vk);
}

Swapchain::~Swapchain() {
  vkDeviceWaitIdle(device_.device());
}

void Swapchain::recreate(uint32_t width, uint32_t height) {
  VkDevice vk = device_.device();
  vk::check(vkDeviceWaitIdle(vk), "vkDeviceWaitIdle");
  blit_done_.clear();
  images_.clear();
  unencoded_.reset();
  stale_ = false;
  VkSurfaceCapabilitiesKHR caps;
  vk::check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(device_.physical_device(), device_.surface(), &caps),
            "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
  if (caps.currentExtent.width != std::numeric_limits<uint32_t>::max()) {
    extent_ = caps.currentExtent;
  } else {
    extent_.width = std::clamp(width, caps.minImageExtent.width, caps.maxImageExtent.width);
    extent_.height = std::clamp(height, caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  if (extent_.width == 0 || extent_.height == 0 || width == 0 || height == 0) {
    extent_ = {0, 0};  // minimized: no images until the window is restored
    swapchain_.reset();
    return;
  }
  if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
    throw std::runtime_error(device_.name() + ": the window's images cannot be blitted to (no TRANSFER_DST usage)");

  VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  info.surface = device_.surface();
  // One image more than the minimum, so that acquiring never waits for the display to release one.
  info.minImageCount = caps.minImageCount + 1;
  if (caps.maxImageCount > 0) info.minImageCount = std::min(info.minImageCount, caps.maxImageCount);
  info.imageFormat = format_;
  info.imageColorSpace = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  info.imageExtent = extent_;
  info.imageArrayLayers = 1;
  // Written by the blit or copy only, never rendered to; read back for a screenshot where it can be.
  can_read_back_ = (caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) != 0;
  info.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | (can_read_back_ ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0);
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  if (!(caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR))
    info.compositeAlpha = VkCompositeAlphaFlagBitsKHR(caps.supportedCompositeAlpha & -caps.supportedCompositeAlpha);
  info.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // vsync; the one mode every surface has
  info.clipped = VK_TRUE;
  info.oldSwapchain = swapchain_.get();
  vk::UniqueSwapchain created;
  vk::check(vkCreateSwapchainKHR(vk, &info, nullptr, created.receive(vk)), "vkCreateSwapchainKHR");
  swapchain_ = std::move(created);  // the old one goes

  uint32_t count = 0;
  vk::check(vkGetSwapchainImagesKHR(vk, swapchain_.get(), &count, nullptr), "vkGetSwapchainImagesKHR");
  images_.resize(count);
  vk::check(vkGetSwapchainImagesKHR(vk, swapchain_.get(), &count, images_.data()), "vkGetSwapchainImagesKHR");
  for (uint32_t i = 0; i < count; ++i) blit_done_.push_back(vk::make_semaphore(vk));
  if (is_srgb(format_))
    unencoded_ = std::make_unique<TransferImage>(
        device_, unencoded_twin(format_), VK_FORMAT_FEATURE_BLIT_DST_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT,
        VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, extent_.width, extent_.height);
}

// A 1:1 blit, so NEAREST copies each pixel; it converts float to the target's 8-bit format. The
// target is in TRANSFER_DST_OPTIMAL.
void Swapchain::record_blit(VkImage source, VkImageLayout source_layout, VkImage target) {
  VkImageBlit region{};
  region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.srcOffsets[1] = {int32_t(extent_.width), int32_t(extent_.height), 1};
  region.dstSubresource = region.srcSubresource;
  region.dstOffsets[1] = region.srcOffsets[1];
  vkCmdBlitImage(commands_, source, source_layout, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region,
                 VK_FILTER_NEAREST);
}

bool Swapchain::present(VkImage source, VkImageLayout source_layout, VkExtent2D source_extent,
                        WindowPixels* shown) {
  if (!swapchain_) return false;
  if (shown && !can_read_back_)
    throw std::runtime_error(device_.name() +
                             ": the window's images cannot be read back (no TRANSFER_SRC usage)");
  if (source_extent.width != extent_.width || source_extent.height != extent_.height)
    throw std::logic_error("Swapchain::present: the source image is not the swapchain's size");
  VkDevice vk = device_.device();
  uint32_t index = 0;
  const VkResult acquired = vkAcquireNextImageKHR(vk, swapchain_.get(), std::numeric_limits<uint64_t>::max(),
                                                  image_acquired_.get(), VK_NULL_HANDLE, &index);
  if (acquired == VK_ERROR_OUT_OF_DATE_KHR) {  // nothing acquired, the semaphore stays unsignalled
    stale_ = true;
    return false;
  }
  if (acquired != VK_SUBOPTIMAL_KHR) vk::check(acquired, "vkAcquireNextImageKHR");

  // A suboptimal image was acquired and its semaphore signalled: it is still presented, then replaced.
  vk::check(vkResetCommandBuffer(commands_, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vk::check(vkBeginCommandBuffer(commands_, &begin), "vkBeginCommandBuffer");
  // The previous contents are not needed (UNDEFINED). The source needs no barrier of ours: both
  // render_to_image and the mesh layer's last pass end with one whose second scope is every later
  // command, ours included.
  vk::transition(commands_, {images_[index], VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                             VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
                             VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT});
  VkImage window_image = images_[index];
  if (!unencoded_) {
    record_blit(source, source_layout, window_image);
  } else {
    // The blit writes the _UNORM twin (no encoding); its bytes go to the _SRGB image unchanged.
    VkImage twin = unencoded_->image();
    record_blit(source, source_layout, twin);
    vk::transition(commands_, {twin, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                               VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                               VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                               VK_PIPELINE_STAGE_TRANSFER_BIT});
    VkImageCopy copy{};
    copy.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.dstSubresource = copy.srcSubresource;
    copy.extent = {extent_.width, extent_.height, 1};
    vkCmdCopyImage(commands_, twin, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, window_image,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
    // Back to the layout the next frame's blit expects, once the copy has read it.
    vk::transition(commands_, {twin, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_ACCESS_TRANSFER_READ_BIT,
                               VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                               VK_PIPELINE_STAGE_TRANSFER_BIT});
  }
  vk::Buffer readback;
  VkImageLayout window_layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  if (shown) {
    readback = vk::Buffer(device_.context(), VkDeviceSize(extent_.width) * extent_.height * 4,
                          vk::MemoryUse::Readback, "the window's pixels");
    vk::transition(commands_, {window_image, VK_IMAGE_ASPECT_COLOR_BIT, window_layout,
                               VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT,
                               VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                               VK_PIPELINE_STAGE_TRANSFER_BIT});
    window_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {extent_.width, extent_.height, 1};
    vkCmdCopyImageToBuffer(commands_, window_image, window_layout, readback.handle(), 1, &region);
    VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(commands_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                         &to_host, 0, nullptr, 0, nullptr);
  }
  vk::transition(commands_,
                 {window_image, VK_IMAGE_ASPECT_COLOR_BIT, window_layout, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                  shown ? VkAccessFlags{0} : VkAccessFlags{VK_ACCESS_TRANSFER_WRITE_BIT}, 0,
                  VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT});
  vk::check(vkEndCommandBuffer(commands_), "vkEndCommandBuffer");

  // The blit waits for the acquired image at the transfer stage, where the first barrier starts.
  const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.waitSemaphoreCount = 1;
  submit.pWaitSemaphores = image_acquired_.address();
  submit.pWaitDstStageMask = &wait_stage;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &commands_;
  submit.signalSemaphoreCount = 1;
  submit.pSignalSemaphores = blit_done_[index].address();
  vk::check(vkQueueSubmit(device_.queue(), 1, &submit, blit_fence_.get()), "vkQueueSubmit (blit)");

  VkPresentInfoKHR present{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  present.waitSemaphoreCount = 1;
  present.pWaitSemaphores = blit_done_[index].address();
  present.swapchainCount = 1;
  present.pSwapchains = swapchain_.address();
  present.pImageIndices = &index;
  const VkResult presented = vkQueuePresentKHR(device_.queue(), &present);
  // Waiting here frees the command buffer and the acquire semaphore for the next frame, and the
  // source for the next render; the renderer waits for its own work anyway, so little is lost.
  vk::check(vkWaitForFences(vk, 1, blit_fence_.address(), VK_TRUE, std::numeric_limits<uint64_t>::max()),
            "vkWaitForFences");
  vk::check(vkResetFences(vk, 1, blit_fence_.address()), "vkResetFences");
  if (shown) {
    // The window's bytes in its format's channel order; the screenshot is R G B.
    const bool bgr = format_ == VK_FORMAT_B8G8R8A8_UNORM || format_ == VK_FORMAT_B8G8R8A8_SRGB;
    const auto* bytes = readback.mapped_as<const uint8_t>();
    shown->width = extent_.width;
    shown->height = extent_.height;
    shown->rgb.resize(size_t(extent_.width) * extent_.height * 3);
    for (size_t pixel = 0; pixel < size_t(extent_.width) * extent_.height; ++pixel)
      for (size_t c = 0; c < 3; ++c) shown->rgb[3 * pixel + c] = bytes[4 * pixel + (bgr ? 2 - c : c)];
  }
  if (presented == VK_ERROR_OUT_OF_DATE_KHR) {
    stale_ = true;
    return false;
  }
  if (presented != VK_SUBOPTIMAL_KHR) vk::check(presented, "vkQueuePresentKHR");
  stale_ = acquired == VK_SUBOPTIMAL_KHR || presented == VK_SUBOPTIMAL_KHR;
  return true;
}

}  // namespace tilesplat::viewer
