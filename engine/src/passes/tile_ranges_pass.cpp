#include "passes/tile_ranges_pass.h"

#include <vector>

#include "shader_io.h"

namespace tilesplat {

namespace {
using RangesPush = shader_io::TileRangesPush;  // compute/shader_io.h
// tile_ranges_texel's bindings: the sorted keys and the frame's counters.
const std::vector<VkDescriptorType> kTexelBindings = {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER,
                                                      VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER};
}  // namespace

TileRangesPass::TileRangesPass(vk::Context& ctx) : texel_buffers_(vk::texel_buffers_wanted(ctx)) {
  for (uint32_t wide : {0u, 1u}) {
    pipeline_[wide] = vk::ComputePipeline(ctx, "tile_ranges", sizeof(RangesPush), {{0, wide}});
    if (texel_buffers_)
      texel_pipeline_[wide] =
          vk::ComputePipeline(ctx, "tile_ranges_texel", sizeof(RangesPush), {{0, wide}}, kTexelBindings);
  }
}

void TileRangesPass::record(VkCommandBuffer cmd, const vk::Buffer& sorted_keys, bool wide_keys, vk::Buffer& ranges,
                            const vk::Buffer& counters, VkDeviceSize ranges_args_offset, uint32_t tiles) {
  // Texel views; none where a buffer has more texels than the device allows (then the address path).
  std::vector<VkBufferView> views;
  if (texel_buffers_) {
    views = vk::complete_views(
        {sorted_keys.texel_view(wide_keys ? VK_FORMAT_R32G32_UINT : VK_FORMAT_R32_UINT, wide_keys ? 8 : 4),
         counters.texel_view(VK_FORMAT_R32_UINT, 4)});
  }
  const vk::ComputePipeline& pipeline = (views.empty() ? pipeline_ : texel_pipeline_)[wide_keys ? 1 : 0];
  pipeline.bind(cmd, RangesPush{sorted_keys.address(), ranges.address(), counters.address(), tiles});
  if (!views.empty()) pipeline.push_texel_views(cmd, views);
  pipeline.dispatch_indirect(cmd, counters.handle(), ranges_args_offset);
}

}  // namespace tilesplat
