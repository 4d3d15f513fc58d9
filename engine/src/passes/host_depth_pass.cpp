#include "passes/host_depth_pass.h"

#include <bit>

#include "shader_io.h"

namespace tilesplat {

namespace {
using shader_io::HostDepthPush;  // compute/shader_io.h

void split_bits(double value, shader_io::uvec2& bits) {
  const uint64_t all = std::bit_cast<uint64_t>(value);
  bits.x = uint32_t(all);  // packDouble2x32 takes the low word first
  bits.y = uint32_t(all >> 32);
}
}  // namespace

void HostDepthPass::record_view_depths(VkCommandBuffer cmd, const DepthConvention& convention,
                                       const vk::Buffer& window, const vk::Buffer& view, uint32_t width,
                                       uint32_t height) {
  record(cmd, 0, convention, window, view, width, height);
}

void HostDepthPass::record_window_depths(VkCommandBuffer cmd, const DepthConvention& convention,
                                         const vk::Buffer& surface, const vk::Buffer& window, uint32_t width,
                                         uint32_t height) {
  record(cmd, 1, convention, window, surface, width, height);
}

void HostDepthPass::record(VkCommandBuffer cmd, uint32_t direction, const DepthConvention& convention,
                           const vk::Buffer& window, const vk::Buffer& view, uint32_t width,
                           uint32_t height) {
  const vk::ComputePipeline& pipeline = pipelines_.get(direction, [&] {
    const char* shader = ctx_.features().shader_float64 ? "host_depth" : "host_depth_fp32";
    return vk::ComputePipeline(ctx_, shader, sizeof(HostDepthPush), {{0, direction}});
  });
  HostDepthPush push{window.address(),    view.address(),      {},    {},
                     float(convention.a), float(convention.b), width, height};
  split_bits(convention.a, push.a_bits);
  split_bits(convention.b, push.b_bits);
  pipeline.bind(cmd, push);
  pipeline.dispatch(cmd, vk::div_ceil(width, 16), vk::div_ceil(height, 16));
}

}  // namespace tilesplat
