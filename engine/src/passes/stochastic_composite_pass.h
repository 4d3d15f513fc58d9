// Stochastic composite (Compositor::kStochastic): sort-free. Each pixel keeps each splat of its tile's
// unordered list with probability alpha and shows the nearest kept one; the mean over samples
// converges to the sorted front-to-back blend (compute/composite_stochastic.comp).
#pragma once

#include <array>

#include "passes/composite_pass.h"
#include "vulkan/buffer.h"
#include "vulkan/command_stream.h"
#include "vulkan/compute_pipeline.h"
#include "vulkan/pipeline_variants.h"

namespace tilesplat {

class StochasticCompositePass {
 public:
  explicit StochasticCompositePass(vk::Context& ctx);
  struct Samples {
    uint32_t count = 1;  // samples averaged (StochasticSettings::frames)
    uint32_t seed = 1;   // the hashed thresholds' seed
    StochasticSampler sampler = StochasticSampler::kHash;
    // StochasticSettings::accumulate: samples 0 .. first - 1 are in the state's sums already, this frame
    // adds samples first .. first + count - 1, and its last sample keeps the sums for the next.
    uint32_t first = 0;
    bool keep_sums = false;
  };
  // Records every sample, each as chunks.count dispatches (as CompositePass::Chunks: chunk 0 writes
  // the longest list over one chunk to FrameCounters::max_tile_pairs, chunks_for() turns it into the
  // count a re-render needs). The per-pixel sums and the chunks' carried state live in chunks.state
  // (state_bytes), which only one sample in one chunk does without. Flushes the stream after every
  // kSamplesPerSubmission samples, so that no submission runs long enough for a GPU watchdog.
  // `in.tile_lists` binned by tile in any order; of the cut-offs only alpha applies (a sample keeps
  // one splat, so there is no transmittance to cut).
  void record(vk::CommandStream& stream, const CompositeInputs& in, const Samples& samples,
              const CompositePass::Chunks& chunks);
  uint32_t chunks_for(uint64_t longest_tile_list) const;
  static bool needs_state(uint32_t samples, uint32_t chunks) { return samples > 1 || chunks > 1; }
  static VkDeviceSize state_bytes(uint32_t width, uint32_t height) { return VkDeviceSize(width) * height * 32; }

  static constexpr uint32_t kSamplesPerSubmission = 64;

 private:
  TileCompositeLayout layout_;
  // A pipeline of composite_stochastic.comp: the layout's constants, then its own by name.
  struct Variant {
    TileCompositeLayout::Variant layout;
    float max_alpha = float(kDefaultMaxAlpha);
    bool stratified = false;  // StochasticSampler::kStratified (STRATIFIED)
    bool keep_sums = false;   // the last sample keeps the sums in the state (KEEP_SUMS)
    bool sobol = false;       // StochasticSampler::kSobol (SOBOL)
    auto operator<=>(const Variant&) const = default;
  };
  vk::PipelineVariants<Variant> pipelines_;
};

}  // namespace tilesplat
