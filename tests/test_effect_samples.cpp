// The effects' sample patterns (tilesplat/effect_samples.h): Sobol's points and their strata, the lens
// positions and shutter times they give, and frames whose samples add up call after call
// (RenderSettings::accumulate_samples) to the frame of all their samples.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <set>
#include <stdexcept>
#include <vector>

#include "process_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/effect_samples.h"
#include "tilesplat/image.h"
#include "tilesplat/lens.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"
#include "tilesplat/shutter.h"

using namespace tilesplat;
using tilesplat::testing::error_of;
using tilesplat::testing::max_abs_difference;

namespace {

// Whether points [first, first + 2^bits) put one point in every box of 2^-a by 2^-(bits - a) of
// dimensions (x, y), for every a.
bool is_net(uint32_t first, int bits, size_t x, size_t y) {
  for (int a = 0; a <= bits; ++a) {
    std::set<std::pair<uint32_t, uint32_t>> boxes;
    for (uint32_t i = first; i < first + (uint32_t(1) << bits); ++i) {
      const auto p = effect_sample_point(i);
      boxes.insert({uint32_t(std::ldexp(p[x], a)), uint32_t(std::ldexp(p[y], bits - a))});
    }
    if (boxes.size() != size_t(1) << bits) return false;
  }
  return true;
}

}  // namespace

TEST(EffectSamplePoint, StratifiesEveryPowerOfTwoBlockAndIsCentredOnAverage) {
  // Dimensions 0 and 1 (the lens): a (0,2)-sequence, every aligned block of 2^k points a net.
  for (int bits = 1; bits <= 8; ++bits)
    for (uint32_t block = 0; block < 3; ++block)
      EXPECT_TRUE(is_net(block << bits, bits, 0, 1)) << bits << " bits, block " << block;
  // Dimension 2 (the time): one point in each of 2^k slices; and it is not dimension 0 or 1 again.
  for (int bits = 1; bits <= 10; ++bits) {
    std::set<uint32_t> slices;
    for (uint32_t i = 0; i < (uint32_t(1) << bits); ++i)
      slices.insert(uint32_t(std::ldexp(effect_sample_point(i)[2], bits)));
    EXPECT_EQ(slices.size(), size_t(1) << bits) << bits;
  }
  int differ_0 = 0, differ_1 = 0;
  for (uint32_t i = 0; i < 64; ++i) {
    const auto p = effect_sample_point(i);
    for (const double value : p) EXPECT_TRUE(value >= 0 && value < 1);
    differ_0 += p[2] != p[0];
    differ_1 += p[2] != p[1];
  }
  EXPECT_GT(differ_0, 32);
  EXPECT_GT(differ_1, 32);
  // The scramble puts each point anywhere in its stratum: the mean of 1,024 points is the middle to far
  // better than the corners' 1/2048 (the unscrambled sequence's bias).
  for (size_t dim = 0; dim < 3; ++dim) {
    double sum = 0;
    for (uint32_t i = 0; i < 1024; ++i) sum += effect_sample_point(i)[dim];
    EXPECT_NEAR(sum / 1024, 0.5, 1e-4) << "dimension " << dim;
  }
}

TEST(ConcentricDiskPoint, MapsTheSquareOntoTheDiskPreservingArea) {
  EXPECT_EQ(concentric_disk_point(0.5, 0.5), (std::array<double, 2>{0, 0}));
  // A uniform grid of the square: every point in the disk, the disk's quarters filled equally, and
  // the mean squared radius that of a uniform disk (1/2).
  constexpr int kSide = 256;
  double radius_squared = 0;
  int quadrant[4] = {0, 0, 0, 0};
  for (int i = 0; i < kSide; ++i)
    for (int j = 0; j < kSide; ++j) {
      const auto p = concentric_disk_point((i + 0.5) / kSide, (j + 0.5) / kSide);
      const double r2 = p[0] * p[0] + p[1] * p[1];
      ASSERT_LE(r2, 1.0 + 1e-12);
      radius_squared += r2;
      ++quadrant[(p[0] >= 0 ? 1 : 0) + (p[1] >= 0 ? 2 : 0)];
    }
  EXPECT_NEAR(radius_squared / (kSide * kSide), 0.5, 1e-4);
  for (const int count : quadrant) EXPECT_EQ(count, kSide * kSide / 4);
}

TEST(SamplePattern, NamesParseAndTheEvenPatternIsTodays) {
  for (SamplePattern pattern : {SamplePattern::kEven, SamplePattern::kSobol})
    EXPECT_EQ(parse_sample_pattern(sample_pattern_name(pattern)), pattern);
  EXPECT_NE(error_of([] { parse_sample_pattern("halton"); }).find("known: even, sobol"), std::string::npos);
  // The even pattern is lens_samples and shutter_times, to the bit.
  for (const int count : {1, 5, 32}) {
    const auto spiral = lens_samples(count);
    const auto times = shutter_times(0.25, 0.75, count);
    for (int i = 0; i < count; ++i) {
      EXPECT_EQ(lens_sample(SamplePattern::kEven, i, count), spiral[size_t(i)]);
      EXPECT_EQ(shutter_time(0.25, 0.75, SamplePattern::kEven, i, count), times[size_t(i)]);
    }
    EXPECT_THROW(lens_sample(SamplePattern::kEven, count, count), std::invalid_argument);
    EXPECT_THROW(shutter_time(0, 1, SamplePattern::kEven, count, count), std::invalid_argument);
  }
  // The progressive pattern does not depend on the count.
  for (int i = 0; i < 40; ++i) {
    EXPECT_EQ(lens_sample(SamplePattern::kSobol, i, 1), lens_sample(SamplePattern::kSobol, i, 4096));
    const auto p = effect_sample_point(uint32_t(i));
    EXPECT_EQ(lens_sample(SamplePattern::kSobol, i, 7), concentric_disk_point(p[0], p[1]));
    EXPECT_DOUBLE_EQ(shutter_time(0.2, 0.6, SamplePattern::kSobol, i, 3), 0.2 + 0.4 * p[2]);
  }
  EXPECT_THROW(lens_sample(SamplePattern::kSobol, -1, 1), std::invalid_argument);
  EXPECT_THROW(lens_sample(SamplePattern::kSobol, 0, 0), std::invalid_argument);
  // A rolling shutter's bands take the even times in order.
  Shutter rolling{.open = 0,
                  .close = 1,
                  .samples = 4,
                  .end_camera = std::nullopt,
                  .scan = ShutterScan::kTopToBottom,
                  .pattern = SamplePattern::kSobol};
  EXPECT_NE(error_of([&] { validate(rolling); }).find("rolling shutter"), std::string::npos);
  rolling.scan = ShutterScan::kGlobal;
  EXPECT_NO_THROW(validate(rolling));
}

class AccumulatedSamples : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = load_scene(tilesplat::testing::bundled_playbot());
    camera_ = orbit_camera(scene_, 96, 64, {.azimuth_deg = 30});
    renderer_ = &tilesplat::testing::validated_renderer();
    renderer_->set_scene(scene_);
    const Bounds bounds = compute_bounds(scene_);
    focus_ = camera_.to_camera({bounds.center[0], bounds.center[1], bounds.center[2]})[2];
    lens_ = {.aperture_diameter = 0.05 * focus_,
             .focus_distance = focus_,
             .samples = 1,
             .pattern = SamplePattern::kSobol};
  }
  GaussianScene scene_;
  Camera camera_;
  Renderer* renderer_ = nullptr;
  double focus_ = 1;
  ThinLens lens_;
};

TEST_F(AccumulatedSamples, ASobolLensFrameIsTheMeanOfItsPinholeFrames) {
  RenderSettings settings;
  settings.lens = lens_;
  settings.lens.samples = 6;
  const RenderImage through_lens = renderer_->render(camera_, settings);
  EXPECT_EQ(renderer_->last_frame_stats().samples, 6);
  EXPECT_EQ(renderer_->last_frame_stats().accumulated_samples, 0u);
  RenderSettings one = settings;
  one.lens.samples = 1;
  settings.accumulate_samples = false;
  // A frame of 1 is the pinhole frame of sample 0 (through the linear mean's round trip).
  const Camera first = lens_sample_camera(camera_, lens_, lens_sample(SamplePattern::kSobol, 0, 1));
  EXPECT_LE(max_abs_difference(renderer_->render(camera_, one).rgba, renderer_->render(first).rgba), 1e-6f);
  const ImageDifference d = compare_images(through_lens, render_reference(scene_, camera_, settings));
  std::printf("[ measure  ] depth of field, 6 sobol samples, against the float64 reference: %.1f dB\n",
              d.psnr_db);
  EXPECT_GE(d.psnr_db, 60.0);
}

TEST_F(AccumulatedSamples, CallsOfOneSampleAddUpToTheFrameOfAll) {
  constexpr int kSamples = 8;
  RenderSettings settings;
  settings.lens = lens_;
  settings.lens.samples = kSamples;
  const RenderImage all = renderer_->render(camera_, settings);  // one call, the host's float64 mean

  settings.accumulate_samples = true;
  settings.lens.samples = 1;  // does not matter: one sample a call
  RenderImage accumulated;
  for (int call = 1; call <= kSamples; ++call) {
    accumulated = renderer_->render(camera_, settings);
    ASSERT_EQ(renderer_->last_frame_stats().accumulated_samples, uint32_t(call));
    if (call == 1) {
      const Camera first = lens_sample_camera(camera_, lens_, lens_sample(SamplePattern::kSobol, 0, 1));
      EXPECT_LE(max_abs_difference(accumulated.rgba, renderer_->render(first).rgba), 1e-6f)
          << "sample 0's pinhole frame";
      // A frame without accumulate_samples in between starts the mean anew; so does the next call here.
      accumulated = renderer_->render(camera_, settings);
      ASSERT_EQ(renderer_->last_frame_stats().accumulated_samples, 1u);
    }
  }
  const ImageDifference d = compare_images(accumulated, all);
  std::printf("[ measure  ] %d accumulated lens samples against one call of %d: max abs %.2e\n", kSamples,
              kSamples, d.max_abs);
  EXPECT_LE(max_abs_difference(accumulated.rgba, all.rgba), 2e-5f);
  EXPECT_LE(max_abs_difference(accumulated.depth, all.depth), 2e-5f * float(focus_));
  EXPECT_EQ(accumulated.splat_count, all.splat_count);
  EXPECT_NE(accumulated.rgba, renderer_->render(camera_).rgba);

  // Another camera, aperture or background starts anew.
  settings.background = {1, 1, 1};
  renderer_->render(camera_, settings);
  EXPECT_EQ(renderer_->last_frame_stats().accumulated_samples, 1u);
  renderer_->render(camera_, settings);
  EXPECT_EQ(renderer_->last_frame_stats().accumulated_samples, 2u);
  renderer_->render(orbit_camera(scene_, 96, 64, {.azimuth_deg = 31}), settings);
  EXPECT_EQ(renderer_->last_frame_stats().accumulated_samples, 1u);
  EXPECT_EQ(renderer_->validation_messages(), 0u);
}

TEST_F(AccumulatedSamples, AShutterAndALensAccumulateOneJointSampleACall) {
  constexpr int kSamples = 5;
  const Camera end = orbit_camera(scene_, 96, 64, {.azimuth_deg = 36});
  RenderSettings settings;
  settings.background = {0.2f, 0.3f, 0.4f};  // colours averaged as opaque
  settings.lens = lens_;
  settings.shutter = {.open = 0.1,
                      .close = 0.9,
                      .samples = 3,
                      .end_camera = end,
                      .scan = ShutterScan::kGlobal,
                      .pattern = SamplePattern::kSobol};
  settings.accumulate_samples = true;
  RenderImage accumulated;
  for (int call = 0; call < kSamples; ++call) accumulated = renderer_->render(camera_, settings);
  EXPECT_EQ(renderer_->last_frame_stats().accumulated_samples, uint32_t(kSamples));
  // Sample k: the camera at time k seen from lens position k, as the definition says.
  std::vector<double> sum(accumulated.rgba.size(), 0.0);
  RenderSettings pinhole;
  pinhole.background = settings.background;
  for (int k = 0; k < kSamples; ++k) {
    const Camera moved = camera_between(camera_, end, shutter_time(0.1, 0.9, SamplePattern::kSobol, k, 1));
    const Camera sample = lens_sample_camera(moved, lens_, lens_sample(SamplePattern::kSobol, k, 1));
    const std::vector<float> linear =
        convert_colours(renderer_->render(sample, pinhole).rgba, ColourEncoding::kSrgbDisplay,
                        ColourEncoding::kSceneLinear, /*opaque=*/true);
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += linear[i];
  }
  std::vector<float> mean(sum.size());
  for (size_t i = 0; i < sum.size(); ++i) mean[i] = float(sum[i] / kSamples);
  const std::vector<float> expected =
      convert_colours(mean, ColourEncoding::kSceneLinear, ColourEncoding::kSrgbDisplay, /*opaque=*/true);
  EXPECT_LE(max_abs_difference(accumulated.rgba, expected), 2e-5f);
}

TEST_F(AccumulatedSamples, WhatCannotAccumulateIsRefused) {
  RenderSettings settings;
  settings.lens = lens_;
  settings.accumulate_samples = true;
  settings.lens.pattern = SamplePattern::kEven;
  EXPECT_NE(error_of([&] { renderer_->render(camera_, settings); }).find("pattern must be sobol"),
            std::string::npos);
  settings.lens.pattern = SamplePattern::kSobol;
  EXPECT_NE(error_of([&] { render_reference(scene_, camera_, settings); }).find("accumulate_samples"),
            std::string::npos);
  EXPECT_NE(error_of([&] { renderer_->render(scene_, camera_, settings); }).find("uploads its scene"),
            std::string::npos);
  renderer_->set_scene(scene_);
  // The refusals left nothing armed: the next frames are whole frames and a fresh accumulation.
  EXPECT_EQ(renderer_->render(camera_).rgba, renderer_->render(camera_).rgba);
  EXPECT_EQ(renderer_->last_frame_stats().accumulated_samples, 0u);
  renderer_->render(camera_, settings);
  EXPECT_EQ(renderer_->last_frame_stats().accumulated_samples, 1u);
  // Without a lens or shutter it does nothing.
  settings.lens = {};
  EXPECT_EQ(renderer_->render(camera_, settings).rgba, renderer_->render(camera_).rgba);
  EXPECT_EQ(renderer_->last_frame_stats().accumulated_samples, 0u);
}

#ifdef TILESPLAT_VIEWER_EXE
// The viewer's depth of field (--f-stop, key F): a view at rest adds a lens sample a redraw, and its
// screenshot is those samples rendered in one call: the image of tilesplat-render --f-stop with
// --lens-samples N --sample-pattern sobol, N the count it reports, to the bit.
TEST(AccumulatedSamplesViewer, AddUpLensSamplesWhileTheViewRests) {
  const std::filesystem::path out = tilesplat::testing::fresh_output_dir();
  const std::vector<std::string> view = {tilesplat::testing::bundled_playbot().string(),
                                         "--width",
                                         "160",
                                         "--height",
                                         "90",
                                         "--f-stop",
                                         "0.05",
                                         "--units-per-metre",
                                         "10"};
  std::vector<std::string> viewer_args = view;
  viewer_args.insert(viewer_args.end(), {"--no-mesh", "--frames", "6", "--validation", "--screenshot",
                                         (out / "viewer.exr").string()});
  const std::optional<std::string> display = tilesplat::testing::display_prefix();
  if (!display) TILESPLAT_SKIP_OR_FAIL(tilesplat::testing::kNoDisplay);
  const std::string prefix = *display;
  const tilesplat::testing::ProcessResult viewer =
      tilesplat::testing::run_process(prefix, TILESPLAT_VIEWER_EXE, viewer_args);
  ASSERT_EQ(viewer.exit_code, 0) << viewer.err;
  EXPECT_NE(viewer.err.find("validation: 0 messages"), std::string::npos) << viewer.err;
  const std::string said = "the screenshot is the mean of ";
  const size_t at = viewer.err.find(said);
  ASSERT_NE(at, std::string::npos) << viewer.err;
  const int samples = std::atoi(viewer.err.c_str() + at + said.size());
  // Six redraws of a view that never moved: each added its sample (a resize at the start may restart).
  EXPECT_GE(samples, 4) << viewer.err;
  EXPECT_LE(samples, 6) << viewer.err;
  std::vector<std::string> render_args = view;
  render_args.insert(render_args.end(), {"--lens-samples", std::to_string(samples), "--sample-pattern",
                                         "sobol", "-o", (out / "render.exr").string()});
  const tilesplat::testing::ProcessResult render =
      tilesplat::testing::run_process("", TILESPLAT_RENDER_EXE, render_args);
  ASSERT_EQ(render.exit_code, 0) << render.err;
  const RenderImage shot = read_exr(out / "viewer.exr");
  EXPECT_EQ(shot.rgba, read_exr(out / "render.exr").rgba);
  // And it is blurred: not the pinhole's image.
  std::vector<std::string> pinhole_args = {tilesplat::testing::bundled_playbot().string(),
                                           "--width",
                                           "160",
                                           "--height",
                                           "90",
                                           "-o",
                                           (out / "pinhole.exr").string()};
  ASSERT_EQ(tilesplat::testing::run_process("", TILESPLAT_RENDER_EXE, pinhole_args).exit_code, 0);
  EXPECT_LT(compare_images(shot, read_exr(out / "pinhole.exr")).psnr_db, 45.0);
}

// The viewer's motion blur (key B, on for a view whose shutter opens): the bundled moving_playbots.json's
// view 1, its camera panning and a model moving, adds a time sample a redraw, placing the moving copy
// anew each time, and its screenshot is tilesplat-render's image of the view with --shutter-samples N
// --sample-pattern sobol, to the bit.
TEST(AccumulatedSamplesViewer, AddUpTimeSamplesOfMovingModelsWhileTheViewRests) {
  const std::optional<std::string> display = tilesplat::testing::display_prefix();
  if (!display) TILESPLAT_SKIP_OR_FAIL(tilesplat::testing::kNoDisplay);
  const std::filesystem::path out = tilesplat::testing::fresh_output_dir();
  const std::string scene = (tilesplat::testing::bundled_scene_dir() / "moving_playbots.json").string();
  const std::vector<std::string> view = {scene, "--view", "1", "--width", "160", "--height", "90"};
  std::vector<std::string> viewer_args = view;
  viewer_args.insert(viewer_args.end(), {"--no-mesh", "--frames", "6", "--validation", "--screenshot",
                                         (out / "viewer.exr").string()});
  const tilesplat::testing::ProcessResult viewer =
      tilesplat::testing::run_process(*display, TILESPLAT_VIEWER_EXE, viewer_args);
  ASSERT_EQ(viewer.exit_code, 0) << viewer.err;
  EXPECT_NE(viewer.err.find("validation: 0 messages"), std::string::npos) << viewer.err;
  const std::string said = "the screenshot is the mean of ";
  const size_t at = viewer.err.find(said);
  ASSERT_NE(at, std::string::npos) << viewer.err;
  EXPECT_NE(viewer.err.find("time samples", at), std::string::npos) << viewer.err;
  const int samples = std::atoi(viewer.err.c_str() + at + said.size());
  EXPECT_GE(samples, 4) << viewer.err;
  EXPECT_LE(samples, 6) << viewer.err;
  auto render = [&](std::vector<std::string> extra, const std::string& name) {
    std::vector<std::string> args = view;
    args.insert(args.end(), extra.begin(), extra.end());
    args.insert(args.end(), {"-o", (out / name).string()});
    return tilesplat::testing::run_process("", TILESPLAT_RENDER_EXE, args);
  };
  const tilesplat::testing::ProcessResult blurred =
      render({"--shutter-samples", std::to_string(samples), "--sample-pattern", "sobol"}, "render.exr");
  ASSERT_EQ(blurred.exit_code, 0) << blurred.err;
  EXPECT_NE(read_exr_string_attributes(out / "render.exr")
                .at("renderSettings")
                .find(",samples:" + std::to_string(samples) + ",scan:global,camera:moving,pattern:sobol"),
            std::string::npos);
  const RenderImage shot = read_exr(out / "viewer.exr");
  EXPECT_EQ(shot.rgba, read_exr(out / "render.exr").rgba);
  // And it is blurred: not the sharp frame of one time sample.
  const tilesplat::testing::ProcessResult sharp =
      render({"--shutter-samples", "1", "--sample-pattern", "sobol"}, "sharp.exr");
  ASSERT_EQ(sharp.exit_code, 0) << sharp.err;
  EXPECT_LT(compare_images(shot, read_exr(out / "sharp.exr")).psnr_db, 35.0);
}
#endif
