// Projection: 3D Gaussians -> screen-space splats (mean, conic, opacity, colour, depth, tile rect).
#pragma once

#include <map>

#include "passes/key_buffers.h"
#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

struct Camera;

// The scene's attributes on the GPU, as the loader produced them (raw log scales and logits).
struct SceneBuffers {
  vk::Buffer positions, log_scales, rotations, opacity_logits, sh;
  uint32_t count = 0;
  int sh_degree = 0;
};

// Bytes of one projected splat record (SPLAT_VEC4S vec4 in compute/common.glsl).
constexpr uint32_t kSplatRecordBytes = 4 * 16;

// Per-Gaussian outputs of the projection, inputs of the later passes.
struct ProjectedBuffers {
  vk::Buffer splats;       // kSplatRecordBytes per Gaussian
  vk::Buffer rects;        // uvec2 per Gaussian: packed tile rect
  vk::Buffer tile_counts;  // uint per Gaussian: tiles touched, 0 = culled
  vk::Buffer depth_offsets;  // uint per depth position: exclusive prefix sum of tile_counts in depth order
  vk::Buffer offsets;        // uint per Gaussian: where its (tile, Gaussian) pairs start (the same sums)
  KeyBuffers depth_order;  // the depth sort's pairs: view depth bits (culled: last), Gaussian index
};

class ProjectionPass {
 public:
  explicit ProjectionPass(vk::Context& ctx);
  // Writes this frame's camera; must be called before record(), outside the command buffer.
  void set_camera(const Camera& camera);
  void record(VkCommandBuffer cmd, const SceneBuffers& scene, ProjectedBuffers& out, VkDeviceAddress counters);

 private:
  const vk::ComputePipeline& pipeline_for(int sh_degree);
  vk::Context& ctx_;
  vk::Buffer camera_params_;
  std::map<int, vk::ComputePipeline> pipelines_;  // one per SH degree (specialization constant)
};

}  // namespace tilesplat
