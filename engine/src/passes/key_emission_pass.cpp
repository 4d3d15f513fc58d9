#include "passes/key_emission_pass.h"

#include <bit>
#include <utility>
#include <vector>

#include "passes/frame_counters.h"

namespace tilesplat {

namespace {
using SetupPush = shader_io::FrameSetupPush;        // compute/shader_io.h
using ScatterPush = shader_io::ScatterOffsetsPush;  // compute/shader_io.h
// key_emission_texel's bindings: splat records, rects, tile counts and offsets in; narrow keys, wide
// keys and values out.
const std::vector<VkDescriptorType> kTexelBindings = {
    VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER,
    VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER,
    VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER,
    VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER};

// key_emission.comp and key_emission_big.comp.
using EmitPush = shader_io::KeyEmissionPush;  // compute/shader_io.h
}  // namespace

KeyEmissionPass::KeyEmissionPass(vk::Context& ctx)
    : ctx_(ctx),
      frame_setup_(ctx, "frame_setup", sizeof(SetupPush)),
      scatter_offsets_(ctx, "scatter_offsets", sizeof(ScatterPush)),
      texel_buffers_(vk::texel_buffers_wanted(ctx)) {
  if (!texel_buffers_) return;
  unused_keys_ = vk::Buffer(ctx, 16, vk::MemoryUse::Device, "key emission unused key view");
  scatter_offsets_texel_ =
      vk::ComputePipeline(ctx, "scatter_offsets_texel", sizeof(ScatterPush), {},
                          {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER,
                           VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER});
}

void KeyEmissionPass::record(VkCommandBuffer cmd, const ProjectedBuffers& projected,
                             const vk::Buffer* depth_order, KeyBuffers& keys, uint32_t gaussians,
                             const TileGrid& tiles, const vk::Buffer& counters_buffer, bool square_tiles,
                             float alpha_inv) {
  const VkDeviceAddress counters = counters_buffer.address();
  frame_setup_.bind(cmd, SetupPush{counters, keys.capacity});
  frame_setup_.dispatch(cmd, 1);
  if (depth_order) {
    std::vector<VkBufferView> views;
    if (texel_buffers_) {
      views = {depth_order->texel_view(VK_FORMAT_R32_UINT, 4),
               projected.depth_offsets.texel_view(VK_FORMAT_R32_UINT, 4),
               projected.offsets.texel_view(VK_FORMAT_R32_UINT, 4)};
      views = vk::complete_views(std::move(views));
    }
    const vk::ComputePipeline& scatter = views.empty() ? scatter_offsets_ : scatter_offsets_texel_;
    scatter.bind(cmd, ScatterPush{depth_order->address(), projected.depth_offsets.address(),
                                  projected.offsets.address(), gaussians});
    if (!views.empty()) scatter.push_texel_views(cmd, views);
    scatter.dispatch(cmd, vk::div_ceil(gaussians, 256));
  }
  vk::barrier(cmd);
  // Texel views in binding order (key_emission.comp, TS_TEXEL_BUFFERS); none where a buffer has more
  // texels than the device allows, and then this frame takes the address path.
  std::vector<VkBufferView> views;
  if (texel_buffers_) {
    const bool wide = keys.wide_keys;
    views = {projected.splats.texel_view(VK_FORMAT_R32G32B32A32_SFLOAT, 16),
             projected.rects.texel_view(VK_FORMAT_R32G32_UINT, 8),
             projected.tile_counts.texel_view(VK_FORMAT_R32_UINT, 4),
             projected.offsets.texel_view(VK_FORMAT_R32_UINT, 4),
             (wide ? unused_keys_ : keys.keys).texel_view(VK_FORMAT_R32_UINT, 4),
             (wide ? keys.keys : unused_keys_).texel_view(VK_FORMAT_R32G32_UINT, 8),
             keys.values.texel_view(VK_FORMAT_R32_UINT, 4)};
    views = vk::complete_views(std::move(views));
  }
  const bool texel = !views.empty();
  const Variant variant{keys.wide_keys, square_tiles, alpha_inv, texel};
  auto it = emit_keys_.find(variant);
  if (it == emit_keys_.end()) {
    const std::vector<vk::SpecConstant> spec = {
        {0, keys.wide_keys}, {1, square_tiles}, {2, std::bit_cast<uint32_t>(alpha_inv)}};
    auto emit = texel
                    ? vk::ComputePipeline(ctx_, "key_emission_texel", sizeof(EmitPush), spec, kTexelBindings)
                    : vk::ComputePipeline(ctx_, "key_emission", sizeof(EmitPush), spec);
    it = emit_keys_
             .emplace(variant, std::make_pair(std::move(emit), vk::ComputePipeline(ctx_, "key_emission_big",
                                                                                   sizeof(EmitPush), spec)))
             .first;
  }
  const auto& [emit_keys, emit_big_splat_keys] = it->second;
  const EmitPush push{projected.splats.address(),
                      projected.rects.address(),
                      projected.tile_counts.address(),
                      projected.offsets.address(),
                      keys.keys.address(),
                      keys.values.address(),
                      projected.depth_order.keys.address(),
                      projected.big_splats.address(),
                      counters,
                      gaussians,
                      tiles.tiles_x,
                      keys.capacity,
                      tiles.count,
                      tiles.packed_first()};
  emit_keys.bind(cmd, push);
  if (texel) emit_keys.push_texel_views(cmd, views);
  emit_keys.dispatch(cmd, vk::div_ceil(gaussians, 256));
  vk::barrier(cmd);
  emit_big_splat_keys.bind(cmd, push);
  emit_big_splat_keys.dispatch_indirect(cmd, counters_buffer.handle(), kBigSplatsOffset);
}

}  // namespace tilesplat
