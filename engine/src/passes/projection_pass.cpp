#include "passes/projection_pass.h"

#include <algorithm>
#include <cmath>

#include "tilesplat/camera.h"
#include "tilesplat/reference.h"

namespace tilesplat {

namespace {

// Mirrors CameraParams in compute/projection.comp.
struct CameraParams {
  double rotation[9];  // world to camera, row-major
  double centre[3];
  double focal_principal[4];
  float clip[4];
  uint32_t grid[4];
};
static_assert(sizeof(CameraParams) == 160);

struct ProjectionPush {
  VkDeviceAddress positions, log_scales, rotations, opacity_logits, sh, camera;
  VkDeviceAddress splats, rects, tile_counts, depth_keys, depth_values, counters;
  uint32_t count;
  uint32_t pad;
};

constexpr double kNearPlane = 0.2;

}  // namespace

ProjectionPass::ProjectionPass(vk::Context& ctx)
    : ctx_(ctx), camera_params_(ctx, sizeof(CameraParams), vk::MemoryUse::Upload, "camera params") {}

void ProjectionPass::set_camera(const Camera& camera) {
  CameraParams p{};
  std::copy(camera.rotation.begin(), camera.rotation.end(), p.rotation);
  std::copy(camera.position.begin(), camera.position.end(), p.centre);
  p.focal_principal[0] = camera.fx;
  p.focal_principal[1] = camera.fy;
  p.focal_principal[2] = camera.cx;
  p.focal_principal[3] = camera.cy;
  p.clip[0] = float(1.3 * camera.tan_half_fov_x());
  p.clip[1] = float(1.3 * camera.tan_half_fov_y());
  p.clip[2] = float(kNearPlane);
  p.grid[0] = uint32_t((camera.width + kTileSize - 1) / kTileSize);
  p.grid[1] = uint32_t((camera.height + kTileSize - 1) / kTileSize);
  p.grid[2] = uint32_t(camera.width);
  p.grid[3] = uint32_t(camera.height);
  vk::upload(ctx_, camera_params_, &p, sizeof(p));
}

const vk::ComputePipeline& ProjectionPass::pipeline_for(int sh_degree) {
  auto it = pipelines_.find(sh_degree);
  if (it == pipelines_.end())
    it = pipelines_
             .emplace(sh_degree, vk::ComputePipeline(ctx_, ctx_.features().shader_float64 ? "projection"
                                                                                           : "projection_fp32",
                                                     sizeof(ProjectionPush),
                                                     {{0, uint32_t(sh_degree)}}))
             .first;
  return it->second;
}

void ProjectionPass::record(VkCommandBuffer cmd, const SceneBuffers& scene, ProjectedBuffers& out,
                            VkDeviceAddress counters) {
  ProjectionPush push{scene.positions.address(), scene.log_scales.address(), scene.rotations.address(),
                      scene.opacity_logits.address(), scene.sh.address(), camera_params_.address(),
                      out.splats.address(), out.rects.address(), out.tile_counts.address(),
                      out.depth_order.keys.address(), out.depth_order.values.address(), counters,
                      scene.count, 0};
  const auto& pipeline = pipeline_for(scene.sh_degree);
  pipeline.bind(cmd, push);
  pipeline.dispatch(cmd, vk::div_ceil(scene.count, 256));
}

}  // namespace tilesplat
