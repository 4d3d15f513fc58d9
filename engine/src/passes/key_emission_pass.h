// Frame setup + key emission: caps the key count at the buffers' capacity, sizes the indirect
// dispatches, hands each Gaussian its offset from the depth-order prefix sum, then writes one
// (tile id, Gaussian index) pair per touched tile, front to back. Without a depth order (a strategy
// that sorts (tile, depth) pairs itself) the offsets are already per Gaussian and the keys are
// 64-bit tile << 32 | depth bits.
#pragma once

#include <map>
#include <utility>

#include "passes/key_buffers.h"
#include "passes/projection_pass.h"
#include "passes/tile_grid.h"
#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

class KeyEmissionPass {
 public:
  explicit KeyEmissionPass(vk::Context& ctx);
  // depth_order: the Gaussian indices front to back (the depth sort's values), with
  // projected.depth_offsets the prefix sum of the tile counts taken in that order; or null, with
  // projected.offsets the prefix sum in Gaussian order and keys.wide_keys.
  // square_tiles and alpha_inv must be the projection's (ProjectionVariant): both count the same tiles.
  void record(VkCommandBuffer cmd, const ProjectedBuffers& projected, const vk::Buffer* depth_order,
              KeyBuffers& keys, uint32_t gaussians, const TileGrid& tiles, const vk::Buffer& counters,
              bool square_tiles, float alpha_inv);

 private:
  vk::Context& ctx_;
  vk::ComputePipeline frame_setup_;
  vk::ComputePipeline scatter_offsets_;
  // The pipelines of key_emission (or key_emission_texel) and key_emission_big: their specialization
  // constants by name.
  struct Variant {
    bool wide_keys = false;      // 64-bit (tile, depth) keys
    bool square_tiles = false;   // the projection's tile test (ProjectionVariant::square_tiles)
    float alpha_inv = 255.0f;    // the projection's coverage alpha (ProjectionVariant::alpha_inv)
    bool texel_buffers = false;  // the CPU layout (key_emission_texel)
    auto operator<=>(const Variant&) const = default;
  };
  std::map<Variant, std::pair<vk::ComputePipeline, vk::ComputePipeline>> emit_keys_;
  bool texel_buffers_;      // CPU drivers: key_emission_texel (vk::texel_buffers_wanted)
  vk::Buffer unused_keys_;  // the texel binding of the key width a frame does not write
  vk::ComputePipeline scatter_offsets_texel_;  // CPU drivers: scatter_offsets through texel buffers
};

}  // namespace tilesplat
