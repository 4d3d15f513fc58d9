#include "frame/frame_accumulator.h"

#include <utility>

namespace tilesplat {

FrameAccumulator::StochasticFrames FrameAccumulator::stochastic_frames(const RenderSettings& settings,
                                                                       uint32_t frames) {
  return {frames,
          settings.background,
          settings.depth,
          settings.splat_count,
          settings.stochastic.seed,
          settings.max_alpha};
}

uint32_t FrameAccumulator::arm_next_sample(uint64_t scene_identity, const Camera& camera,
                                           const RenderSettings& settings) {
  Samples sums{scene_identity, camera, settings, 0};
  sums.settings.lens.samples = sums.settings.shutter.samples = 0;  // one sample a call, whatever they say
  if (samples_) {
    sums.samples = samples_->samples;
    if (!(sums == *samples_)) sums.samples = 0;
  }
  const uint32_t index = sums.samples;
  ++sums.samples;
  armed_sample_ = sums;
  return index;
}

uint32_t FrameAccumulator::stochastic_frames_before(const RenderSettings& settings) const {
  if (stochastic_.frames == 0 || !(stochastic_frames(settings, stochastic_.frames) == stochastic_)) return 0;
  return stochastic_.frames;
}

std::optional<FrameAccumulator::Samples> FrameAccumulator::take_armed_sample() {
  return std::exchange(armed_sample_, std::nullopt);
}

FrameAccumulator::FrameSums FrameAccumulator::frame_started(const RenderSettings& settings, uint32_t frames,
                                                            std::optional<Samples> sample) {
  stochastic_ = {};
  samples_.reset();
  return {stochastic_frames(settings, frames), std::move(sample)};
}

void FrameAccumulator::frame_completed(const FrameSums& sums, bool stochastic_accumulate, bool whole) {
  if (!whole) return;
  if (stochastic_accumulate) stochastic_ = sums.stochastic;
  if (sums.samples) samples_ = sums.samples;
}

}  // namespace tilesplat
