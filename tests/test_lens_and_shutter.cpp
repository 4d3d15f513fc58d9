// Depth of field (RenderSettings::lens, tilesplat/lens.h) and motion blur (RenderSettings::shutter,
// tilesplat/shutter.h): the sample patterns, the camera of each sample, the frame as the linear mean of the
// samples' frames on the GPU and in the float64 reference, and off being the pinhole frame to the bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/lens.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"
#include "tilesplat/shutter.h"

using namespace tilesplat;
using tilesplat::testing::max_abs_difference;

namespace {

// Where a camera-space point of `camera` lands on its image.
std::array<double, 2> project(const Camera& camera, const std::array<double, 3>& world) {
  const auto p = camera.to_camera(world);
  return {camera.fx * p[0] / p[2] + camera.cx, camera.fy * p[1] / p[2] + camera.cy};
}

// The mean of frames in linear light, written out as the definition says (tilesplat/lens.h); `opaque`
// for frames over a background.
RenderImage linear_mean(const std::vector<RenderImage>& frames, bool opaque = false) {
  std::vector<double> sum(frames.front().rgba.size(), 0.0);
  for (const RenderImage& frame : frames) {
    const std::vector<float> linear =
        convert_colours(frame.rgba, ColourEncoding::kSrgbDisplay, ColourEncoding::kSceneLinear, opaque);
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += linear[i];
  }
  std::vector<float> mean(sum.size());
  for (size_t i = 0; i < sum.size(); ++i) mean[i] = float(sum[i] / double(frames.size()));
  RenderImage image = frames.front();
  image.rgba = convert_colours(mean, ColourEncoding::kSceneLinear, ColourEncoding::kSrgbDisplay, opaque);
  return image;
}

}  // namespace

TEST(LensSamples, AreVogelsSpiralOnTheUnitDisk) {
  for (const int count : {1, 2, 7, 32, 1024}) {
    const auto samples = lens_samples(count);
    ASSERT_EQ(samples.size(), size_t(count));
    double sum_x = 0, sum_y = 0, sum_r2 = 0;
    for (int i = 0; i < count; ++i) {
      const auto [x, y] = samples[size_t(i)];
      const double r = std::hypot(x, y);
      EXPECT_NEAR(r, std::sqrt((i + 0.5) / count), 1e-12);
      EXPECT_LE(r, 1.0);
      if (r > 1e-9) {
        const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
        EXPECT_NEAR(std::remainder(std::atan2(y, x) - i * golden, 2 * std::numbers::pi), 0.0, 1e-9) << i;
      }
      sum_x += x, sum_y += y, sum_r2 += r * r;
    }
    EXPECT_NEAR(sum_r2 / count, 0.5, 1e-12);  // each sample stands for an equal area
    if (count >= 32) {
      EXPECT_LT(std::hypot(sum_x, sum_y) / count, 0.03) << count;  // centred
    }
  }
  EXPECT_EQ(lens_samples(32), lens_samples(32));
  for (const int bad : {0, -1, kMaxLensSamples + 1})
    EXPECT_THROW(lens_samples(bad), std::invalid_argument) << bad;
}

TEST(LensSampleCamera, KeepsTheFocusPlaneWhereThePinholeSeesIt) {
  const Camera camera = look_at_camera({1, -0.5, -4}, {0, 0, 0}, {0, -1, 0}, 320, 240, 50);
  const ThinLens lens{.aperture_diameter = 0.2, .focus_distance = 3.0, .samples = 16};
  // Points at view depth 3 (in focus) and 6 (behind it), across the image.
  const auto at_depth = [&](double x, double y, double z) {
    std::array<double, 3> world = camera.position;  // position + R^T (x, y, z)
    for (int k = 0; k < 3; ++k)
      world[k] += x * camera.rotation[k] + y * camera.rotation[3 + k] + z * camera.rotation[6 + k];
    return world;
  };
  double behind_moved = 0;
  for (const auto& sample : lens_samples(lens.samples)) {
    const Camera moved = lens_sample_camera(camera, lens, sample);
    EXPECT_EQ(moved.rotation, camera.rotation);
    const double shift =
        std::hypot(moved.position[0] - camera.position[0], moved.position[1] - camera.position[1],
                   moved.position[2] - camera.position[2]);
    EXPECT_NEAR(shift, 0.1 * std::hypot(sample[0], sample[1]), 1e-12);
    for (const auto& [x, y] : {std::array{0.0, 0.0}, std::array{0.9, -0.4}, std::array{-1.2, 0.7}}) {
      const auto pinhole = project(camera, at_depth(x, y, 3.0));
      const auto through = project(moved, at_depth(x, y, 3.0));
      EXPECT_NEAR(through[0], pinhole[0], 1e-9);
      EXPECT_NEAR(through[1], pinhole[1], 1e-9);
      const auto far_pinhole = project(camera, at_depth(x, y, 6.0));
      const auto far_through = project(moved, at_depth(x, y, 6.0));
      behind_moved = std::max(behind_moved,
                              std::hypot(far_through[0] - far_pinhole[0], far_through[1] - far_pinhole[1]));
    }
  }
  // The circle of confusion of depth 6 focused at 3: aperture * fx * |1/6 - 1/3| / 2 at the rim.
  EXPECT_NEAR(behind_moved, 0.2 * camera.fx * (1.0 / 3 - 1.0 / 6) / 2, 0.2 * camera.fx / 12 * 0.05);
  EXPECT_EQ(lens_sample_camera(camera, ThinLens{}, {0.5, 0.5}), camera);  // no aperture: the pinhole
  EXPECT_THROW(lens_sample_camera(camera, {.aperture_diameter = 0.1, .focus_distance = 0}, {0, 0}),
               std::invalid_argument);
}

TEST(ApertureForFStop, IsTheFocalLengthOverTheFNumber) {
  // 1920 px wide, fx 1920: a 36 mm sensor makes it a 36 mm lens; at f/2 the aperture is 18 mm.
  Camera camera;
  camera.width = 1920, camera.height = 1080, camera.fx = camera.fy = 1920, camera.cx = 960, camera.cy = 540;
  EXPECT_NEAR(aperture_for_f_stop(camera, 2.0), 0.018, 1e-12);
  EXPECT_NEAR(aperture_for_f_stop(camera, 2.0, 36.0, 100.0), 1.8, 1e-12);  // a scene in centimetres
  for (const double bad : {0.0, -1.0, std::nan("")}) {
    EXPECT_THROW(aperture_for_f_stop(camera, bad), std::invalid_argument) << bad;
    EXPECT_THROW(aperture_for_f_stop(camera, 2.0, bad), std::invalid_argument) << bad;
  }
}

class AveragedFrames : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = load_scene(tilesplat::testing::bundled_playbot());
    camera_ = orbit_camera(scene_, 128, 72, {.azimuth_deg = 30});
    renderer_ = &tilesplat::testing::validated_renderer();
    renderer_->set_scene(scene_);
    const Bounds bounds = compute_bounds(scene_);
    const auto p = camera_.to_camera({bounds.center[0], bounds.center[1], bounds.center[2]});
    focus_ = p[2];  // the view depth of the scene's centre
  }
  GaussianScene scene_;
  Camera camera_;
  Renderer* renderer_ = nullptr;
  double focus_ = 1;
};

TEST_F(AveragedFrames, OffIsThePinholeFrameToTheBit) {
  const RenderImage pinhole = renderer_->render(camera_);
  RenderSettings settings;
  settings.lens = {.aperture_diameter = 0, .focus_distance = 2.5, .samples = 8};
  const RenderImage off = renderer_->render(camera_, settings);
  EXPECT_EQ(off.rgba, pinhole.rgba);
  EXPECT_EQ(off.depth, pinhole.depth);
  EXPECT_EQ(off.splat_count, pinhole.splat_count);
  EXPECT_EQ(renderer_->last_frame_stats().samples, 1);
  EXPECT_EQ(render_reference(scene_, camera_, settings).rgba, render_reference(scene_, camera_).rgba);
}

TEST_F(AveragedFrames, IsTheLinearMeanOfTheSamplesPinholeFrames) {
  RenderSettings settings;
  settings.lens = {.aperture_diameter = 0.05 * focus_, .focus_distance = focus_, .samples = 6};
  const RenderImage through_lens = renderer_->render(camera_, settings);
  const FrameStats stats = renderer_->last_frame_stats();
  EXPECT_EQ(stats.samples, 6);
  EXPECT_EQ(stats.passes.front().name, "projection");

  std::vector<RenderImage> frames;
  double gpu_ms = 0;
  for (const auto& sample : lens_samples(6)) {
    frames.push_back(renderer_->render(lens_sample_camera(camera_, settings.lens, sample)));
    gpu_ms += renderer_->last_frame_stats().gpu_ms;
  }
  const RenderImage mean = linear_mean(frames);
  EXPECT_LE(max_abs_difference(through_lens.rgba, mean.rgba), 1e-6f);
  EXPECT_GT(stats.gpu_ms, 0.5 * gpu_ms);  // the samples' times, summed
  // Depth: the alpha-weighted mean of the samples' depths.
  const size_t pixel = size_t(36) * 128 + 64;
  double alpha_depth = 0, alpha = 0;
  for (const RenderImage& frame : frames) {
    alpha_depth += double(frame.rgba[4 * pixel + 3]) * frame.depth[pixel];
    alpha += frame.rgba[4 * pixel + 3];
  }
  ASSERT_GT(alpha, 0.0);
  EXPECT_NEAR(through_lens.depth[pixel], alpha_depth / alpha, 1e-5 * focus_);
  EXPECT_NE(through_lens.rgba, frames.front().rgba);

  // The reference makes it the same way from its own pinhole frames.
  const RenderImage reference = render_reference(scene_, camera_, settings);
  const ImageDifference d = compare_images(through_lens, reference);
  std::printf(
      "[ measure  ] depth of field, 6 samples, against the float64 reference: PSNR %.1f dB, max abs %.2e\n",
      d.psnr_db, d.max_abs);
  EXPECT_GE(d.psnr_db, 60.0);
  EXPECT_EQ(renderer_->validation_messages(), 0u);
}

TEST_F(AveragedFrames, OverABackgroundTheColoursAreAveragedAsOpaque) {
  // Over white, a pixel's colour holds the background (C = c + T), so it is not premultiplied by its
  // alpha: decoding C / A would blow it up where alpha is small. Each is converted as an opaque colour.
  RenderSettings settings;
  settings.background = {1, 1, 1};
  settings.lens = {.aperture_diameter = 0.1 * focus_, .focus_distance = focus_, .samples = 4};
  const RenderImage through_lens = renderer_->render(camera_, settings);
  RenderSettings pinhole = settings;
  pinhole.lens = {};
  std::vector<RenderImage> frames;
  for (const auto& sample : lens_samples(4))
    frames.push_back(renderer_->render(lens_sample_camera(camera_, settings.lens, sample), pinhole));
  EXPECT_LE(max_abs_difference(through_lens.rgba, linear_mean(frames, /*opaque=*/true).rgba), 1e-6f);
  float brightest = 0;
  for (size_t i = 0; i < through_lens.rgba.size(); ++i)
    if (i % 4 != 3) brightest = std::max(brightest, through_lens.rgba[i]);
  EXPECT_LE(brightest, 1.0f + 1e-5f);  // white is the brightest there is
  EXPECT_GE(compare_images(through_lens, render_reference(scene_, camera_, settings)).psnr_db, 60.0);
}

TEST_F(AveragedFrames, BlursWhatIsOutOfFocusMore) {
  const RenderImage pinhole = renderer_->render(camera_);
  RenderSettings settings;
  settings.lens = {.aperture_diameter = 0.08 * focus_, .focus_distance = focus_, .samples = 16};
  const double in_focus = compare_images(renderer_->render(camera_, settings), pinhole).psnr_db;
  settings.lens.focus_distance = 4 * focus_;  // focused far behind the scene
  const double out_of_focus = compare_images(renderer_->render(camera_, settings), pinhole).psnr_db;
  std::printf("[ measure  ] against the pinhole frame: focused on the scene %.1f dB, behind it %.1f dB\n",
              in_focus, out_of_focus);
  EXPECT_GT(in_focus, out_of_focus + 3.0);
}

TEST_F(AveragedFrames, BadLensesAreRefused) {
  RenderSettings settings;
  for (const ThinLens bad :
       {ThinLens{.aperture_diameter = -0.1}, ThinLens{.aperture_diameter = std::nan("")},
        ThinLens{.aperture_diameter = 0.1, .focus_distance = 0},
        ThinLens{.aperture_diameter = 0.1, .focus_distance = -2},
        ThinLens{.aperture_diameter = 0.1, .focus_distance = 1, .samples = 0},
        ThinLens{.aperture_diameter = 0.1, .focus_distance = 1, .samples = kMaxLensSamples + 1}}) {
    settings.lens = bad;
    EXPECT_THROW(renderer_->render(camera_, settings), std::invalid_argument);
    EXPECT_THROW(render_reference(scene_, camera_, settings), std::invalid_argument);
  }
  settings.lens = {.aperture_diameter = 0.1, .focus_distance = 1, .samples = 4};
  settings.host = HostDepth{};
  EXPECT_THROW(renderer_->render(camera_, settings), std::invalid_argument);
}

TEST(ShutterTimes, AreTheMiddlesOfEqualSlices) {
  EXPECT_EQ(shutter_times(0, 1, 4), (std::vector<double>{0.125, 0.375, 0.625, 0.875}));
  EXPECT_EQ(shutter_times(0.25, 0.25, 2), (std::vector<double>{0.25, 0.25}));
  const auto times = shutter_times(0.2, 0.7, 5);
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(times[size_t(i)], 0.2 + (i + 0.5) * 0.1, 1e-15);
  EXPECT_THROW(shutter_times(0.5, 0.4, 4), std::invalid_argument);
  EXPECT_THROW(shutter_times(-0.1, 0.4, 4), std::invalid_argument);
  EXPECT_THROW(shutter_times(0, 1.5, 4), std::invalid_argument);
  EXPECT_THROW(shutter_times(0, std::nan(""), 4), std::invalid_argument);
  EXPECT_THROW(shutter_times(0, 1, 0), std::invalid_argument);
}

TEST(CameraBetween, BlendsPositionAndIntrinsicsAndSlerpsTheRotation) {
  const Camera start = look_at_camera({0, 0, -4}, {0, 0, 0}, {0, -1, 0}, 64, 48, 50);
  const Camera end = look_at_camera({4, 0, 0}, {0, 0, 0}, {0, -1, 0}, 64, 48, 40);  // a quarter turn round
  EXPECT_EQ(camera_between(start, end, 0), start);
  const Camera middle = camera_between(start, end, 0.5);
  EXPECT_NEAR(middle.position[0], 2, 1e-12);
  EXPECT_NEAR(middle.position[2], -2, 1e-12);
  EXPECT_NEAR(middle.fy, 0.5 * (start.fy + end.fy), 1e-9);
  // Half of the quarter turn: the view axis (the rotation's third row) at 45 degrees between the two.
  const std::array<double, 3> axis = {middle.rotation[6], middle.rotation[7], middle.rotation[8]};
  EXPECT_NEAR(axis[0], -std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(axis[2], std::sqrt(0.5), 1e-9);
  const Camera at_end = camera_between(start, end, 1);
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(at_end.rotation[size_t(k)], end.rotation[size_t(k)], 1e-12);
  EXPECT_THROW(camera_between(start, resize_camera(end, 32, 24), 0.5), std::invalid_argument);
  EXPECT_THROW(camera_between(start, end, 1.5), std::invalid_argument);
}

TEST_F(AveragedFrames, MotionBlurIsTheLinearMeanOfTheFramesAtTheShutterTimes) {
  RenderSettings settings;
  const Camera end = orbit_camera(scene_, 128, 72, {.azimuth_deg = 40});
  // Off: a closed shutter, or an open one over a camera that does not move, is the frame it always was.
  const RenderImage still = renderer_->render(camera_);
  settings.shutter = {.open = 0.3, .close = 0.3, .samples = 8, .end_camera = end};
  EXPECT_EQ(renderer_->render(camera_, settings).rgba, still.rgba);
  settings.shutter = {.open = 0, .close = 1, .samples = 8, .end_camera = std::nullopt};
  EXPECT_EQ(renderer_->render(camera_, settings).rgba, still.rgba);
  EXPECT_EQ(renderer_->last_frame_stats().samples, 1);

  settings.shutter = {.open = 0, .close = 0.5, .samples = 5, .end_camera = end};
  const RenderImage blurred = renderer_->render(camera_, settings);
  EXPECT_EQ(renderer_->last_frame_stats().samples, 5);
  std::vector<RenderImage> frames;
  for (const double t : shutter_times(0, 0.5, 5))
    frames.push_back(renderer_->render(camera_between(camera_, end, t)));
  EXPECT_LE(max_abs_difference(blurred.rgba, linear_mean(frames).rgba), 1e-6f);
  EXPECT_LT(compare_images(blurred, still).psnr_db, 40.0);
  const ImageDifference d = compare_images(blurred, render_reference(scene_, camera_, settings));
  std::printf("[ measure  ] motion blur, 5 samples, against the float64 reference: PSNR %.1f dB\n",
              d.psnr_db);
  EXPECT_GE(d.psnr_db, 60.0);

  // With a lens too, every time sample is a lens frame: 5 x 3 pinhole frames.
  settings.lens = {.aperture_diameter = 0.05 * focus_, .focus_distance = focus_, .samples = 3};
  const RenderImage both = renderer_->render(camera_, settings);
  EXPECT_EQ(renderer_->last_frame_stats().samples, 15);
  std::vector<RenderImage> lens_frames;
  RenderSettings lens_only;
  lens_only.lens = settings.lens;
  for (const double t : shutter_times(0, 0.5, 5))
    lens_frames.push_back(renderer_->render(camera_between(camera_, end, t), lens_only));
  EXPECT_LE(max_abs_difference(both.rgba, linear_mean(lens_frames).rgba), 2e-6f);

  settings.lens = {};
  settings.shutter.end_camera = resize_camera(end, 64, 36);
  EXPECT_THROW(renderer_->render(camera_, settings), std::invalid_argument);
  settings.shutter = {.open = 0.6, .close = 0.5, .samples = 5, .end_camera = end};
  EXPECT_THROW(renderer_->render(camera_, settings), std::invalid_argument);
  EXPECT_THROW(render_reference(scene_, camera_, settings), std::invalid_argument);
  EXPECT_EQ(renderer_->validation_messages(), 0u);
}

TEST(TransformBetween, BlendsTranslationAndScaleAndSlerpsTheRotation) {
  ModelTransform start;
  start.translation = {1, 2, 3};
  ModelTransform end = start;
  end.translation = {3, 2, -1};
  end.scale = {3, 3, 3};
  end.rotation = quaternion_from_euler_xyz_deg({0, 90, 0});
  EXPECT_EQ(transform_between(start, end, 0).translation, start.translation);
  EXPECT_EQ(transform_between(start, end, 0).rotation, start.rotation);
  EXPECT_EQ(transform_between(start, end, 1).rotation, end.rotation);
  EXPECT_EQ(transform_between(start, end, 1).scale, end.scale);
  const ModelTransform half = transform_between(start, end, 0.5);
  EXPECT_EQ(half.translation, (std::array<double, 3>{2, 2, 1}));
  EXPECT_EQ(half.scale, (std::array<double, 3>{2, 2, 2}));
  const std::array<double, 4> quarter = quaternion_from_euler_xyz_deg({0, 45, 0});
  for (size_t k = 0; k < 4; ++k) EXPECT_NEAR(half.rotation[k], quarter[k], 1e-12) << k;
  // A model that does not turn keeps its rotation to the bit.
  ModelTransform slid = start;
  slid.rotation = quaternion_from_euler_xyz_deg({10, 20, 30});
  ModelTransform slid_end = slid;
  slid_end.translation = {0, 0, 0};
  EXPECT_EQ(transform_between(slid, slid_end, 0.3).rotation, slid.rotation);
  EXPECT_THROW(transform_between(start, end, 1.5), std::invalid_argument);
  ModelTransform upright = end;
  upright.z_up = true;
  EXPECT_THROW(transform_between(start, upright, 0.5), std::invalid_argument);
  ModelTransform stretched = end;
  stretched.scale = {1, 2, 1};
  EXPECT_THROW(transform_between(start, stretched, 0.5), std::invalid_argument);
}

// Two copies of the playbot, the second sliding sideways and turning while the shutter is open.
class MovingModels : public AveragedFrames {
 protected:
  void SetUp() override {
    AveragedFrames::SetUp();
    instances_.files = {scene_};
    instances_.sh_degree = scene_.sh_degree;
    const Bounds bounds = compute_bounds(scene_);
    ModelTransform beside;
    beside.translation = {0.4 * bounds.radius, 0, 0};
    ModelTransform moved = beside;
    moved.translation = {-0.4 * bounds.radius, 0, 0.2 * bounds.radius};
    moved.rotation = quaternion_from_euler_xyz_deg({0, 40, 0});
    instances_.instances = {{0, {}, std::nullopt}, {0, beside, moved}};
  }
  SceneInstances instances_;
};

TEST_F(MovingModels, AreTheLinearMeanOfTheScenesAtTheShutterTimes) {
  ASSERT_TRUE(instances_.moves());
  Renderer& renderer = *renderer_;
  // Closed, the scene is where it is at time 0: the merged scene's frame, bit for bit.
  renderer.set_scene(merge_instances(instances_));
  const RenderImage still = renderer.render(camera_);
  EXPECT_EQ(renderer.render(instances_, camera_).rgba, still.rgba);
  RenderSettings settings;
  settings.shutter = {.open = 0.4, .close = 0.4, .samples = 6, .end_camera = std::nullopt};
  EXPECT_EQ(renderer.render(instances_, camera_, settings).rgba, still.rgba);
  EXPECT_EQ(merge_instances(instances_, 0).positions, merge_instances(instances_).positions);

  // Open over a still camera: the mean of the frames of the scene placed at each time.
  settings.shutter = {.open = 0.1, .close = 0.9, .samples = 5, .end_camera = std::nullopt};
  const RenderImage blurred = renderer.render(instances_, camera_, settings);
  EXPECT_EQ(renderer.last_frame_stats().samples, 5);
  std::vector<RenderImage> frames;
  for (const double t : shutter_times(0.1, 0.9, 5)) {
    renderer.set_scene(merge_instances(instances_, t));
    frames.push_back(renderer.render(camera_));
  }
  EXPECT_LE(max_abs_difference(blurred.rgba, linear_mean(frames).rgba), 1e-6f);
  EXPECT_LT(compare_images(blurred, still).psnr_db, 35.0);
  const ImageDifference d = compare_images(blurred, render_reference(instances_, camera_, settings));
  std::printf("[ measure  ] moving models, 5 samples, against the float64 reference: PSNR %.1f dB\n",
              d.psnr_db);
  EXPECT_GE(d.psnr_db, 60.0);

  // With the camera moving too, each time sample sees the scene then from the camera then.
  const Camera end = orbit_camera(scene_, 128, 72, {.azimuth_deg = 40});
  settings.shutter.end_camera = end;
  const RenderImage both = renderer.render(instances_, camera_, settings);
  std::vector<RenderImage> moving_frames;
  for (const double t : shutter_times(0.1, 0.9, 5)) {
    renderer.set_scene(merge_instances(instances_, t));
    moving_frames.push_back(renderer.render(camera_between(camera_, end, t)));
  }
  EXPECT_LE(max_abs_difference(both.rgba, linear_mean(moving_frames).rgba), 1e-6f);

  // In parts under a memory budget, each time sample's parts place the copies where they are then. A
  // renderer of its own: the budget counts what a renderer holds, which the frames of earlier tests in
  // this process grew in the shared one.
  settings.shutter.end_camera = std::nullopt;
  settings.memory_budget = 3 << 20;
  RendererOptions validated;
  validated.validation = true;
  const std::unique_ptr<Renderer> fresh = Renderer::create(validated);
  const RenderImage parts = fresh->render(instances_, camera_, settings);
  EXPECT_GT(fresh->last_frame_stats().scene_parts, 5);  // more than one part for each of the 5 samples
  EXPECT_LE(max_abs_difference(parts.rgba, blurred.rgba), 1e-6f);
  EXPECT_EQ(renderer.validation_messages(), 0u);
  EXPECT_EQ(fresh->validation_messages(), 0u);
}

// A renderer that keeps the copies (set_scene of SceneInstances) places them per time sample itself: the
// frames of render(instances, camera, settings) without an upload per call, and samples that add up.
TEST_F(MovingModels, ASetSceneOfCopiesPlacesThemAtEachSamplesTime) {
  Renderer& renderer = *renderer_;
  RenderSettings settings;
  settings.shutter = {.open = 0.1,
                      .close = 0.9,
                      .samples = 5,
                      .end_camera = std::nullopt,
                      .scan = ShutterScan::kGlobal,
                      .pattern = SamplePattern::kSobol};
  const RenderImage uploaded_per_sample = renderer.render(instances_, camera_, settings);
  renderer.set_scene(merge_instances(instances_));
  const RenderImage still = renderer.render(camera_);

  renderer.set_scene(instances_);
  EXPECT_EQ(renderer.render(camera_).rgba, still.rgba);  // closed: where they are at time 0
  const RenderImage blurred = renderer.render(camera_, settings);
  EXPECT_EQ(renderer.last_frame_stats().samples, 5);
  EXPECT_EQ(blurred.rgba, uploaded_per_sample.rgba);
  EXPECT_EQ(renderer.render(camera_).rgba, still.rgba);  // closed again: placed back at time 0

  // One time sample a call, added up on the device: the frame of all of them.
  settings.accumulate_samples = true;
  RenderImage accumulated;
  for (int call = 1; call <= 5; ++call) {
    accumulated = renderer.render(camera_, settings);
    ASSERT_EQ(renderer.last_frame_stats().accumulated_samples, uint32_t(call));
  }
  EXPECT_LE(max_abs_difference(accumulated.rgba, blurred.rgba), 2e-5f);
  // The copies' placings do not restart the sums; another scene does.
  renderer.set_scene(instances_);
  renderer.render(camera_, settings);
  EXPECT_EQ(renderer.last_frame_stats().accumulated_samples, 1u);
  // A scene without moving copies keeps nothing: an open shutter over it without an end camera blurs
  // nothing.
  SceneInstances still_copies = instances_;
  still_copies.instances[1].end_transform.reset();
  renderer.set_scene(still_copies);
  settings.accumulate_samples = false;
  EXPECT_EQ(renderer.render(camera_, settings).rgba, still.rgba);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST_F(MovingModels, ARollingShutterPlacesEachBandsScene) {
  RenderSettings settings;
  settings.shutter = {
      .open = 0, .close = 1, .samples = 3, .end_camera = std::nullopt, .scan = ShutterScan::kLeftToRight};
  Renderer& renderer = *renderer_;
  const RenderImage rolled = renderer.render(instances_, camera_, settings);
  const std::vector<double> times = shutter_times(0, 1, 3);
  for (int k = 0; k < 3; ++k) {
    renderer.set_scene(merge_instances(instances_, times[size_t(k)]));
    const RenderImage frame = renderer.render(camera_);
    // Band k: columns [k w / 3, (k + 1) w / 3).
    for (int y = 0; y < camera_.height; ++y)
      for (int x = k * camera_.width / 3; x < (k + 1) * camera_.width / 3; ++x) {
        const size_t p = 4 * (size_t(y) * size_t(camera_.width) + size_t(x));
        ASSERT_EQ(rolled.rgba[p], frame.rgba[p]) << "band " << k << " pixel " << x << "," << y;
      }
  }
}

TEST_F(AveragedFrames, ARollingShutterExposesEachBandAtItsTime) {
  const Camera end = orbit_camera(scene_, 128, 72, {.azimuth_deg = 40});
  const std::vector<double> times = shutter_times(0.1, 0.9, 4);
  std::vector<RenderImage> frames;  // the frames at the four band times
  for (const double t : times) frames.push_back(renderer_->render(camera_between(camera_, end, t)));
  // Each scan: band k (from where the scan starts) is the k-th frame's, to the bit.
  for (const ShutterScan scan : {ShutterScan::kTopToBottom, ShutterScan::kBottomToTop,
                                 ShutterScan::kLeftToRight, ShutterScan::kRightToLeft}) {
    RenderSettings settings;
    settings.shutter = {.open = 0.1, .close = 0.9, .samples = 4, .end_camera = end, .scan = scan};
    const RenderImage rolled = renderer_->render(camera_, settings);
    EXPECT_EQ(renderer_->last_frame_stats().samples, 4);
    const bool rows = scan == ShutterScan::kTopToBottom || scan == ShutterScan::kBottomToTop;
    const bool reversed = scan == ShutterScan::kBottomToTop || scan == ShutterScan::kRightToLeft;
    const int extent = rows ? 72 : 128;
    size_t checked = 0;
    for (int y = 0; y < 72; ++y)
      for (int x = 0; x < 128; ++x) {
        const int along = reversed ? extent - 1 - (rows ? y : x) : (rows ? y : x);
        const size_t band = size_t(along * 4 / extent), p = size_t(y) * 128 + size_t(x);
        for (size_t c = 0; c < 4; ++c)
          ASSERT_EQ(rolled.rgba[4 * p + c], frames[band].rgba[4 * p + c]) << x << "," << y;
        ASSERT_EQ(rolled.depth[p], frames[band].depth[p]);
        ++checked;
      }
    EXPECT_EQ(checked, size_t(128 * 72));
    // The reference stitches its own frames the same way.
    const ImageDifference d = compare_images(rolled, render_reference(scene_, camera_, settings));
    std::printf("[ measure  ] rolling shutter %s, 4 bands, against the float64 reference: PSNR %.1f dB\n",
                shutter_scan_name(scan), d.psnr_db);
    EXPECT_GE(d.psnr_db, 60.0);
  }
  // A global shutter of the same times is another image (the mean, not the bands).
  RenderSettings global;
  global.shutter = {.open = 0.1, .close = 0.9, .samples = 4, .end_camera = end};
  RenderSettings rolling = global;
  rolling.shutter.scan = ShutterScan::kTopToBottom;
  EXPECT_LT(compare_images(renderer_->render(camera_, global), renderer_->render(camera_, rolling)).psnr_db,
            40.0);
  // More bands than rows: one per row.
  rolling.shutter.samples = 500;
  EXPECT_EQ(renderer_->render(camera_, rolling).width, 128);
  EXPECT_EQ(renderer_->last_frame_stats().samples, 72);
  EXPECT_EQ(parse_shutter_scan("bottom-to-top"), ShutterScan::kBottomToTop);
  EXPECT_THROW(parse_shutter_scan("diagonal"), std::invalid_argument);
  EXPECT_EQ(renderer_->validation_messages(), 0u);
}
