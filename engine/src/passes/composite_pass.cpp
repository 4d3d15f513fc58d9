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

// llvmpipe ends any shader invocation after 65535 loop iterations in all (LP_MAX_TGSI_LOOP_ITERATIONS),
// silently. A 16-pixel column spends at most ~800 per batch of 256 splats (staging, listing, two
// bands; composite_stochastic.comp has the same loops), so 8192 splats (32 batches, ~26k iterations)
// leave a wide margin.
constexpr uint32_t kCpuDriverChunkSplats = 8192;

}  // namespace

// On CPU drivers every shared-memory read is a scalar load per SIMD lane: there one invocation
// blends a 16-pixel column so that each staged splat is read once per 16 pixels. GPUs want one
// invocation per pixel.
// TILESPLAT_COMPOSITE_PIXELS (1, 2, 4, 8 or 16) overrides the choice, so that the tests run the
// GPU layout on lavapipe too.
uint32_t composite_pixels_per_invocation(const vk::Context& ctx) {
  if (const char* env = std::getenv("TILESPLAT_COMPOSITE_PIXELS"); env && *env) {
    const std::string value = env;
    if (value != "1" && value != "2" && value != "4" && value != "8" && value != "16")
      throw std::invalid_argument("TILESPLAT_COMPOSITE_PIXELS must be 1, 2, 4, 8 or 16, got '" + value + "'");
    return uint32_t(std::stoul(value));
  }
  return ctx.is_cpu_device() ? kTileSize : 1;
}

const std::vector<VkDescriptorType>& composite_texel_bindings() {
  static const std::vector<VkDescriptorType> types = {
      VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER,
      VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER,
      VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER};
  return types;
}

std::vector<VkBufferView> composite_texel_views(const vk::Buffer& splats, const vk::Buffer& list,
                                                const OutputBuffers& out, bool write_depth, bool write_count,
                                                const vk::Buffer& unused) {
  return vk::complete_views({splats.texel_view(VK_FORMAT_R32G32B32A32_SFLOAT, 16),
                             list.texel_view(VK_FORMAT_R32_UINT, 4),
                             out.rgba.texel_view(VK_FORMAT_R32G32B32A32_SFLOAT, 16),
                             (write_depth ? out.depth : unused).texel_view(VK_FORMAT_R32_SFLOAT, 4),
                             (write_count ? out.count : unused).texel_view(VK_FORMAT_R32_UINT, 4)});
}

uint32_t composite_chunk_splats(const vk::Context& ctx) {
  return ctx.is_cpu_device() ? kCpuDriverChunkSplats : std::numeric_limits<uint32_t>::max();
}

CompositePass::CompositePass(vk::Context& ctx)
    : ctx_(ctx),
      pixels_per_invocation_(composite_pixels_per_invocation(ctx)),
      chunk_splats_(composite_chunk_splats(ctx)),
      texel_buffers_(pixels_per_invocation_ > 1 && vk::texel_buffers_wanted(ctx)) {
  if (texel_buffers_) unused_output_ = vk::Buffer(ctx, 16, vk::MemoryUse::Device, "composite unused output");
}

void CompositePass::record(VkCommandBuffer cmd, const CompositeInputs& in, const Chunks& chunks,
                           const HostSurface& host, const Carry& carry) {
  OutputBuffers& out = in.out;
  const std::vector<VkBufferView> views =
      texel_buffers_ ? composite_texel_views(in.splats, in.tile_lists, out, in.write_depth, in.write_count,
                                             unused_output_)
                     : std::vector<VkBufferView>{};
  Variant variant;
  variant.write_depth = in.write_depth;
  variant.write_count = in.write_count;
  variant.cutoffs = in.cutoffs;
  variant.host_depth_in = host.view_depth != nullptr;
  variant.surface_depth_out = host.surface_depth != nullptr;
  variant.exact_depth_order = variant.host_depth_in && host.exact_depth_order;
  variant.texel_buffers = !views.empty();
  variant.chunked = chunks.count > 1 || carry.any();
  auto it = pipelines_.find(variant);
  if (it == pipelines_.end()) {
    const float alpha_inv = coverage_alpha_inv(variant.cutoffs.alpha);
    it = pipelines_
             .emplace(
                 variant,
                 vk::ComputePipeline(
                     ctx_, variant.texel_buffers ? "composite_texel" : "composite", sizeof(CompositePush),
                     {{0, variant.write_depth ? 1u : 0u},
                      {1, variant.write_count ? 1u : 0u},
                      {2, pixels_per_invocation_},
                      {3, kTileSize / pixels_per_invocation_},
                      {4, std::bit_cast<uint32_t>(variant.cutoffs.alpha)},
                      {5, std::bit_cast<uint32_t>(alpha_inv)},
                      {6, std::bit_cast<uint32_t>(variant.cutoffs.transmittance)},
                      {7, variant.host_depth_in ? 1u : 0u},
                      {8, variant.surface_depth_out ? 1u : 0u},
                      {9, variant.exact_depth_order ? 1u : 0u},
                      {10, variant.chunked ? 1u : 0u},
                      {11, std::bit_cast<uint32_t>(variant.cutoffs.max_alpha)}},
                     variant.texel_buffers ? composite_texel_bindings() : std::vector<VkDescriptorType>{}))
             .first;
  }
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
                       chunk * chunk_splats_,
                       chunk_splats_,
                       flags,
                       host.surface_alpha,
                       out.first_tile};
    it->second.bind(cmd, push);
    if (variant.texel_buffers) it->second.push_texel_views(cmd, views);
    it->second.dispatch(cmd, tiles_x, tiles_y);
  }
}

uint32_t composite_chunks_needed(uint64_t longest_tile_list, uint32_t chunk_splats) {
  return uint32_t(std::max<uint64_t>(1, (longest_tile_list + chunk_splats - 1) / chunk_splats));
}

uint32_t CompositePass::chunks_for(uint64_t longest_tile_list) const {
  return composite_chunks_needed(longest_tile_list, chunk_splats_);
}

}  // namespace tilesplat
