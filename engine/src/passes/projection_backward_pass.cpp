#include "passes/projection_backward_pass.h"

#include "shader_io.h"

namespace tilesplat {

using shader_io::ProjectionBackwardPush;

ProjectionBackwardPass::ProjectionBackwardPass(vk::Context& ctx)
    : ctx_(ctx),
      camera_params_(ctx, sizeof(shader_io::CameraParams), vk::MemoryUse::Upload, "backward camera params") {}

void ProjectionBackwardPass::set_camera(const Camera& camera, double near_plane, const TileGrid& tiles) {
  const shader_io::CameraParams params = camera_params(camera, near_plane, tiles);
  vk::upload(ctx_, camera_params_, &params, sizeof(params));
}

void ProjectionBackwardPass::record(VkCommandBuffer cmd, const SceneBuffers& scene,
                                    const ProjectedBuffers& projected, const vk::Buffer& splat_gradients,
                                    Antialiasing antialiasing, vk::Buffer& gradients, vk::Buffer& counters) {
  const Variant variant{scene.sh_degree, antialiasing};
  const vk::ComputePipeline& pipeline = pipelines_.get(variant, [&] {
    const uint32_t coefficients = uint32_t((scene.sh_degree + 1) * (scene.sh_degree + 1));
    return vk::ComputePipeline(
        ctx_, ctx_.features().shader_float64 ? "projection_backward" : "projection_backward_fp32",
        sizeof(ProjectionBackwardPush),
        {{0, uint32_t(scene.sh_degree)},
         {1, coefficients},
         {2, antialiasing == Antialiasing::kMip ? 1u : 3u},
         {3, antialiasing == Antialiasing::kClassic ? 0u : 1u}});
  });
  ProjectionBackwardPush push{};
  push.positions = scene.positions.address();
  push.log_scales = scene.log_scales.address();
  push.rotations = scene.rotations.address();
  push.opacity_logits = scene.opacity_logits.address();
  push.sh = scene.sh.address();
  push.camera = camera_params_.address();
  push.tile_counts = projected.tile_counts.address();
  push.splat_gradients = splat_gradients.address();
  push.gradients = gradients.address();
  push.counters = counters.address();
  push.count = scene.count;
  pipeline.bind(cmd, push);
  pipeline.dispatch(cmd, vk::div_ceil(scene.count, 256));
}

}  // namespace tilesplat
