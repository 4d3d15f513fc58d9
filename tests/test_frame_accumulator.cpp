// FrameAccumulator (engine/src/frame/frame_accumulator.h), tested without a device: when a frame continues
// the stochastic frames and the lens and shutter samples summed before it, when the sums start anew, and
// that a frame which does not complete whole leaves nothing to continue. With plan_frame: a frame
// continues the stochastic sums only on reused lists, and the re-run of its composite starts them anew.
#include <gtest/gtest.h>

#include "frame/frame_accumulator.h"
#include "frame/frame_plan.h"
#include "test_support.h"

namespace tilesplat {
namespace {

// A 64x48 camera at the origin looking down +z.
Camera camera() {
  return testing::axis_camera(64, 48, 50);
}

RenderSettings stochastic(bool accumulate = true) {
  RenderSettings settings;
  settings.compositor = Compositor::kStochastic;
  settings.stochastic.frames = 2;
  settings.stochastic.accumulate = accumulate;
  return settings;
}

// Runs one frame of `frames` stochastic frames through the accumulator as the renderer does: the frames
// it continues, then what it leaves once it completes (whole or not).
uint32_t stochastic_frame(FrameAccumulator& sums, const RenderSettings& settings, bool whole = true) {
  const uint32_t before = sums.stochastic_frames_before(settings);
  const FrameAccumulator::FrameSums left =
      sums.frame_started(settings, before + settings.stochastic.frames, sums.take_armed_sample());
  sums.frame_completed(left, settings.stochastic.accumulate, whole);
  return left.stochastic.frames;
}

TEST(FrameAccumulator, StochasticFramesAddUpWhileTheyAreRenderedAlike) {
  FrameAccumulator sums;
  EXPECT_EQ(sums.stochastic_frames_before(stochastic()), 0u);
  EXPECT_EQ(stochastic_frame(sums, stochastic()), 2u);
  EXPECT_EQ(stochastic_frame(sums, stochastic()), 4u);
  EXPECT_EQ(stochastic_frame(sums, stochastic()), 6u);
  EXPECT_EQ(sums.stochastic().frames, 6u);
  // What the lists do not cover restarts the mean: the background, the outputs, the seed, the cap.
  RenderSettings other = stochastic();
  other.background = {1, 0, 0};
  EXPECT_EQ(sums.stochastic_frames_before(other), 0u);
  other = stochastic();
  other.depth = false;
  EXPECT_EQ(sums.stochastic_frames_before(other), 0u);
  other = stochastic();
  other.stochastic.seed = 2;
  EXPECT_EQ(sums.stochastic_frames_before(other), 0u);
  other = stochastic();
  other.max_alpha = 0.999;
  EXPECT_EQ(sums.stochastic_frames_before(other), 0u);
  // The frame count of a call does not matter: 1 more frame continues 6.
  other = stochastic();
  other.stochastic.frames = 1;
  EXPECT_EQ(sums.stochastic_frames_before(other), 6u);
}

TEST(FrameAccumulator, AFrameThatDoesNotAccumulateOrCompleteLeavesNothingToContinue) {
  FrameAccumulator sums;
  stochastic_frame(sums, stochastic());
  ASSERT_EQ(sums.stochastic().frames, 2u);
  // A frame that does not accumulate sums its own frames over the old ones: they are gone.
  stochastic_frame(sums, stochastic(/*accumulate=*/false));
  EXPECT_EQ(sums.stochastic().frames, 0u);
  stochastic_frame(sums, stochastic());
  ASSERT_EQ(sums.stochastic().frames, 2u);
  // A frame that started but did not complete whole (lists cut short, statistics incomplete).
  stochastic_frame(sums, stochastic(), /*whole=*/false);
  EXPECT_EQ(sums.stochastic().frames, 0u);
  EXPECT_EQ(sums.stochastic_frames_before(stochastic()), 0u);
}

TEST(FrameAccumulator, SamplesContinueForTheSameSceneCameraAndSettings) {
  FrameAccumulator sums;
  RenderSettings settings;
  settings.lens = ThinLens{0.1, 2.0, 16, SamplePattern::kSobol};
  settings.accumulate_samples = true;
  const Camera view = camera();
  for (uint32_t call = 0; call < 3; ++call) {
    EXPECT_EQ(sums.arm_next_sample(7, view, settings), call);
    const FrameAccumulator::FrameSums left = sums.frame_started(settings, 0, sums.take_armed_sample());
    ASSERT_TRUE(left.samples);
    EXPECT_EQ(left.samples->before(), call);
    sums.frame_completed(left, false, true);
  }
  // The sample counts do not matter (one sample a call).
  RenderSettings more = settings;
  more.lens.samples = 64;
  EXPECT_EQ(sums.arm_next_sample(7, view, more), 3u);
  (void)sums.take_armed_sample();
  // Another scene, camera or setting starts anew.
  EXPECT_EQ(sums.arm_next_sample(8, view, settings), 0u);
  (void)sums.take_armed_sample();
  Camera moved = view;
  moved.position[0] += 0.1;
  EXPECT_EQ(sums.arm_next_sample(7, moved, settings), 0u);
  (void)sums.take_armed_sample();
  RenderSettings wider = settings;
  wider.lens.aperture_diameter = 0.2;
  EXPECT_EQ(sums.arm_next_sample(7, view, wider), 0u);
}

TEST(FrameAccumulator, AnArmedSampleIsTakenOnceAndAnyFrameForgetsTheSums) {
  FrameAccumulator sums;
  RenderSettings settings;
  settings.shutter = Shutter{0.0, 1.0, 8, camera(), ShutterScan::kGlobal, SamplePattern::kSobol};
  settings.accumulate_samples = true;
  sums.arm_next_sample(1, camera(), settings);
  EXPECT_TRUE(sums.take_armed_sample());
  EXPECT_FALSE(sums.take_armed_sample()) << "armed for one frame alone";
  // Two samples summed, then a frame that is no sample (any other render): the sums are its own.
  for (int call = 0; call < 2; ++call) {
    sums.arm_next_sample(1, camera(), settings);
    sums.frame_completed(sums.frame_started(settings, 0, sums.take_armed_sample()), false, true);
  }
  ASSERT_EQ(sums.samples()->samples, 2u);
  const FrameAccumulator::FrameSums plain = sums.frame_started(RenderSettings{}, 0, sums.take_armed_sample());
  EXPECT_FALSE(plain.samples);
  sums.frame_completed(plain, false, true);
  EXPECT_FALSE(sums.samples());
  EXPECT_EQ(sums.arm_next_sample(1, camera(), settings), 0u);
}

TEST(FrameAccumulator, PlanContinuesStochasticFramesOnlyOnReusedListsAndACompositeRerunRestarts) {
  FrameContext context;
  context.scene.count = 100;
  context.scene.generation = 1;
  context.device = {true, 0x10005, 65535, uint64_t(2) << 30};
  context.sort = {"radix", FrameSortPlan::kDepthThenTile, false};
  context.stochastic_frames_before = 6;
  const RenderSettings settings = stochastic();
  const FramePlan built = plan_frame(camera(), settings, context);
  ASSERT_TRUE(built.build_lists);
  EXPECT_EQ(built.stochastic_first_sample, 0u) << "new lists: the sums start anew";
  context.lists = built.lists;
  const FramePlan reused = plan_frame(camera(), settings, context);
  ASSERT_FALSE(reused.build_lists);
  EXPECT_EQ(reused.stochastic_first_sample, 6u);
  EXPECT_EQ(plan_frame(camera(), stochastic(/*accumulate=*/false), context).stochastic_first_sample, 0u);
  EXPECT_EQ(composite_only(reused).stochastic_first_sample, 0u);
}

}  // namespace
}  // namespace tilesplat
