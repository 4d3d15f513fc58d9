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
#include "window_device.h"

namespace tilesplat::viewer {

class MeshLayer {
 public:
  // Geometry sized to the scene's bounds; images of `width` x `height`.
  MeshLayer(const WindowDevice& device, const Bounds& bounds, uint32_t width, uint32_t height);
  ~MeshLayer();
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
  VkImage picture() const { return picture_.image; }
  static constexpr VkFormat kPictureFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
  static constexpr VkImageLayout kPictureLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }

  // The clip-from-world matrix the mesh is drawn with (column-major, Vulkan clip space, y down,
  // standard depth) and the depth convention of its projection.
  std::array<double, 16> projection(const Camera& camera) const;
  static std::array<double, 16> view_matrix(const Camera& camera);

 private:
  struct Image {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
  };
  struct Vertex {
    float position[3];
    float colour[3];
  };
  Image make_image(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect);
  void destroy_image(Image& image);
  void build_geometry(const Bounds& bounds);
  void create_render_passes();
  void create_pipelines();
  VkPipeline make_pipeline(VkShaderModule vertex, VkShaderModule fragment, VkPrimitiveTopology topology,
                           bool mesh, VkRenderPass pass);
  void begin(VkCommandBuffer cmd);
  // Resets `fence` (when given) and submits `cmd`, after `wait` and signalling `signal` (either may be null).
  void submit(VkCommandBuffer cmd, VkSemaphore wait, VkSemaphore signal, VkFence fence);
  void wait_for(VkFence fence, bool& pending);
  void destroy();

  const WindowDevice& device_;
  VkDevice vk_;
  uint32_t width_, height_;
  double near_, far_;  // the mesh's depth range, from the scene's size
  Image picture_;      // the mesh's colour, then the splats over it and the grid
  Image depth_;        // D32_SFLOAT: the box's depth, the splats' where dense, the grid's
  Image splats_;       // what render_to_image writes: the splats' premultiplied RGBA over black
  VkBuffer vertices_ = VK_NULL_HANDLE;
  VkDeviceMemory vertex_memory_ = VK_NULL_HANDLE;
  uint32_t box_vertices_ = 0, grid_vertices_ = 0;
  VkRenderPass box_pass_ = VK_NULL_HANDLE;   // clears colour and depth
  VkRenderPass over_pass_ = VK_NULL_HANDLE;  // keeps them, ends with the picture ready to blit
  VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
  VkSampler sampler_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
  VkDescriptorSet splats_set_ = VK_NULL_HANDLE;
  VkPipelineLayout mesh_layout_ = VK_NULL_HANDLE, over_layout_ = VK_NULL_HANDLE;
  VkPipeline box_pipeline_ = VK_NULL_HANDLE, grid_pipeline_ = VK_NULL_HANDLE, over_pipeline_ = VK_NULL_HANDLE;
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
  VkCommandBuffer box_commands_ = VK_NULL_HANDLE, grid_commands_ = VK_NULL_HANDLE;
  VkSemaphore box_drawn_ = VK_NULL_HANDLE, splats_drawn_ = VK_NULL_HANDLE;
  VkFence box_fence_ = VK_NULL_HANDLE, grid_fence_ = VK_NULL_HANDLE;
  bool box_pending_ = false, grid_pending_ = false;  // the fences have a submission to wait for
};

}  // namespace tilesplat::viewer
