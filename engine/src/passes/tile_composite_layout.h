// How the composites that stage splats per tile (composite.comp, composite_stochastic.comp) run on this
// device, decided once per pass: the pixels of a tile's column one invocation blends (16 on CPU drivers,
// where each staged splat is then read once per column; 1 on GPUs; TILESPLAT_COMPOSITE_PIXELS overrides),
// the splats of a tile's list one dispatch takes (llvmpipe's loop limit; unlimited on GPUs), and whether
// the column layout reads and writes through texel buffers. The per-pixel re-sorting composite
// (composite_resort.comp) shares the specialization constants they all start with.
#pragma once

#include <compare>
#include <cstdint>
#include <string>
#include <vector>

#include "passes/composite_inputs.h"
#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

// The pixels of a column one invocation blends on this device (see the top of this file); the re-sorting
// composite takes 1 where this is 1, else the whole column.
uint32_t composite_pixels_per_invocation(const vk::Context& ctx);

// The constants every composite shader starts with: 0 write depth, 1 write count, 2 pixels an invocation,
// 3 invocations a column, 4 the alpha cut-off and 5 its coverage factor (tile_coverage.h).
std::vector<vk::SpecConstant> composite_spec_constants(bool write_depth, bool write_count,
                                                       uint32_t pixels_per_invocation, float alpha_cutoff);

class TileCompositeLayout {
 public:
  // `pass`: the pass's name, for its stand-in buffer.
  TileCompositeLayout(vk::Context& ctx, const std::string& pass);

  uint32_t pixels_per_invocation() const { return pixels_per_invocation_; }
  uint32_t chunk_splats() const { return chunk_splats_; }
  // Dispatches of chunk_splats() each that a tile list of this length needs (at least 1).
  uint32_t chunks_for(uint64_t longest_tile_list) const;

  // The frame's texel views (splats and tile lists in; colour, depth and count out, a stand-in for an
  // output that is off), or none: in the GPU layout, or where a buffer has more texels than the device
  // allows (then the shader's plain variant reads the buffers by address).
  std::vector<VkBufferView> texel_views(const CompositeInputs& in) const;
  // What a variant of a composite shader is made of beyond its own constants.
  struct Variant {
    bool write_depth = true;
    bool write_count = true;
    float alpha_cutoff = 1.0f / 255.0f;
    bool texel_buffers = false;  // the shader's texel twin (`shader`_texel), bound to texel_views()
    auto operator<=>(const Variant&) const = default;
  };
  // A pipeline of `shader` (or its texel twin) with composite_spec_constants, then `more`.
  vk::ComputePipeline make_pipeline(const std::string& shader, uint32_t push_constant_bytes,
                                    const Variant& variant, std::vector<vk::SpecConstant> more) const;

 private:
  vk::Context& ctx_;
  uint32_t pixels_per_invocation_;
  uint32_t chunk_splats_;
  bool texel_buffers_;
  vk::Buffer unused_output_;  // the texel binding of an output that is off
};

}  // namespace tilesplat
