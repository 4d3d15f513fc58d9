#include "passes/tile_composite_layout.h"

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <utility>

#include "passes/tile_coverage.h"
#include "tilesplat/reference.h"

namespace tilesplat {

namespace {

// llvmpipe ends any shader invocation after 65535 loop iterations in all (LP_MAX_TGSI_LOOP_ITERATIONS),
// silently. A 16-pixel column spends at most ~800 per batch of 256 splats (staging, listing, two
// bands; composite_stochastic.comp has the same loops), so 8192 splats (32 batches, ~26k iterations)
// leave a wide margin.
constexpr uint32_t kCpuDriverChunkSplats = 8192;

// The texel twins bind the splat records and the tiles' list in, and colour, depth and count out.
const std::vector<VkDescriptorType>& texel_bindings() {
  static const std::vector<VkDescriptorType> types = {
      VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER,
      VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER,
      VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER};
  return types;
}

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

std::vector<vk::SpecConstant> composite_spec_constants(bool write_depth, bool write_count,
                                                       uint32_t pixels_per_invocation, float alpha_cutoff) {
  return {{0, write_depth ? 1u : 0u},
          {1, write_count ? 1u : 0u},
          {2, pixels_per_invocation},
          {3, kTileSize / pixels_per_invocation},
          {4, std::bit_cast<uint32_t>(alpha_cutoff)},
          {5, std::bit_cast<uint32_t>(coverage_alpha_inv(alpha_cutoff))}};
}

TileCompositeLayout::TileCompositeLayout(vk::Context& ctx, const std::string& pass)
    : ctx_(ctx),
      pixels_per_invocation_(composite_pixels_per_invocation(ctx)),
      chunk_splats_(ctx.is_cpu_device() ? kCpuDriverChunkSplats : std::numeric_limits<uint32_t>::max()),
      texel_buffers_(pixels_per_invocation_ > 1 && vk::texel_buffers_wanted(ctx)) {
  if (texel_buffers_) unused_output_ = vk::Buffer(ctx, 16, vk::MemoryUse::Device, pass + " unused output");
}

uint32_t TileCompositeLayout::chunks_for(uint64_t longest_tile_list) const {
  return uint32_t(std::max<uint64_t>(1, (longest_tile_list + chunk_splats_ - 1) / chunk_splats_));
}

std::vector<VkBufferView> TileCompositeLayout::texel_views(const CompositeInputs& in) const {
  if (!texel_buffers_) return {};
  const OutputBuffers& out = in.out;
  return vk::complete_views(
      {in.splats.texel_view(VK_FORMAT_R32G32B32A32_SFLOAT, 16),
       in.tile_lists.texel_view(VK_FORMAT_R32_UINT, 4),
       out.rgba.texel_view(VK_FORMAT_R32G32B32A32_SFLOAT, 16),
       (in.write_depth ? out.depth : unused_output_).texel_view(VK_FORMAT_R32_SFLOAT, 4),
       (in.write_count ? out.count : unused_output_).texel_view(VK_FORMAT_R32_UINT, 4)});
}

vk::ComputePipeline TileCompositeLayout::make_pipeline(const std::string& shader,
                                                       uint32_t push_constant_bytes, const Variant& variant,
                                                       std::vector<vk::SpecConstant> more) const {
  std::vector<vk::SpecConstant> spec = composite_spec_constants(variant.write_depth, variant.write_count,
                                                                pixels_per_invocation_, variant.alpha_cutoff);
  spec.insert(spec.end(), more.begin(), more.end());
  return vk::ComputePipeline(ctx_, variant.texel_buffers ? shader + "_texel" : shader, push_constant_bytes,
                             spec,
                             variant.texel_buffers ? texel_bindings() : std::vector<VkDescriptorType>{});
}

}  // namespace tilesplat
