// FrameAccumulator: what the sums on the device hold between frames, and when a frame continues them.
//   - The stochastic compositor's frames (StochasticSettings::accumulate), summed in the composite state:
//     a frame continues them when it reuses the previous frame's lists (plan_frame decides that) and was
//     rendered with the same background, outputs, seed and alpha cap.
//   - Lens and shutter samples a call at a time (RenderSettings::accumulate_samples), summed in
//     FrameResources::sample_sums: a call continues them when its scene, camera and settings are those of
//     the calls before it, the sample counts aside (one sample a call, whatever they say).
// A frame that starts takes what it continues and leaves nothing behind (the sums are its own now); what
// it leaves becomes the next frame's only once it completes whole. Plain values: tested without a device
// (tests/test_frame_accumulator.cpp).
#pragma once
#include <array>
#include <cstdint>
#include <optional>

#include "tilesplat/camera.h"
#include "tilesplat/render_settings.h"

namespace tilesplat {

class FrameAccumulator {
 public:
  // The stochastic frames in the composite state's sums, and what they were rendered with beyond their
  // lists.
  struct StochasticFrames {
    uint32_t frames = 0;
    std::array<float, 3> background = {0, 0, 0};
    bool depth = false, splat_count = false;
    uint32_t seed = 0;
    double max_alpha = 0;
    bool operator==(const StochasticFrames&) const = default;
  };
  // `frames` stochastic frames rendered with `settings`.
  static StochasticFrames stochastic_frames(const RenderSettings& settings, uint32_t frames);

  // The lens and shutter samples in the sample sums: of which scene (Renderer's scene identity), camera
  // and settings (their sample counts at 0), and how many.
  struct Samples {
    uint64_t scene_identity = 0;
    Camera camera;
    RenderSettings settings;
    uint32_t samples = 0;
    // The samples in the sums before the last one (FrameContext::samples_before of the frame that adds it).
    uint32_t before() const { return samples - 1; }
    bool operator==(const Samples&) const = default;
  };

  // For a call of RenderSettings::accumulate_samples: the index of the sample it renders (0 when the
  // sums start anew), arming the sums that sample leaves for the next frame_started().
  uint32_t arm_next_sample(uint64_t scene_identity, const Camera& camera, const RenderSettings& settings);

  // The stochastic frames in the sums that a frame rendered with `settings` continues if it reuses the
  // lists (FrameContext::stochastic_frames_before): 0 unless they were rendered as it is.
  uint32_t stochastic_frames_before(const RenderSettings& settings) const;

  // What a frame leaves in the sums once it completes.
  struct FrameSums {
    StochasticFrames stochastic;     // its stochastic frames, those it continued included
    std::optional<Samples> samples;  // a sample of an accumulated lens or shutter frame
  };
  // Takes the sample armed for this frame (armed for one frame alone, even one that throws before it
  // runs). Call first, before anything that may throw.
  std::optional<Samples> take_armed_sample();
  // A frame starts: `frames` stochastic frames (its plan's first sample plus its samples) and the taken
  // sample are what it leaves; the sums held until now are its own from here on and are forgotten.
  FrameSums frame_started(const RenderSettings& settings, uint32_t frames, std::optional<Samples> sample);
  // The frame completed: with its lists whole and its statistics complete, what it left is what the next
  // frames continue (the stochastic frames only when it accumulates them).
  void frame_completed(const FrameSums& sums, bool stochastic_accumulate, bool whole);

  // What the next frames continue (for the statistics and the tests).
  const StochasticFrames& stochastic() const { return stochastic_; }
  const std::optional<Samples>& samples() const { return samples_; }

 private:
  StochasticFrames stochastic_;          // frames 0: none to continue
  std::optional<Samples> samples_;       // the sample sums the last frame left
  std::optional<Samples> armed_sample_;  // arm_next_sample's, for the next frame to take
};

}  // namespace tilesplat
