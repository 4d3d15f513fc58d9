#include "passes/depth_quantize_pass.h"

namespace tilesplat {

namespace {
struct DepthQuantizePush {
  VkDeviceAddress depth_keys, counters;
  uint32_t count, pad;
};
}  // namespace

DepthQuantizePass::DepthQuantizePass(vk::Context& ctx)
    : pipeline_(ctx, "depth_quantize", sizeof(DepthQuantizePush)) {}

void DepthQuantizePass::record(VkCommandBuffer cmd, ProjectedBuffers& projected, uint32_t gaussians,
                               VkDeviceAddress counters) {
  pipeline_.bind(cmd, DepthQuantizePush{projected.depth_order.keys.address(), counters, gaussians, 0});
  pipeline_.dispatch(cmd, vk::div_ceil(gaussians, 256));
}

}  // namespace tilesplat
