#include "backward/frame_backward.h"

#include <algorithm>
#include <cstring>

#include "shader_io.h"
#include "vulkan/readback.h"

namespace tilesplat {
namespace {

void fill_zero(VkCommandBuffer cmd, const vk::Buffer& buffer, VkDeviceSize bytes) {
  vkCmdFillBuffer(cmd, buffer.handle(), 0, (bytes + 3) / 4 * 4, 0);
}

// The floats projection_backward.comp writes per Gaussian: positions 3, log scales 3, rotations 4, logit 1,
// SH 3 K, means2d 2, |means2d| 2.
uint64_t scene_gradient_floats(const BackwardPlan& plan) {
  const uint64_t coefficients = uint64_t((plan.sh_degree + 1) * (plan.sh_degree + 1));
  return (15 + 3 * coefficients) * plan.gaussians;
}

}  // namespace

FrameBackward::FrameBackward(vk::Context& ctx, vk::GpuTimer& timer)
    : ctx_(ctx), timer_(timer), composite_(ctx), projection_(ctx) {}

void FrameBackward::reserve(vk::Buffer& buffer, uint64_t bytes, const char* name) {
  bytes = std::max<uint64_t>(bytes, 16);
  if (buffer.handle() != VK_NULL_HANDLE && buffer.size() >= bytes) return;
  buffer = vk::Buffer(ctx_, bytes, vk::MemoryUse::Device, name);
}

void FrameBackward::upload_pixel_gradients(const FrameGradients& gradients, size_t pixels) {
  std::vector<float> rgba(4 * pixels, 0.0f), depths(2 * pixels, 0.0f);
  for (size_t p = 0; p < pixels; ++p) {
    if (!gradients.rgb.empty()) std::copy_n(&gradients.rgb[3 * p], 3, &rgba[4 * p]);
    if (!gradients.alpha.empty()) rgba[4 * p + 3] = gradients.alpha[p];
    if (!gradients.expected_depth.empty()) depths[2 * p] = gradients.expected_depth[p];
    if (!gradients.accumulated_depth.empty()) depths[2 * p + 1] = gradients.accumulated_depth[p];
  }
  reserve(pixel_rgba_, rgba.size() * sizeof(float), "pixel gradients (rgba)");
  reserve(pixel_depth_, depths.size() * sizeof(float), "pixel gradients (depths)");
  vk::upload(ctx_, pixel_rgba_, rgba.data(), rgba.size() * sizeof(float));
  vk::upload(ctx_, pixel_depth_, depths.data(), depths.size() * sizeof(float));
}

SceneGradients FrameBackward::run(const BackwardPlan& plan, const Camera& camera, double near_plane,
                                  const FrameResources& resources, const FrameGradients& gradients,
                                  std::vector<PassTiming>& passes) {
  const size_t pixels = size_t(plan.tiles.width) * plan.tiles.height;
  upload_pixel_gradients(gradients, pixels);
  const uint64_t splat_bytes = uint64_t(plan.gaussians) * shader_io::SPLAT_GRADIENT_FLOATS * sizeof(float);
  const uint64_t scene_bytes = scene_gradient_floats(plan) * sizeof(float);
  reserve(splat_gradients_, splat_bytes, "splat gradients");
  reserve(scene_gradients_, scene_bytes, "scene gradients");
  reserve(counters_, 16, "backward counters");
  projection_.set_camera(camera, near_plane, plan.tiles);

  const vk::Buffer& lists = resources.lists_in_alt ? resources.keys.values_alt : resources.keys.values;
  ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
    timer_.begin_frame(cmd);
    for (BackwardPass pass : plan.passes) {
      switch (pass) {
        case BackwardPass::kClearGradients:
          fill_zero(cmd, splat_gradients_, splat_bytes);
          fill_zero(cmd, scene_gradients_, scene_bytes);
          fill_zero(cmd, counters_, 16);
          break;
        case BackwardPass::kCompositeBackward:
          composite_.record(cmd,
                            {resources.projected.splats, lists, resources.ranges, pixel_rgba_, pixel_depth_,
                             plan.background, plan.tiles, plan.max_alpha},
                            splat_gradients_);
          break;
        case BackwardPass::kProjectionBackward:
          projection_.record(cmd, resources.scene, resources.projected, splat_gradients_, plan.antialiasing,
                             scene_gradients_, counters_);
          break;
      }
      vk::barrier(cmd);
      if (const char* name = timed_name(pass)) timer_.mark(cmd, name);
    }
  });
  double ms = 0;
  for (const auto& section : timer_.read(&ms)) passes.push_back({section.name, section.ms});

  std::vector<float> all;
  vk::read_buffer(ctx_, scene_gradients_, all, scene_gradient_floats(plan));
  std::vector<uint32_t> counters;
  vk::read_buffer(ctx_, counters_, counters, 1);
  const size_t n = plan.gaussians;
  const size_t sh_floats = 3 * size_t((plan.sh_degree + 1) * (plan.sh_degree + 1)) * n;
  SceneGradients out;
  auto take = [&](std::vector<float>& into, size_t begin, size_t count) {
    into.assign(all.begin() + std::ptrdiff_t(begin), all.begin() + std::ptrdiff_t(begin + count));
  };
  take(out.positions, 0, 3 * n);
  take(out.log_scales, 3 * n, 3 * n);
  take(out.rotations, 6 * n, 4 * n);
  take(out.opacity_logits, 10 * n, n);
  take(out.sh, 11 * n, sh_floats);
  take(out.means2d, 11 * n + sh_floats, 2 * n);
  take(out.means2d_abs, 13 * n + sh_floats, 2 * n);
  out.unformed = counters[shader_io::BACKWARD_COUNTER_UNFORMED];
  return out;
}

uint64_t FrameBackward::device_bytes() const {
  return pixel_rgba_.size() + pixel_depth_.size() + splat_gradients_.size() + scene_gradients_.size() +
         counters_.size();
}

}  // namespace tilesplat
