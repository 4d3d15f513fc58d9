// Composite with per-pixel re-sorting of a window of splats by their depth along each pixel's ray
// (AccuracyModes::resort_window). Runs instead of CompositePass in that mode.
#pragma once

#include "passes/composite_pass.h"
#include "vulkan/pipeline_variants.h"

namespace tilesplat {

struct Camera;

class CompositeResortPass {
 public:
  explicit CompositeResortPass(vk::Context& ctx);
  // ray_depth: the projection's per-Gaussian re-sorting data (ProjectedBuffers::ray_depth).
  // `in.tile_lists` in centre-depth order; `window` splats re-sorted per pixel by ray depth.
  void record(VkCommandBuffer cmd, const CompositeInputs& in, const vk::Buffer& ray_depth,
              const Camera& camera, uint32_t window, VkDeviceAddress counters);
  // The longest tile list this pass blends on this device; a longer one is written to
  // FrameCounters::max_tile_pairs (and the frame is refused). Unlimited except on CPU drivers,
  // where llvmpipe cuts a shader short after 65535 loop iterations.
  uint32_t max_tile_splats() const;

 private:
  vk::Context& ctx_;
  uint32_t pixels_per_invocation_;
  // A pipeline of composite_resort.comp: its specialization constants by name.
  struct Variant {
    bool write_depth = true;
    bool write_count = true;
    CompositeCutoffs cutoffs;
    uint32_t window = 0;  // AccuracyModes::resort_window
    auto operator<=>(const Variant&) const = default;
  };
  vk::PipelineVariants<Variant> pipelines_;
};

}  // namespace tilesplat
