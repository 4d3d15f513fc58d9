// A host's images (tilesplat/vulkan_interop.h) as render_to_image uses them: checks of what the host
// handed over, and copies that take an image out of the host's layout and leave it there again.
#pragma once

#include <vulkan/vulkan.h>

#include "tilesplat/vulkan_interop.h"
#include "vulkan/buffer.h"

namespace tilesplat {

// Throw std::invalid_argument ("render_to_image: ...") for an image the frame cannot be written to or
// read from: a null handle, a size other than the camera's, a format or layout not supported, and
// for the depth image settings.host unset or with depth values of its own.
void check_colour_target(const ExternalImage& target, const Camera& camera);
void check_depth_image(const ExternalDepthImage& depth, const ExternalImage& target,
                       const RenderSettings& settings);
// Both: the depth image when given, else that settings.host asks for no depth out (it has nowhere to go).
void check_images(const ExternalImage& target, const ExternalDepthImage* depth, const Camera& camera,
                  const RenderSettings& settings);

// The aspect a depth image's depths are in (DEPTH for D32_SFLOAT, COLOR for R32_SFLOAT).
VkImageAspectFlags depth_aspect(const ExternalDepthImage& depth);

// Copy a tightly packed buffer into mip 0, layer 0 of `image` (aspect), or out of it. The image goes
// from `layout` to a transfer layout and back, with barriers against any earlier or later access; an
// image handed over UNDEFINED (only as a destination) is left GENERAL.
void copy_buffer_to_image(VkCommandBuffer cmd, const vk::Buffer& buffer, VkImage image,
                          VkImageAspectFlags aspect, VkImageLayout layout, uint32_t width, uint32_t height);
void copy_image_to_buffer(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout layout,
                          const vk::Buffer& buffer, uint32_t width, uint32_t height);

}  // namespace tilesplat
