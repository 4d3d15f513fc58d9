// Composite: front-to-back alpha blending of each tile's sorted splats into the output images.
#pragma once

#include <array>
#include <compare>
#include <map>
#include <vector>

#include "tilesplat/render_settings.h"
#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

struct OutputBuffers {
  vk::Buffer rgba;   // vec4 per pixel
  vk::Buffer depth;  // float per pixel (only when requested)
  vk::Buffer count;  // uint per pixel (only when requested)
  uint32_t width = 0, height = 0;
  // Where the images start in the camera's tile grid, x | y << 16 (TileGrid::packed_first): 0 for the
  // whole image, else a RenderSettings::region's first tile.
  uint32_t first_tile = 0;
};

// Shared by the composites that stage splats per tile (composite.comp, composite_stochastic.comp):
// how many pixels of a column one invocation handles (16 on CPU drivers, 1 on GPUs, or
// TILESPLAT_COMPOSITE_PIXELS), and how many splats of a tile's list one dispatch may take (llvmpipe's
// loop limit; unlimited on GPUs).
uint32_t composite_pixels_per_invocation(const vk::Context& ctx);
// The CPU-driver variants of both composites (composite.comp, composite_stochastic.comp with
// TS_TEXEL_BUFFERS) bind the splat records and the tiles' list in and colour, depth and count out:
// these descriptor types, and those views (`unused` stands in for an output that is off; empty where
// a buffer has more texels than the device allows).
const std::vector<VkDescriptorType>& composite_texel_bindings();
std::vector<VkBufferView> composite_texel_views(const vk::Buffer& splats, const vk::Buffer& list,
                                                const OutputBuffers& out, bool write_depth, bool write_count,
                                                const vk::Buffer& unused);
uint32_t composite_chunk_splats(const vk::Context& ctx);

// The cut-offs as in AccuracyModes (reference: 1/255 and 1e-4), and the cap on alpha
// (RenderSettings::max_alpha).
struct CompositeCutoffs {
  float alpha = 1.0f / 255.0f;
  float transmittance = 1e-4f;
  float max_alpha = float(kDefaultMaxAlpha);
  auto operator<=>(const CompositeCutoffs&) const = default;
};

// What every composite blends and where to: the projected splats, each tile's list of Gaussian
// indices (front to back for the sorted composites, in any order for the stochastic one) and its
// [start, end) in `ranges`, the output images, and what the frame asks of them.
struct CompositeInputs {
  const vk::Buffer& splats;      // ProjectedBuffers::splats
  const vk::Buffer& tile_lists;  // Gaussian indices, tile after tile
  const vk::Buffer& ranges;      // [start, end) of each tile's run in tile_lists
  OutputBuffers& out;
  std::array<float, 3> background = {0, 0, 0};
  bool write_depth = true;
  bool write_count = true;
  CompositeCutoffs cutoffs;
};
// Dispatches of chunk_splats each that a tile list of this length needs (at least 1).
uint32_t composite_chunks_needed(uint64_t longest_tile_list, uint32_t chunk_splats);

class CompositePass {
 public:
  explicit CompositePass(vk::Context& ctx);
  using Cutoffs = CompositeCutoffs;
  // How many dispatches blend each tile's list (see composite.comp): 1, or more on a driver that
  // limits loop iterations, with the pixels' state in `state` (state_bytes) between them. Chunk 0
  // writes the longest list over one chunk to FrameCounters::max_tile_pairs; chunks_for() turns it
  // into the count a re-render needs.
  struct Chunks {
    uint32_t count = 1;
    const vk::Buffer& state;
    VkDeviceAddress counters = 0;
  };
  // A part of a scene rendered in depth-ordered parts (frame_plan.h, ScenePart): each pixel's state
  // comes from the previous part (carry_in) and goes on to the next (carry_out) through the halves of
  // `state` (part_state_bytes), which alternate (state_high: this part writes the upper half).
  struct Carry {
    bool in = false;
    bool out = false;
    bool state_high = false;
    bool any() const { return in || out; }
  };
  // A host's depth (RenderSettings::host): the surface per pixel as view depth in, the depth at which
  // alpha reaches surface_alpha out. Null buffers: that half is off (and its pipeline the one without).
  struct HostSurface {
    const vk::Buffer* view_depth = nullptr;     // float per pixel, +inf where the host drew nothing
    const vk::Buffer* surface_depth = nullptr;  // float per pixel, written
    float surface_alpha = 0.5f;
    bool exact_depth_order = false;  // 32-bit depth keys: a pixel is done at its first splat behind the host
  };
  void record(VkCommandBuffer cmd, const CompositeInputs& in, const Chunks& chunks, const HostSurface& host,
              const Carry& carry);
  uint32_t chunks_for(uint64_t longest_tile_list) const;
  static VkDeviceSize state_bytes(uint32_t width, uint32_t height) { return VkDeviceSize(width) * height * 32; }
  static VkDeviceSize part_state_bytes(uint32_t width, uint32_t height) {
    return 2 * state_bytes(width, height);
  }

 private:
  vk::Context& ctx_;
  uint32_t pixels_per_invocation_;
  uint32_t chunk_splats_;  // splats per tile and dispatch
  bool texel_buffers_;     // the CPU layout reads and writes through texel buffers (composite_texel)
  vk::Buffer unused_output_;  // the texel binding of an output that is off
  // A pipeline of composite.comp: its specialization constants by name.
  struct Variant {
    bool write_depth = true;
    bool write_count = true;
    Cutoffs cutoffs;
    bool host_depth_in = false;      // the host's surfaces test each splat (HOST_DEPTH)
    bool surface_depth_out = false;  // the depth where alpha reaches surface_alpha is written (SURFACE_DEPTH)
    bool exact_depth_order = false;  // a pixel is done at its first splat behind the host (HOST_DEPTH_SORTED)
    bool texel_buffers = false;      // the CPU layout (composite_texel)
    bool chunked = false;            // a tile's list takes more than one dispatch (CHUNKED)
    auto operator<=>(const Variant&) const = default;
  };
  std::map<Variant, vk::ComputePipeline> pipelines_;
};

}  // namespace tilesplat
