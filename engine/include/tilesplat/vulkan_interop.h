/// @file
/// Running the renderer inside a host application's Vulkan: on its device, into its images.
/// The only public header with Vulkan types; the rest of the API stays Vulkan-free.
#pragma once

#include <vulkan/vulkan.h>

#include <memory>
#include <span>

#include "tilesplat/export.h"
#include "tilesplat/renderer.h"

namespace tilesplat {

/// A device the host application created. The renderer borrows these handles: it never destroys
/// them, and they must outlive the renderer. The device must have been created with Vulkan 1.2,
/// VkPhysicalDeviceVulkan12Features::bufferDeviceAddress and VkPhysicalDeviceFeatures::shaderInt64
/// (and preferably shaderFloat64, which makes the projection's geometry exact; say so below).
/// The renderer submits to `queue` and waits for its own fence; do not use the queue from another
/// thread while a render call runs.
struct ExternalVulkanDevice {
  VkInstance instance = VK_NULL_HANDLE;               ///< the host's instance (Vulkan 1.2 or later)
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;  ///< the physical device `device` was made on
  VkDevice device = VK_NULL_HANDLE;                   ///< the host's logical device
  VkQueue queue = VK_NULL_HANDLE;                     ///< from a family with compute and timestamp support
  uint32_t queue_family = 0;                          ///< the family `queue` belongs to
  bool shader_float64_enabled = false;                ///< whether `device` was created with shaderFloat64 on
  /// Whether `device` was created with independentBlend on, which the raster compositor's splat counts
  /// need (Compositor::kRaster); without it, render with RenderSettings::splat_count off.
  bool independent_blend_enabled = false;
  /// Whether `device` was created with VK_EXT_rasterization_order_attachment_access and its
  /// rasterizationOrderColorAttachmentAccess on, which the raster compositor's depth out with a host's
  /// depth needs (HostDepth::write_depth with Compositor::kRaster).
  bool rasterization_order_attachment_access_enabled = false;
};

/// A renderer on the host's device. RendererOptions::device and RendererOptions::validation do not apply (the
/// host chose the device and its instance's layers). Throws std::invalid_argument for bad handles.
TILESPLAT_API std::unique_ptr<Renderer> create_renderer(const ExternalVulkanDevice& device,
                                                        const RendererOptions& options = {});

/// An image the caller owns, created on the same device as the renderer.
struct ExternalImage {
  VkImage image = VK_NULL_HANDLE;  ///< the host's 2D image; mip level 0, array layer 0 is written
  uint32_t width = 0;              ///< must equal the camera's width
  uint32_t height = 0;             ///< must equal the camera's height
  /// R32G32B32A32_SFLOAT (the frame as it is: display values, as Renderer::render returns them),
  /// R16G16B16A16_SFLOAT (rounded to half), R8G8B8A8_UNORM (clamped to [0, 1], round(255 c)) or
  /// R8G8B8A8_SRGB (the same bytes as UNORM, since the colours are sRGB-encoded already: sampling the image
  /// decodes them to linear light, per premultiplied channel; docs/colour.md).
  VkFormat format = VK_FORMAT_R32G32B32A32_SFLOAT;
  /// The layout the image is in when render_to_image is called; it is left in the same layout
  /// (an image handed over in VK_IMAGE_LAYOUT_UNDEFINED is left in VK_IMAGE_LAYOUT_GENERAL).
  /// The image needs VK_IMAGE_USAGE_TRANSFER_DST_BIT.
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
};

/// A host's depth image for render_to_image, created on the renderer's device: the depth buffer it
/// drew its meshes into, in the convention of RenderSettings::host.
struct ExternalDepthImage {
  VkImage image = VK_NULL_HANDLE;  ///< the host's 2D image; mip level 0, array layer 0
  uint32_t width = 0;              ///< must equal the camera's width
  uint32_t height = 0;             ///< must equal the camera's height
  /// VK_FORMAT_D32_SFLOAT (its depth aspect) or VK_FORMAT_R32_SFLOAT (a depth the host copied out).
  VkFormat format = VK_FORMAT_D32_SFLOAT;
  /// The layout the image is in when render_to_image is called and is left in (not UNDEFINED: its
  /// contents are read). It needs VK_IMAGE_USAGE_TRANSFER_SRC_BIT, and VK_IMAGE_USAGE_TRANSFER_DST_BIT
  /// when HostDepth::write_depth writes the splats' depth into it.
  VkImageLayout layout = VK_IMAGE_LAYOUT_GENERAL;
};

/// Renders a frame and writes premultiplied RGBA (colour over the background, A = 1 - T) into the
/// image. The work has completed on the GPU when the call returns. RenderSettings::host depth-tests
/// the splats against a host's depth values given in host memory (HostDepth::depth); its depth out
/// (HostDepth::write_depth) needs the overload below, with a depth image. Throws
/// std::invalid_argument when the image does not match the camera or has an unsupported format, or
/// for write_depth.
TILESPLAT_API void render_to_image(Renderer& renderer, const Camera& camera, const RenderSettings& settings,
                                   const ExternalImage& target);

/// The same, depth-tested against the host's depth image: settings.host must be set (its convention,
/// write_depth, alpha_threshold) without depth values of its own, as the image provides them. The
/// splats blend only in front of the image's surfaces; with write_depth, the image then holds the
/// splats' depth where their alpha reached the threshold and keeps the host's elsewhere, so that
/// geometry drawn afterwards is hidden behind dense splats. The depth stays on the device (a compute
/// pass converts it, in float64 where the device has it); a NaN in the image means no surface at that
/// pixel. Blocks, as the call above. Throws std::invalid_argument for a missing or mismatched image,
/// an unsupported format or layout, or settings.host unset or with depth values.
TILESPLAT_API void render_to_image(Renderer& renderer, const Camera& camera, const RenderSettings& settings,
                                   const ExternalImage& target, const ExternalDepthImage& depth);

/// The host's semaphores around a frame that render_to_image submits without waiting for it. Binary
/// semaphores, or timeline ones with their values (VkTimelineSemaphoreSubmitInfo, Vulkan 1.2).
struct HostFrameSync {
  /// Waited for before the frame's first command (the host's work that wrote the depth image, say).
  /// Each must be signalled, or have its signal submitted, before the call.
  std::span<const VkSemaphore> wait;
  /// The stage each wait blocks, one per semaphore; empty: VK_PIPELINE_STAGE_ALL_COMMANDS_BIT.
  std::span<const VkPipelineStageFlags> wait_stages;
  std::span<const uint64_t> wait_values;  ///< one per wait semaphore for timeline ones; empty for binary
  /// Signalled once the frame's writes to the colour and depth images are complete and available.
  std::span<const VkSemaphore> signal;
  std::span<const uint64_t> signal_values;  ///< one per signal semaphore for timeline ones; empty for binary
};

/// Renders a frame into the host's images without waiting for it: the frame is submitted to
/// ExternalVulkanDevice::queue, waiting for `sync.wait` and signalling `sync.signal`, and the call
/// returns while it runs, so the host records and submits its own work meanwhile. `depth` may be null
/// (then settings.host must not ask for write_depth); otherwise as the blocking overload above.
///
/// One frame is in flight at a time: the next call of any kind on the renderer (or
/// wait_for_frame(), or its destruction) first waits for this one. The images must stay valid, and
/// must not be used by the host, until `sync.signal` is signalled; they are left in their layouts.
/// last_frame_stats() describes a frame once it has been waited for. The frame cannot re-render on
/// the host's time: one that needs more (tile, Gaussian) pairs or composite chunks than the buffers
/// hold is drawn with those that fit (FrameStats::complete is false), and the buffers grow for the
/// next frame. Errors found only when the frame is waited for (a frame beyond the renderer's limits)
/// are thrown by that wait.
TILESPLAT_API void render_to_image(Renderer& renderer, const Camera& camera, const RenderSettings& settings,
                                   const ExternalImage& target, const ExternalDepthImage* depth,
                                   const HostFrameSync& sync);

/// A command buffer of the host's that render_to_image records a frame into, and how the renderer
/// learns that the host's submission of it has completed.
struct HostCommandBuffer {
  /// In the recording state, from a pool of ExternalVulkanDevice::queue_family; the host submits it
  /// (to a queue of that family) before its next call on the renderer.
  VkCommandBuffer command_buffer = VK_NULL_HANDLE;
  /// A timeline semaphore (Vulkan 1.2) that the host's submission of the command buffer signals...
  VkSemaphore timeline = VK_NULL_HANDLE;
  uint64_t value = 0;  ///< ...to this value, or a later one, once the command buffer has completed
};

/// Records a frame into the host's command buffer instead of submitting it: the frame runs inside the
/// host's own submission, wherever the host puts it among its commands. Every image access is fenced
/// by barriers against all commands before and after it (docs/embedding.md), and the images are left
/// in their layouts. The renderer's own buffers are uploaded as the call records, so one frame is in
/// flight at a time: the next call on the renderer (or wait_for_frame(), or its destruction) first
/// waits for `commands.timeline` to reach `commands.value`, and the host must have submitted the
/// command buffer by then. As with HostFrameSync, a frame that outgrows the buffers is drawn with what
/// fits (FrameStats::complete). Throws std::invalid_argument as the calls above, for a null command
/// buffer or semaphore, and for a sort strategy that sorts on the host mid-frame (cpu-radix), before
/// recording anything.
TILESPLAT_API void render_to_image(Renderer& renderer, const Camera& camera, const RenderSettings& settings,
                                   const ExternalImage& target, const ExternalDepthImage* depth,
                                   const HostCommandBuffer& commands);

/// Waits for the frame render_to_image(..., HostFrameSync or HostCommandBuffer) left running, if it
/// has not completed, and makes its statistics last_frame_stats(). Nothing to do after a blocking call.
TILESPLAT_API void wait_for_frame(Renderer& renderer);

}  // namespace tilesplat
