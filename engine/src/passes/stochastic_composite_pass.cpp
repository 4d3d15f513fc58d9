#include "passes/stochastic_composite_pass.h"

#include <bit>
#include <stdexcept>

#include "passes/tile_coverage.h"
#include "shader_io.h"
#include "tilesplat/reference.h"

namespace tilesplat {

namespace {
// Mirrors the push constants of compute/composite_stochastic.comp.
using shader_io::StochasticCompositePush;  // composite_stochastic.comp's push constants
static_assert(sizeof(StochasticCompositePush) <= 128, "Vulkan guarantees 128 bytes of push constants");

}  // namespace

StochasticCompositePass::StochasticCompositePass(vk::Context& ctx) : layout_(ctx, "stochastic composite") {}

void StochasticCompositePass::record(vk::CommandStream& stream, const CompositeInputs& in,
                                     const Samples& samples, const CompositePass::Chunks& chunks) {
  OutputBuffers& out = in.out;
  if (samples.count == 0) throw std::logic_error("stochastic composite: no samples");
  const bool with_state = needs_state(samples.count, chunks.count) || samples.keep_sums;
  if (with_state && chunks.state.size() < state_bytes(out.width, out.height))
    throw std::logic_error("stochastic composite: the state buffer is smaller than the image");
  const std::vector<VkBufferView> views = layout_.texel_views(in);
  const Variant variant{{in.write_depth, in.write_count, in.cutoffs.alpha, !views.empty()},
                        in.cutoffs.max_alpha,
                        samples.sampler == StochasticSampler::kStratified,
                        samples.keep_sums,
                        samples.sampler == StochasticSampler::kSobol};
  const vk::ComputePipeline& pipeline = pipelines_.get(variant, [&] {
    return layout_.make_pipeline("composite_stochastic", sizeof(StochasticCompositePush), variant.layout,
                                 {{6, std::bit_cast<uint32_t>(variant.max_alpha)},
                                  {7, variant.stratified ? 1u : 0u},
                                  {8, variant.keep_sums ? 1u : 0u},
                                  {9, variant.sobol ? 1u : 0u}});
  });
  const uint32_t tiles_x = vk::div_ceil(out.width, kTileSize);
  const uint32_t tiles_y = vk::div_ceil(out.height, kTileSize);
  for (uint32_t sample = samples.first; sample < samples.first + samples.count; ++sample) {
    if (sample > samples.first && (sample - samples.first) % kSamplesPerSubmission == 0) stream.may_split();
    for (uint32_t chunk = 0; chunk < chunks.count; ++chunk) {
      // Each dispatch reads what the previous one left in the state buffer.
      if (sample > samples.first || chunk > 0) vk::barrier(stream.cmd());
      StochasticCompositePush push{in.splats.address(),
                                   in.tile_lists.address(),
                                   in.ranges.address(),
                                   out.rgba.address(),
                                   in.write_depth ? out.depth.address() : 0,
                                   in.write_count ? out.count.address() : 0,
                                   with_state ? chunks.state.address() : 0,
                                   chunks.counters,
                                   {in.background[0], in.background[1], in.background[2], 0.0f},
                                   out.width,
                                   out.height,
                                   tiles_x,
                                   chunk * layout_.chunk_splats(),
                                   layout_.chunk_splats(),
                                   chunk + 1 == chunks.count ? 1u : 0u,
                                   sample,
                                   samples.first + samples.count,
                                   samples.seed,
                                   out.first_tile};
      pipeline.bind(stream.cmd(), push);
      if (!views.empty()) pipeline.push_texel_views(stream.cmd(), views);
      pipeline.dispatch(stream.cmd(), tiles_x, tiles_y);
    }
  }
}

uint32_t StochasticCompositePass::chunks_for(uint64_t longest_tile_list) const {
  return layout_.chunks_for(longest_tile_list);
}

}  // namespace tilesplat
