#include "passes/projection_pass.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>

#include "camera/camera_models.h"
#include "lighting.h"
#include "tilesplat/camera.h"
#include "tilesplat/reference.h"

namespace tilesplat {

namespace {
// projection_texel's bindings: positions, log-scales, rotations, opacities and SH in; splat records,
// rects, tile counts, depth keys and depth values out; the camera in (its uvec2 words).
const std::vector<VkDescriptorType> kTexelBindings = {
    VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER,
    VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER,
    VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER,
    VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER,
    VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER,
    VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER};

// compute/shader_io.h: the pass's push constants and the blocks it writes (the camera, the lights).
using shader_io::CameraParams;
using shader_io::LightParams;
using shader_io::LightRecord;
using shader_io::ProjectionPush;
using PackShPush = shader_io::PackShHalfPush;
using PackCovariancePush = shader_io::PackCovarianceHalfPush;

// The words projection.comp reads the camera block by (camera_word) must be where C++ writes its fields.
static_assert(offsetof(CameraParams, clip) == shader_io::CAMERA_CLIP * 8);
static_assert(offsetof(CameraParams, tiles) == shader_io::CAMERA_TILES * 8);
static_assert(offsetof(CameraParams, distortion) == shader_io::CAMERA_DISTORTION * 8);

}  // namespace

ProjectionPass::ProjectionPass(vk::Context& ctx)
    : ctx_(ctx),
      camera_params_(ctx, sizeof(CameraParams), vk::MemoryUse::Upload, "camera params"),
      pack_sh_half_(ctx, "pack_sh_half", sizeof(PackShPush)),
      pack_covariance_half_(ctx, "pack_covariance_half", sizeof(PackCovariancePush)),
      texel_buffers_(vk::texel_buffers_wanted(ctx) && ctx.features().shader_float64) {}

shader_io::CameraParams camera_params(const Camera& camera, double near_plane, const TileGrid& tiles) {
  CameraParams p{};
  std::copy(camera.rotation.begin(), camera.rotation.end(), p.rotation);
  std::copy(camera.position.begin(), camera.position.end(), p.centre);
  p.focal_principal[0] = camera.fx;
  p.focal_principal[1] = camera.fy;
  p.focal_principal[2] = camera.cx;
  p.focal_principal[3] = camera.cy;
  const camera_models::ModelLimits& limits = camera_models::model_limits(camera);
  p.clip[0] = limits.clamp_x;
  p.clip[1] = limits.clamp_y;
  p.clip[2] = near_plane;
  p.clip[3] = limits.reach;
  std::copy(camera.distortion.begin(), camera.distortion.end(), p.distortion);
  p.tiles = {tiles.first_x, tiles.first_y, tiles.first_x + tiles.tiles_x, tiles.first_y + tiles.tiles_y};
  return p;
}

void ProjectionPass::set_camera(const Camera& camera, double near_plane, const TileGrid& tiles) {
  const CameraParams p = camera_params(camera, near_plane, tiles);
  vk::upload(ctx_, camera_params_, &p, sizeof(p));
}

void ProjectionPass::set_lighting(const Lighting& lighting, SceneBuffers& scene) {
  const PreparedLighting prepared = prepare_lighting(lighting);  // validates, lit or not
  if (!lighting.enabled()) return;
  if (!scene.pending_normals.empty()) {
    const VkDeviceSize normal_bytes = scene.pending_normals.size() * sizeof(float);
    scene.normals = vk::Buffer(ctx_, normal_bytes, vk::MemoryUse::Device, "normals");
    vk::upload(ctx_, scene.normals, scene.pending_normals.data(), normal_bytes);
    scene.pending_normals = {};  // the device copy is the scene's now: free the host one
  }
  const VkDeviceSize bytes = sizeof(LightParams) + prepared.lights.size() * sizeof(LightRecord);
  if (light_params_.size() < bytes) light_params_ = vk::Buffer(ctx_, bytes, vk::MemoryUse::Upload, "light params");
  std::vector<std::byte> data(bytes);
  LightParams header{};
  header.normals = scene.normals ? scene.normals.address() : 0;
  std::copy(prepared.ambient.begin(), prepared.ambient.end(), header.ambient);
  header.count = uint32_t(prepared.lights.size());
  std::memcpy(data.data(), &header, sizeof(header));
  for (size_t l = 0; l < prepared.lights.size(); ++l) {
    LightRecord record{};
    std::copy(prepared.lights[l].vector.begin(), prepared.lights[l].vector.end(), record.vector);
    std::copy(prepared.lights[l].radiance.begin(), prepared.lights[l].radiance.end(), record.radiance);
    record.point = prepared.lights[l].point ? 1 : 0;
    std::memcpy(data.data() + sizeof(header) + l * sizeof(LightRecord), &record, sizeof(record));
  }
  vk::upload(ctx_, light_params_, data.data(), bytes);
}

const vk::ComputePipeline& ProjectionPass::pipeline_for(const ProjectionVariant& v, bool texel) {
  return pipelines_.get(std::make_pair(v, texel), [&] {
    const uint32_t stored_coeffs = uint32_t((v.stored_sh_degree + 1) * (v.stored_sh_degree + 1));
    const std::vector<vk::SpecConstant> spec = {{0, uint32_t(v.sh_degree)},
                                                {1, stored_coeffs},
                                                {2, v.sh_half},
                                                {3, v.covariance_half},
                                                {4, v.opacity_extent},
                                                {5, v.square_tiles},
                                                {6, std::bit_cast<uint32_t>(v.alpha_inv)},
                                                {7, v.depth_key_bits},
                                                {8, v.ray_depth},
                                                {9, v.dilation_tenths},
                                                {10, v.compensate_opacity},
                                                {11, v.lighting},
                                                {12, v.file_normals},
                                                {13, v.camera_model},
                                                {14, v.distance_key}};
    const char* shader = texel                            ? "projection_texel"
                         : ctx_.features().shader_float64 ? "projection"
                                                          : "projection_fp32";
    return vk::ComputePipeline(ctx_, shader, sizeof(ProjectionPush), spec,
                               texel ? kTexelBindings : std::vector<VkDescriptorType>{});
  });
}

void ProjectionPass::prepare(SceneBuffers& scene, const ProjectionVariant& variant) {
  const bool pack_sh = variant.sh_half && !scene.sh_half;
  const bool pack_covariance = variant.covariance_half && !scene.covariances_half;
  if (!pack_sh && !pack_covariance) return;
  const uint32_t sh_values = uint32_t(scene.sh.size() / sizeof(float));
  if (pack_sh)
    scene.sh_half = vk::Buffer(ctx_, std::max<VkDeviceSize>(4, VkDeviceSize(vk::div_ceil(sh_values, 2)) * 4),
                               vk::MemoryUse::Device, "spherical harmonics (fp16)");
  if (pack_covariance)
    scene.covariances_half = vk::Buffer(ctx_, std::max<VkDeviceSize>(4, VkDeviceSize(scene.count) * 12),
                                        vk::MemoryUse::Device, "covariances (fp16)");
  ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
    if (pack_sh && sh_values > 0) {
      pack_sh_half_.bind(cmd, PackShPush{scene.sh.address(), scene.sh_half.address(), sh_values});
      pack_sh_half_.dispatch(cmd, std::min(vk::div_ceil(vk::div_ceil(sh_values, 2), 256),
                                           ctx_.limits().max_workgroup_count_x));  // it strides past them
    }
    if (pack_covariance && scene.count > 0) {
      pack_covariance_half_.bind(cmd,
                                 PackCovariancePush{scene.log_scales.address(), scene.rotations.address(),
                                                    scene.covariances_half.address(), scene.count});
      pack_covariance_half_.dispatch(cmd, vk::div_ceil(scene.count, 256));
    }
  });
}

void ProjectionPass::record(VkCommandBuffer cmd, const SceneBuffers& scene, ProjectedBuffers& out,
                            VkDeviceAddress counters, const ProjectionVariant& variant) {
  const vk::Buffer& sh = variant.sh_half ? scene.sh_half : scene.sh;
  ProjectionPush push{scene.positions.address(),
                      scene.log_scales.address(),
                      scene.rotations.address(),
                      scene.opacity_logits.address(),
                      sh.address(),
                      camera_params_.address(),
                      out.splats.address(),
                      out.rects.address(),
                      out.tile_counts.address(),
                      out.depth_order.keys.address(),
                      out.depth_order.values.address(),
                      counters,
                      variant.covariance_half ? scene.covariances_half.address() : 0,
                      variant.ray_depth ? out.ray_depth.address() : 0,
                      variant.lighting ? light_params_.address() : 0,
                      scene.count};
  // Texel views in binding order (projection.comp, TS_TEXEL_BUFFERS); none where a buffer has more
  // texels than the device allows, and then this frame takes the address path.
  std::vector<VkBufferView> views;
  if (texel_buffers_) {
    views = {scene.positions.texel_view(VK_FORMAT_R32_SFLOAT, 4),
             scene.log_scales.texel_view(VK_FORMAT_R32_SFLOAT, 4),
             scene.rotations.texel_view(VK_FORMAT_R32G32B32A32_SFLOAT, 16),
             scene.opacity_logits.texel_view(VK_FORMAT_R32_SFLOAT, 4),
             sh.texel_view(VK_FORMAT_R32_UINT, 4),
             out.splats.texel_view(VK_FORMAT_R32G32B32A32_SFLOAT, 16),
             out.rects.texel_view(VK_FORMAT_R32G32_UINT, 8),
             out.tile_counts.texel_view(VK_FORMAT_R32_UINT, 4),
             out.depth_order.keys.texel_view(VK_FORMAT_R32_UINT, 4),
             out.depth_order.values.texel_view(VK_FORMAT_R32_UINT, 4),
             camera_params_.texel_view(VK_FORMAT_R32G32_UINT, 8)};
    views = vk::complete_views(std::move(views));
  }
  const auto& pipeline = pipeline_for(variant, !views.empty());
  pipeline.bind(cmd, push);
  if (!views.empty()) pipeline.push_texel_views(cmd, views);
  pipeline.dispatch(cmd, vk::div_ceil(scene.count * variant.seam_copies(), 256));
}

}  // namespace tilesplat
