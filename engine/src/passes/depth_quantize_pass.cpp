#include "passes/depth_quantize_pass.h"

#include "shader_io.h"

namespace tilesplat {

namespace {
using shader_io::DepthQuantizePush;  // compute/shader_io.h
}  // namespace

DepthQuantizePass::DepthQuantizePass(vk::Context& ctx)
    : pipeline_(ctx, "depth_quantize", sizeof(DepthQuantizePush)) {}

void DepthQuantizePass::record(VkCommandBuffer cmd, ProjectedBuffers& projected, uint32_t gaussians,
                               VkDeviceAddress counters) {
  pipeline_.bind(cmd, DepthQuantizePush{projected.depth_order.keys.address(), counters, gaussians});
  pipeline_.dispatch(cmd, vk::div_ceil(gaussians, 256));
}

}  // namespace tilesplat
