// Host depth: a host's depth image on the device (render_to_image with an ExternalDepthImage), turned
// into the view depths the composite tests splats against, and the splats' surface depths turned back
// into the host's convention (host_depth.comp). Buffers hold one float a pixel, row-major.
#pragma once

#include "tilesplat/camera.h"
#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"
#include "vulkan/pipeline_variants.h"

namespace tilesplat {

class HostDepthPass {
 public:
  explicit HostDepthPass(vk::Context& ctx) : ctx_(ctx) {}
  // view = the view depth of each window depth, +inf where the host drew nothing (or a NaN).
  void record_view_depths(VkCommandBuffer cmd, const DepthConvention& convention, const vk::Buffer& window,
                          const vk::Buffer& view, uint32_t width, uint32_t height);
  // In place: window = the surface's depth in the host's convention where the splats reached their
  // alpha threshold (surface > 0), the host's own depth elsewhere.
  void record_window_depths(VkCommandBuffer cmd, const DepthConvention& convention, const vk::Buffer& surface,
                            const vk::Buffer& window, uint32_t width, uint32_t height);

 private:
  void record(VkCommandBuffer cmd, uint32_t direction, const DepthConvention& convention,
              const vk::Buffer& window, const vk::Buffer& view, uint32_t width, uint32_t height);

  vk::Context& ctx_;
  vk::PipelineVariants<uint32_t> pipelines_;  // by direction (a specialization constant)
};

}  // namespace tilesplat
