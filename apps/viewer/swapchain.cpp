#include "viewer/swapchain.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace tilesplat::viewer {

namespace {

constexpr VkFormat kFloatFormat = VK_FORMAT_R32G32B32A32_SFLOAT;

bool supports(VkPhysicalDevice device, VkFormat format, VkFormatFeatureFlags features) {
  VkFormatProperties properties;
  vkGetPhysicalDeviceFormatProperties(device, format, &properties);
  return (properties.optimalTilingFeatures & features) == features;
}

// The renderer writes linear radiance. An _SRGB swapchain makes the blit encode it, so the window
// shows what a PNG preview without exposure or tone curve shows; a _UNORM one shows the linear
// values (darker mid-tones).
VkSurfaceFormatKHR choose_format(const WindowDevice& device) {
  uint32_t count = 0;
  vk_check(vkGetPhysicalDeviceSurfaceFormatsKHR(device.physical_device(), device.surface(), &count, nullptr),
           "vkGetPhysicalDeviceSurfaceFormatsKHR");
  std::vector<VkSurfaceFormatKHR> formats(count);
  vk_check(vkGetPhysicalDeviceSurfaceFormatsKHR(device.physical_device(), device.surface(), &count, formats.data()),
           "vkGetPhysicalDeviceSurfaceFormatsKHR");
  const VkFormat preferred[] = {VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_B8G8R8A8_UNORM,
                                VK_FORMAT_R8G8B8A8_UNORM};
  for (VkFormat wanted : preferred)
    for (const VkSurfaceFormatKHR& format : formats)
      if (format.format == wanted && supports(device.physical_device(), wanted, VK_FORMAT_FEATURE_BLIT_DST_BIT))
        return format;
  throw std::runtime_error(device.name() + ": the window offers no 8-bit RGBA format that a blit can write");
}

void transition(VkCommandBuffer commands, VkImage image, VkImageLayout from, VkImageLayout to,
                VkAccessFlags src_access, VkAccessFlags dst_access, VkPipelineStageFlags src_stage,
                VkPipelineStageFlags dst_stage) {
  VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  barrier.oldLayout = from;
  barrier.newLayout = to;
  barrier.srcAccessMask = src_access;
  barrier.dstAccessMask = dst_access;
  barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = image;
  barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(commands, src_stage, dst_stage, 0, 0, nullptr, 0, nullptr, 1, &barrier);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// FloatImage

FloatImage::FloatImage(const WindowDevice& device, uint32_t width, uint32_t height)
    : device_(device.device()), width_(width), height_(height) {
  if (!supports(device.physical_device(), kFloatFormat, VK_FORMAT_FEATURE_BLIT_SRC_BIT))
    throw std::runtime_error(device.name() + ": R32G32B32A32_SFLOAT images cannot be blitted from");
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = kFloatFormat;
  info.extent = {width, height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  vk_check(vkCreateImage(device_, &info, nullptr, &image_), "vkCreateImage (the float image)");

  VkMemoryRequirements requirements;
  vkGetImageMemoryRequirements(device_, image_, &requirements);
  VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  allocate.allocationSize = requirements.size;
  // Device-local where the device has it (every GPU); any allowed type otherwise.
  allocate.memoryTypeIndex = device.memory_type(requirements.memoryTypeBits, 0,
                                                VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, "the float image");
  try {
    vk_check(vkAllocateMemory(device_, &allocate, nullptr, &memory_), "vkAllocateMemory (the float image)");
    vk_check(vkBindImageMemory(device_, image_, memory_, 0), "vkBindImageMemory (the float image)");
    enter_blit_layout(device);
  } catch (...) {
    destroy();  // a throwing constructor runs no destructor
    throw;
  }
}

// Once, so that every frame's blit reads the image in the layout made for it.
void FloatImage::enter_blit_layout(const WindowDevice& device) {
  device.submit_and_wait([&](VkCommandBuffer commands) {
    transition(commands, image_, VK_IMAGE_LAYOUT_UNDEFINED, kLayout, 0, 0, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
               VK_PIPELINE_STAGE_TRANSFER_BIT);
  });
}

FloatImage::~FloatImage() { destroy(); }

void FloatImage::destroy() {
  if (image_) vkDestroyImage(device_, image_, nullptr);
  if (memory_) vkFreeMemory(device_, memory_, nullptr);
  image_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
}

// ---------------------------------------------------------------------------------------------
// Swapchain

Swapchain::Swapchain(const WindowDevice& device) : device_(device) {
  const VkSurfaceFormatKHR surface_format = choose_format(device);
  format_ = surface_format.format;
  VkDevice vk = device.device();
  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool.queueFamilyIndex = device.queue_family();
  vk_check(vkCreateCommandPool(vk, &pool, nullptr, &command_pool_), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  allocate.commandPool = command_pool_;
  allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocate.commandBufferCount = 1;
  VkSemaphoreCreateInfo semaphore{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  try {
    vk_check(vkAllocateCommandBuffers(vk, &allocate, &commands_), "vkAllocateCommandBuffers");
    vk_check(vkCreateSemaphore(vk, &semaphore, nullptr, &image_acquired_), "vkCreateSemaphore");
    vk_check(vkCreateFence(vk, &fence, nullptr, &blit_fence_), "vkCreateFence");
  } catch (...) {
    destroy();
    throw;
  }
}

Swapchain::~Swapchain() { destroy(); }

void Swapchain::destroy() {
  VkDevice vk = device_.device();
  vkDeviceWaitIdle(vk);
  destroy_images();
  if (swapchain_) vkDestroySwapchainKHR(vk, swapchain_, nullptr);
  if (image_acquired_) vkDestroySemaphore(vk, image_acquired_, nullptr);
  if (blit_fence_) vkDestroyFence(vk, blit_fence_, nullptr);
  if (command_pool_) vkDestroyCommandPool(vk, command_pool_, nullptr);
  swapchain_ = VK_NULL_HANDLE;
  image_acquired_ = VK_NULL_HANDLE;
  blit_fence_ = VK_NULL_HANDLE;
  command_pool_ = VK_NULL_HANDLE;
}

void Swapchain::destroy_images() {
  for (VkSemaphore semaphore : blit_done_) vkDestroySemaphore(device_.device(), semaphore, nullptr);
  blit_done_.clear();
  images_.clear();  // owned by the swapchain
}

void Swapchain::recreate(uint32_t width, uint32_t height) {
  VkDevice vk = device_.device();
  vk_check(vkDeviceWaitIdle(vk), "vkDeviceWaitIdle");
  destroy_images();
  stale_ = false;
  VkSurfaceCapabilitiesKHR caps;
  vk_check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(device_.physical_device(), device_.surface(), &caps),
           "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
  if (caps.currentExtent.width != std::numeric_limits<uint32_t>::max()) {
    extent_ = caps.currentExtent;
  } else {
    extent_.width = std::clamp(width, caps.minImageExtent.width, caps.maxImageExtent.width);
    extent_.height = std::clamp(height, caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  if (extent_.width == 0 || extent_.height == 0 || width == 0 || height == 0) {
    extent_ = {0, 0};  // minimized: no images until the window is restored
    if (swapchain_) vkDestroySwapchainKHR(vk, swapchain_, nullptr);
    swapchain_ = VK_NULL_HANDLE;
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
  info.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;  // written by the blit only, never rendered to
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  if (!(caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR))
    info.compositeAlpha = VkCompositeAlphaFlagBitsKHR(caps.supportedCompositeAlpha & -caps.supportedCompositeAlpha);
  info.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // vsync; the one mode every surface has
  info.clipped = VK_TRUE;
  info.oldSwapchain = swapchain_;
  VkSwapchainKHR created = VK_NULL_HANDLE;
  vk_check(vkCreateSwapchainKHR(vk, &info, nullptr, &created), "vkCreateSwapchainKHR");
  if (swapchain_) vkDestroySwapchainKHR(vk, swapchain_, nullptr);
  swapchain_ = created;

  uint32_t count = 0;
  vk_check(vkGetSwapchainImagesKHR(vk, swapchain_, &count, nullptr), "vkGetSwapchainImagesKHR");
  images_.resize(count);
  vk_check(vkGetSwapchainImagesKHR(vk, swapchain_, &count, images_.data()), "vkGetSwapchainImagesKHR");
  VkSemaphoreCreateInfo semaphore{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  blit_done_.assign(count, VK_NULL_HANDLE);
  for (VkSemaphore& done : blit_done_) vk_check(vkCreateSemaphore(vk, &semaphore, nullptr, &done), "vkCreateSemaphore");
}

bool Swapchain::present(VkImage source, VkImageLayout source_layout, VkExtent2D source_extent) {
  if (!swapchain_) return false;
  if (source_extent.width != extent_.width || source_extent.height != extent_.height)
    throw std::logic_error("Swapchain::present: the source image is not the swapchain's size");
  VkDevice vk = device_.device();
  uint32_t index = 0;
  const VkResult acquired =
      vkAcquireNextImageKHR(vk, swapchain_, std::numeric_limits<uint64_t>::max(), image_acquired_, VK_NULL_HANDLE,
                            &index);
  if (acquired == VK_ERROR_OUT_OF_DATE_KHR) {  // nothing acquired, the semaphore stays unsignalled
    stale_ = true;
    return false;
  }
  if (acquired != VK_SUBOPTIMAL_KHR) vk_check(acquired, "vkAcquireNextImageKHR");

  // A suboptimal image was acquired and its semaphore signalled: it is still presented, then replaced.
  vk_check(vkResetCommandBuffer(commands_, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vk_check(vkBeginCommandBuffer(commands_, &begin), "vkBeginCommandBuffer");
  // The previous contents are not needed (UNDEFINED). The source needs no barrier of ours: both
  // render_to_image and the mesh layer's last pass end with one whose second scope is every later
  // command, ours included.
  transition(commands_, images_[index], VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
             VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
  VkImageBlit region{};
  region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.srcOffsets[1] = {int32_t(extent_.width), int32_t(extent_.height), 1};
  region.dstSubresource = region.srcSubresource;
  region.dstOffsets[1] = region.srcOffsets[1];
  // 1:1, so NEAREST copies each pixel; the blit converts float to the swapchain's format.
  vkCmdBlitImage(commands_, source, source_layout, images_[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                 &region, VK_FILTER_NEAREST);
  transition(commands_, images_[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
             VK_ACCESS_TRANSFER_WRITE_BIT, 0, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
  vk_check(vkEndCommandBuffer(commands_), "vkEndCommandBuffer");

  // The blit waits for the acquired image at the transfer stage, where the first barrier starts.
  const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.waitSemaphoreCount = 1;
  submit.pWaitSemaphores = &image_acquired_;
  submit.pWaitDstStageMask = &wait_stage;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &commands_;
  submit.signalSemaphoreCount = 1;
  submit.pSignalSemaphores = &blit_done_[index];
  vk_check(vkQueueSubmit(device_.queue(), 1, &submit, blit_fence_), "vkQueueSubmit (blit)");

  VkPresentInfoKHR present{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  present.waitSemaphoreCount = 1;
  present.pWaitSemaphores = &blit_done_[index];
  present.swapchainCount = 1;
  present.pSwapchains = &swapchain_;
  present.pImageIndices = &index;
  const VkResult presented = vkQueuePresentKHR(device_.queue(), &present);
  // Waiting here frees the command buffer and the acquire semaphore for the next frame, and the
  // source for the next render; the renderer waits for its own work anyway, so little is lost.
  vk_check(vkWaitForFences(vk, 1, &blit_fence_, VK_TRUE, std::numeric_limits<uint64_t>::max()), "vkWaitForFences");
  vk_check(vkResetFences(vk, 1, &blit_fence_), "vkResetFences");
  if (presented == VK_ERROR_OUT_OF_DATE_KHR) {
    stale_ = true;
    return false;
  }
  if (presented != VK_SUBOPTIMAL_KHR) vk_check(presented, "vkQueuePresentKHR");
  stale_ = acquired == VK_SUBOPTIMAL_KHR || presented == VK_SUBOPTIMAL_KHR;
  return true;
}

}  // namespace tilesplat::viewer
