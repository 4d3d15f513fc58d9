// The viewer's own geometry around the splats, as a host application would draw it: a box that the
// scene intersects, drawn first into a colour and a depth buffer; the splats, depth-tested against
// that buffer on the device (render_to_image with the host's semaphores, no CPU stall), writing
// their depth into it where they are dense; then the splats blended over the box's colour, and a
// ground grid drawn last, hidden behind the splats' depth.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/vulkan_interop.h"
#include "vulkan/barriers.h"
#include "vulkan/buffer.h"
#include "vulkan/handle.h"
#include "vulkan/image.h"
#include "window_device.h"

namespace tilesplat::viewer {

class MeshLayer {
 public:
  // Geometry sized to the scene's bounds; images of `width` x `height`.
  MeshLayer(const WindowDevice& device, const Bounds& bounds, uint32_t width, uint32_t height);
  ~MeshLayer();  // waits for the layer's submissions; the handles then release themselves
  MeshLayer(const MeshLayer&) = delete;
  MeshLayer& operator=(const MeshLayer&) = delete;

  // One frame: the box, the splats (submitted without waiting, between the box's submission and the
  // grid's), the grid. `settings` are the frame's; the background becomes the clear colour. Without
  // `depth_out` the splats leave the depth buffer as the box left it, and the grid is drawn over them.
  void draw(Renderer& renderer, const Camera& camera, const RenderSettings& settings, bool depth_out);
  // Whether the frame's modes depth-test against a host's surfaces (not per-pixel re-sorting, not the
  // stochastic compositor); draw() shows the splats alone over the background in the others.
  static bool depth_testable(const RenderSettings& settings);
  // And whether they also write the splats' depth out for the grid (the raster compositor's where the
  // device reads attachments in rasterization order).
  bool writes_depth_out(const RenderSettings& settings) const;

  // The composed picture, R16G16B16A16_SFLOAT in TRANSFER_SRC_OPTIMAL after draw(), for the blit.
  VkImage picture() const { return picture_.handle(); }
  static constexpr VkFormat kPictureFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
  static constexpr VkImageLayout kPictureLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }

  // The clip-from-world matrix the mesh is drawn with (column-major, Vulkan clip space, y down,
  // standard depth) and the depth convention of its projection.
  std::array<double, 16> projection(const Camera& camera) const;
  static std::array<double, 16> view_matrix(const Camera& camera);

 private:
  struct Vertex {
    float position[3];
    float colour[3];
  };
  void build_geometry(const Bounds& bounds);
  void create_render_passes();
  void create_pipelines();
  vk::UniquePipeline make_pipeline(VkShaderModule vertex, VkShaderModule fragment,
                                   VkPrimitiveTopology topology, bool mesh, VkRenderPass pass);
  void begin(VkCommandBuffer cmd);
  // Resets `fence` (when given) and submits `cmd`, after `wait` and signalling `signal` (either may be null).
  void submit(VkCommandBuffer cmd, VkSemaphore wait, VkSemaphore signal, VkFence fence);
  void wait_for(VkFence fence, bool& pending);

  // Declared in the order they are made, each after what it refers to: they are destroyed in the reverse one.
  const WindowDevice& device_;
  VkDevice vk_;
  uint32_t width_, height_;
  double near_, far_;  // the mesh's depth range, from the scene's size
  vk::Image picture_;  // the mesh's colour, then the splats over it and the grid
  vk::Image depth_;    // D32_SFLOAT: the box's depth, the splats' where dense, the grid's
  vk::Image splats_;   // what render_to_image writes: the splats' premultiplied RGBA over black
  vk::Buffer vertices_;
  uint32_t box_vertices_ = 0, grid_vertices_ = 0;
  vk::UniqueRenderPass box_pass_;   // clears colour and depth
  vk::UniqueRenderPass over_pass_;  // keeps them, ends with the picture ready to blit
  vk::UniqueFramebuffer framebuffer_;
  vk::UniqueSampler sampler_;
  vk::UniqueDescriptorSetLayout set_layout_;
  vk::UniqueDescriptorPool descriptor_pool_;
  VkDescriptorSet splats_set_ = VK_NULL_HANDLE;  // from descriptor_pool_, freed with it
  vk::UniquePipelineLayout mesh_layout_, over_layout_;
  vk::UniquePipeline box_pipeline_, grid_pipeline_, over_pipeline_;
  vk::UniqueCommandPool command_pool_;
  VkCommandBuffer box_commands_ = VK_NULL_HANDLE, grid_commands_ = VK_NULL_HANDLE;  // from command_pool_
  vk::UniqueSemaphore box_drawn_, splats_drawn_;
  vk::UniqueFence box_fence_, grid_fence_;
  bool box_pending_ = false, grid_pending_ = false;  // the fences have a submission to wait for
};

}  // namespace tilesplat::viewer
