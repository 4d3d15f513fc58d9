// An image's layout transition and the memory dependency around it, written once for the engine's copies
// in and out of host images, the raster compositor's depth, and the viewer's swapchain and mesh.
#pragma once

#include <vulkan/vulkan.h>

namespace tilesplat::vk {

// On mip level 0 and array layer 0: every image the engine, a host (vulkan_interop.h) or the viewer hands
// over has one of each. Without stages, the dependency is between all commands before and all after.
struct ImageTransition {
  VkImage image = VK_NULL_HANDLE;
  VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT;
  VkImageLayout from = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImageLayout to = VK_IMAGE_LAYOUT_UNDEFINED;
  VkAccessFlags src_access = 0;
  VkAccessFlags dst_access = 0;
  VkPipelineStageFlags src_stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
  VkPipelineStageFlags dst_stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
};

inline void transition(VkCommandBuffer cmd, const ImageTransition& t) {
  VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  barrier.oldLayout = t.from;
  barrier.newLayout = t.to;
  barrier.srcAccessMask = t.src_access;
  barrier.dstAccessMask = t.dst_access;
  barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = t.image;
  barrier.subresourceRange = {t.aspect, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, t.src_stage, t.dst_stage, 0, 0, nullptr, 0, nullptr, 1, &barrier);
}

}  // namespace tilesplat::vk
