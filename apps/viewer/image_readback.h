// The window's picture back in host memory, for a screenshot of what the viewer shows.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "viewer/window_device.h"

namespace tilesplat::viewer {

// Waits for the queue to be idle and copies an R32G32B32A32_SFLOAT or R16G16B16A16_SFLOAT image (in
// `layout`, left there) into float RGBA, row 0 at the top.
std::vector<float> read_rgba(const WindowDevice& device, VkImage image, VkFormat format, VkImageLayout layout,
                             uint32_t width, uint32_t height);

}  // namespace tilesplat::viewer
