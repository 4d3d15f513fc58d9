#include "passes/sample_accumulate_pass.h"

#include "shader_io.h"

namespace tilesplat {

void SampleAccumulatePass::record(VkCommandBuffer cmd, const OutputBuffers& out, const vk::Buffer& sums,
                                  const vk::Buffer& counters, const Frame& frame) {
  using shader_io::SampleAccumulatePush;  // compute/shader_io.h
  if (!pipeline_) pipeline_.emplace(ctx_, "sample_accumulate", uint32_t(sizeof(SampleAccumulatePush)));
  const uint32_t pixels = out.width * out.height;
  pipeline_->bind(cmd, SampleAccumulatePush{out.rgba.address(), frame.write_depth ? out.depth.address() : 0,
                                           frame.write_count ? out.count.address() : 0, sums.address(),
                                           counters.address(), pixels,
                                           frame.samples_before, frame.write_depth, frame.write_count,
                                           frame.opaque});
  pipeline_->dispatch(cmd, vk::div_ceil(pixels, 256), 1);
}

}  // namespace tilesplat
