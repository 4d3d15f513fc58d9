// Composite: front-to-back alpha blending of each tile's sorted splats into the output images.
#pragma once

#include <array>
#include <compare>
#include <vector>

#include "passes/composite_inputs.h"
#include "passes/tile_composite_layout.h"
#include "tilesplat/render_settings.h"
#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"
#include "vulkan/pipeline_variants.h"

namespace tilesplat {

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
  TileCompositeLayout layout_;
  // A pipeline of composite.comp: the layout's constants, then its own by name.
  struct Variant {
    TileCompositeLayout::Variant layout;
    float transmittance = 1e-4f;     // CompositeCutoffs::transmittance (6); alpha is the layout's
    float max_alpha = float(kDefaultMaxAlpha);  // CompositeCutoffs::max_alpha (11)
    bool host_depth_in = false;      // the host's surfaces test each splat (HOST_DEPTH)
    bool surface_depth_out = false;  // the depth where alpha reaches surface_alpha is written (SURFACE_DEPTH)
    bool exact_depth_order = false;  // a pixel is done at its first splat behind the host (HOST_DEPTH_SORTED)
    bool chunked = false;            // a tile's list takes more than one dispatch (CHUNKED)
    auto operator<=>(const Variant&) const = default;
  };
  vk::PipelineVariants<Variant> pipelines_;
};

}  // namespace tilesplat
