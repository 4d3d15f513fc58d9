// Projection: 3D Gaussians -> screen-space splats (mean, conic, opacity, colour, depth, tile rect).
#pragma once

#include <compare>
#include <utility>
#include <vector>

#include "camera/camera_models.h"
#include "passes/key_buffers.h"
#include "passes/projection_variant.h"
#include "passes/tile_grid.h"
#include "shader_io.h"
#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"
#include "vulkan/pipeline_variants.h"

namespace tilesplat {

struct Camera;
struct Lighting;

// The scene's attributes on the GPU, as the loader produced them (raw log scales and logits).
struct SceneBuffers {
  vk::Buffer positions, log_scales, rotations, opacity_logits, sh;
  // Made from the above on the first frame of an accuracy mode that reads them (fp16 SH, fp16
  // covariance); never allocated otherwise.
  vk::Buffer sh_half, covariances_half;
  // Relighting's per-splat normals (3 floats each), uploaded on the first lit frame and never for a
  // scene that is not lit. Until then their host copy waits in pending_normals (see set_scene).
  vk::Buffer normals;
  std::vector<float> pending_normals;
  bool file_normals = false;  // the scene has a usable normal (finite, non-zero) somewhere
  uint32_t count = 0;
  int sh_degree = 0;
};

// Bytes of one projected splat record (SPLAT_VEC4S vec4, compute/shader_io.h).
constexpr uint32_t kSplatRecordBytes = shader_io::SPLAT_VEC4S * 16;

// Per-record outputs of the projection, inputs of the later passes: one record per Gaussian, two for
// the equirectangular camera (ProjectionVariant::seam_copies).
struct ProjectedBuffers {
  uint32_t records = 0;    // what the buffers hold
  vk::Buffer splats;       // kSplatRecordBytes per Gaussian
  vk::Buffer rects;        // uvec2 per Gaussian: packed tile rect
  vk::Buffer tile_counts;  // uint per Gaussian: tiles touched, 0 = culled
  vk::Buffer depth_offsets;  // uint per depth position: exclusive prefix sum of tile_counts in depth order
  vk::Buffer offsets;        // uint per Gaussian: where its (tile, Gaussian) pairs start (the same sums)
  KeyBuffers depth_order;  // the depth sort's pairs: view depth bits (culled: last), Gaussian index
  vk::Buffer ray_depth;    // RAY_DEPTH_VEC4S vec4 per Gaussian, only for per-pixel re-sorting
  vk::Buffer big_splats;   // uint per Gaussian: the splats whose keys key_emission_big.comp writes
};

// Bytes of one Gaussian's per-pixel re-sorting data (RAY_DEPTH_VEC4S, compute/shader_io.h).
constexpr uint32_t kRayDepthBytes = shader_io::RAY_DEPTH_VEC4S * 16;

// The camera block projection.comp reads (and projection_backward.comp, of the same frame).
shader_io::CameraParams camera_params(const Camera& camera, double near_plane, const TileGrid& tiles);

class ProjectionPass {
 public:
  explicit ProjectionPass(vk::Context& ctx);
  // Writes this frame's camera and its tiles (the image's, or a region's); must be called before
  // record(), outside the command buffer.
  void set_camera(const Camera& camera, double near_plane, const TileGrid& tiles);
  // Validates this frame's lights (tilesplat::validate) and, when there are any, writes them and
  // uploads the scene's pending normals (once per scene). Must be called before record(), outside the
  // command buffer; record() of a lit variant reads what the last call wrote.
  void set_lighting(const Lighting& lighting, SceneBuffers& scene);
  // Makes the half-precision copies the variant reads, once per scene (outside any command buffer).
  void prepare(SceneBuffers& scene, const ProjectionVariant& variant);
  void record(VkCommandBuffer cmd, const SceneBuffers& scene, ProjectedBuffers& out, VkDeviceAddress counters,
              const ProjectionVariant& variant);

 private:
  const vk::ComputePipeline& pipeline_for(const ProjectionVariant& variant, bool texel);
  vk::Context& ctx_;
  vk::Buffer camera_params_;
  vk::Buffer light_params_;  // LightParams of compute/projection.comp; grown to the most lights seen
  // Specialization constants per variant, and whether through texel buffers (projection_texel).
  vk::PipelineVariants<std::pair<ProjectionVariant, bool>> pipelines_;  // with the texel twin or not
  vk::ComputePipeline pack_sh_half_;
  vk::ComputePipeline pack_covariance_half_;
  bool texel_buffers_;  // CPU drivers with float64: projection_texel (vk::texel_buffers_wanted)
};

}  // namespace tilesplat
