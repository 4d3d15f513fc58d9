#include "passes/composite_pass.h"

#include <bit>
#include <algorithm>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

#include "passes/tile_coverage.h"
#include "shader_io.h"
#include "tilesplat/reference.h"

namespace tilesplat {

namespace {
using shader_io::CompositePush;  // composite.comp's push constants
static_assert(sizeof(CompositePush) <= 128, "Vulkan guarantees 128 bytes of push constants");
}  // namespace

CompositePass::CompositePass(vk::Context& ctx) : layout_(ctx, "composite") {}

void CompositePass::record(VkCommandBuffer cmd, const CompositeInputs& in, const Chunks& chunks,
                           const HostSurface& host, const Carry& carry) {
  OutputBuffers& out = in.out;
  const std::vector<VkBufferView> views = layout_.texel_views(in);
  Variant variant;
  variant.layout = {in.write_depth, in.write_count, in.cutoffs.alpha, !views.empty()};
  variant.transmittance = in.cutoffs.transmittance;
  variant.max_alpha = in.cutoffs.max_alpha;
  variant.host_depth_in = host.view_depth != nullptr;
  variant.surface_depth_out = host.surface_depth != nullptr;
  variant.exact_depth_order = variant.host_depth_in && host.exact_depth_order;
  variant.chunked = chunks.count > 1 || carry.any();
  const vk::ComputePipeline& pipeline = pipelines_.get(variant, [&] {
    return layout_.make_pipeline("composite", sizeof(CompositePush), variant.layout,
                                 {{6, std::bit_cast<uint32_t>(variant.transmittance)},
                                  {7, variant.host_depth_in ? 1u : 0u},
                                  {8, variant.surface_depth_out ? 1u : 0u},
                                  {9, variant.exact_depth_order ? 1u : 0u},
                                  {10, variant.chunked ? 1u : 0u},
                                  {11, std::bit_cast<uint32_t>(variant.max_alpha)}});
  });
  const uint32_t tiles_x = vk::div_ceil(out.width, kTileSize);
  const uint32_t tiles_y = vk::div_ceil(out.height, kTileSize);
  const VkDeviceSize needed = carry.any()        ? part_state_bytes(out.width, out.height)
                              : chunks.count > 1 ? state_bytes(out.width, out.height)
                                                 : 0;
  if (chunks.state.size() < needed)
    throw std::logic_error("composite: the chunk state buffer is smaller than the image");
  const uint32_t carry_flags = (carry.in ? shader_io::COMPOSITE_CARRY_IN : 0u) |
                               (carry.out ? shader_io::COMPOSITE_CARRY_OUT : 0u) |
                               (carry.state_high ? shader_io::COMPOSITE_STATE_HIGH : 0u);
  for (uint32_t chunk = 0; chunk < chunks.count; ++chunk) {
    if (chunk > 0) vk::barrier(cmd);
    const uint32_t flags = carry_flags | (chunk + 1 == chunks.count ? shader_io::COMPOSITE_LAST_CHUNK : 0u);
    CompositePush push{in.splats.address(),
                       in.tile_lists.address(),
                       in.ranges.address(),
                       out.rgba.address(),
                       in.write_depth ? out.depth.address() : 0,
                       in.write_count ? out.count.address() : 0,
                       needed > 0 ? chunks.state.address() : 0,
                       chunks.counters,
                       variant.host_depth_in ? host.view_depth->address() : 0,
                       variant.surface_depth_out ? host.surface_depth->address() : 0,
                       {in.background[0], in.background[1], in.background[2], 0.0f},
                       out.width,
                       out.height,
                       tiles_x,
                       chunk * layout_.chunk_splats(),
                       layout_.chunk_splats(),
                       flags,
                       host.surface_alpha,
                       out.first_tile};
    pipeline.bind(cmd, push);
    if (!views.empty()) pipeline.push_texel_views(cmd, views);
    pipeline.dispatch(cmd, tiles_x, tiles_y);
  }
}

uint32_t CompositePass::chunks_for(uint64_t longest_tile_list) const {
  return layout_.chunks_for(longest_tile_list);
}

}  // namespace tilesplat
