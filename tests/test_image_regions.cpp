// RenderSettings::region: a frame of part of the camera's image is that part of the whole frame, bit for
// bit, with every compositor, camera model and exact sort strategy; it bins only the tiles it meets; the
// float64 reference crops alike; bad regions are clear errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

// The pixels `region` of `image` (the whole camera's), every channel.
RenderImage crop_of(const RenderImage& image, const PixelRegion& region) {
  RenderImage out;
  out.width = region.width;
  out.height = region.height;
  for (int y = region.y; y < region.y + region.height; ++y)
    for (int x = region.x; x < region.x + region.width; ++x) {
      const size_t p = size_t(y) * size_t(image.width) + size_t(x);
      for (size_t c = 0; c < 4; ++c) out.rgba.push_back(image.rgba[4 * p + c]);
      if (!image.depth.empty()) out.depth.push_back(image.depth[p]);
      if (!image.splat_count.empty()) out.splat_count.push_back(image.splat_count[p]);
    }
  return out;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

void expect_bit_identical(const RenderImage& region, const RenderImage& whole_crop, const std::string& what) {
  EXPECT_EQ(region.width, whole_crop.width) << what;
  EXPECT_EQ(region.height, whole_crop.height) << what;
  EXPECT_TRUE(same_bits(region.rgba, whole_crop.rgba)) << what << ": colour";
  EXPECT_TRUE(same_bits(region.depth, whole_crop.depth)) << what << ": depth";
  EXPECT_EQ(region.splat_count, whole_crop.splat_count) << what << ": splat counts";
}

// Regions that start and end inside tiles, on tile edges, a single row and column, and the image's
// last pixels (the camera is 200x120: its last tile row and column are partial).
const std::vector<PixelRegion>& regions() {
  static const std::vector<PixelRegion> r = {{37, 21, 101, 55}, {0, 0, 64, 32},   {0, 48, 200, 16},
                                             {0, 77, 200, 1},   {199, 0, 1, 120}, {150, 100, 50, 20}};
  return r;
}

class ImageRegions : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = load_scene(testing::bundled_playbot());
    camera_ = orbit_camera(scene_, 200, 120, {.azimuth_deg = 30});
    renderer_ = &testing::validated_renderer();
    renderer_->set_scene(scene_);
  }
  // Each region of the frame of `settings` against the whole frame's pixels.
  void expect_regions_are_the_whole_frames(const Camera& camera, RenderSettings settings,
                                           const std::string& what) {
    settings.region = {};
    const RenderImage whole = renderer_->render(camera, settings);
    for (const PixelRegion& region : regions()) {
      settings.region = region;
      expect_bit_identical(renderer_->render(camera, settings), crop_of(whole, region),
                           what + ", region " + to_string(region));
    }
    EXPECT_EQ(renderer_->validation_messages(), 0u);
  }
  GaussianScene scene_;
  Camera camera_;
  Renderer* renderer_ = nullptr;
};

TEST_F(ImageRegions, ARegionIsTheWholeFramesPixelsWithEveryCompositor) {
  for (const Compositor compositor : {Compositor::kSorted, Compositor::kStochastic, Compositor::kRaster}) {
    RenderSettings settings;
    settings.compositor = compositor;
    settings.stochastic.frames = 4;
    expect_regions_are_the_whole_frames(camera_, settings, to_string(compositor));
  }
  RenderSettings resort;
  resort.accuracy.resort_window = 4;
  expect_regions_are_the_whole_frames(camera_, resort, "resort4");
}

TEST_F(ImageRegions, ARegionIsTheWholeFramesPixelsWithEveryExactSortAndCameraModel) {
  for (const std::string& sort : sort_strategies()) {
    if (!sort_strategy_is_exact(sort)) continue;
    RenderSettings settings;
    settings.sort = sort;
    settings.reuse_lists = false;
    expect_regions_are_the_whole_frames(camera_, settings, "sort " + sort);
  }
  Camera fisheye = camera_;
  fisheye.model = CameraModel::kFisheye;
  fisheye.fx = fisheye.fy = 60;
  expect_regions_are_the_whole_frames(fisheye, {}, "fisheye");
  Camera panorama = equirectangular_camera(camera_);  // its seam copies bin like any splat
  expect_regions_are_the_whole_frames(panorama, {}, "equirectangular");
}

TEST_F(ImageRegions, ABandBinsOnlyTheTilesItMeets) {
  RenderSettings settings;
  settings.reuse_lists = false;
  renderer_->render(camera_, settings);
  const FrameStats whole = renderer_->last_frame_stats();
  // Bands of whole tile rows list each (tile, Gaussian) pair of the whole frame once between them.
  uint64_t pairs = 0, most_visible = 0;
  for (int y = 0; y < 120; y += 32) {
    settings.region = {0, y, 200, std::min(32, 120 - y)};
    const RenderImage band = renderer_->render(camera_, settings);
    EXPECT_EQ(band.height, settings.region.height);
    const FrameStats& stats = renderer_->last_frame_stats();
    std::printf(
        "[ measure  ] 200x120, rows %d to %d: %llu of the whole frame's %llu tile pairs, %llu of its "
        "%llu visible Gaussians\n",
        y, y + settings.region.height, static_cast<unsigned long long>(stats.intersections),
        static_cast<unsigned long long>(whole.intersections), static_cast<unsigned long long>(stats.visible),
        static_cast<unsigned long long>(whole.visible));
    pairs += stats.intersections;
    most_visible = std::max<uint64_t>(most_visible, stats.visible);
  }
  EXPECT_EQ(pairs, whole.intersections);
  EXPECT_LT(most_visible, whole.visible);
  // The lists of one region are not another's: a region after another of the same size rebuilds them.
  settings.reuse_lists = true;
  settings.region = {0, 40, 200, 16};
  renderer_->render(camera_, settings);
  settings.region = {0, 56, 200, 16};
  const RenderImage next = renderer_->render(camera_, settings);
  EXPECT_FALSE(renderer_->last_frame_stats().reused_sorted_lists);
  settings.region = {};
  expect_bit_identical(next, crop_of(renderer_->render(camera_, settings), {0, 56, 200, 16}),
                       "the next band");
}

TEST_F(ImageRegions, InPartsUnderABudgetARegionIsTheWholeFramesPixels) {
  RenderSettings settings;
  const RenderImage whole = renderer_->render(camera_, settings);
  settings.memory_budget = 4ull << 20;
  settings.region = {37, 21, 101, 55};
  const RenderImage parts = renderer_->render(scene_, camera_, settings);
  EXPECT_GE(renderer_->last_frame_stats().scene_parts, 2);
  expect_bit_identical(parts, crop_of(whole, settings.region), "in parts");
  renderer_->set_scene(scene_);  // the renderer holds the last part
}

TEST_F(ImageRegions, TheReferenceCropsAlike) {
  RenderSettings settings;
  const RenderImage whole = render_reference(scene_, camera_, settings);
  settings.region = {37, 21, 101, 55};
  expect_bit_identical(render_reference(scene_, camera_, settings), crop_of(whole, settings.region),
                       "the float64 reference");
  // And the GPU's region against it, as the whole frame is held to it.
  testing::expect_matches_reference(renderer_->render(camera_, settings),
                                    render_reference(scene_, camera_, settings), 2e-5, "a region");
}

TEST_F(ImageRegions, ALensAndAShutterRenderTheRegionOfEachSample) {
  RenderSettings settings;
  settings.lens = {.aperture_diameter = 0.05, .focus_distance = 2.5, .samples = 3};
  const RenderImage whole = renderer_->render(camera_, settings);
  settings.region = {37, 21, 101, 55};
  const RenderImage region = renderer_->render(camera_, settings);
  EXPECT_EQ(renderer_->last_frame_stats().samples, 3);
  expect_bit_identical(region, crop_of(whole, settings.region), "depth of field");

  RenderSettings rolling;
  rolling.shutter = {.open = 0.1,
                     .close = 0.9,
                     .samples = 5,
                     .end_camera = orbit_camera(scene_, 200, 120, {.azimuth_deg = 40}),
                     .scan = ShutterScan::kBottomToTop};
  const RenderImage rolled = renderer_->render(camera_, rolling);
  rolling.region = {37, 21, 101, 55};
  // Bands that miss the region are not rendered: 4 of the 5 bands of 24 rows meet rows 21 to 75.
  const RenderImage rolled_region = renderer_->render(camera_, rolling);
  EXPECT_EQ(renderer_->last_frame_stats().samples, 4);
  expect_bit_identical(rolled_region, crop_of(rolled, rolling.region), "a rolling shutter");
}

TEST_F(ImageRegions, BadRegionsAreClearErrors) {
  auto error_for = [&](const PixelRegion& region) {
    RenderSettings settings;
    settings.region = region;
    return testing::error_of<std::invalid_argument>([&] { renderer_->render(camera_, settings); });
  };
  EXPECT_NE(error_for({190, 0, 20, 10})
                .find("RenderSettings::region 190,0,20x10: it reaches past the 200x120 image"),
            std::string::npos);
  EXPECT_NE(error_for({-1, 0, 20, 10}).find("must not be negative"), std::string::npos);
  EXPECT_NE(error_for({0, 0, 0, 10}).find("width and height must be positive"), std::string::npos);
  RenderSettings host;
  host.region = {0, 0, 10, 10};
  const std::vector<float> host_depth(size_t(200 * 120), 0.5f);
  host.host = HostDepth{};
  host.host->depth = host_depth;
  EXPECT_NE(testing::error_of<std::invalid_argument>([&] {
              renderer_->render(camera_, host);
            }).find("a region cannot be combined with a host's depth"),
            std::string::npos);
  EXPECT_NE(testing::error_of<std::invalid_argument>([&] {
              render_reference(scene_, camera_, host);
            }).find("a region cannot be combined with a host's depth"),
            std::string::npos);
}

TEST(PixelRegion, ParsesAndPrints) {
  EXPECT_EQ(parse_pixel_region("0,540,1920x64"), (PixelRegion{0, 540, 1920, 64}));
  EXPECT_EQ(parse_pixel_region("3,4,5,6"), (PixelRegion{3, 4, 5, 6}));
  EXPECT_TRUE(parse_pixel_region("whole").whole());
  EXPECT_EQ(to_string(PixelRegion{0, 540, 1920, 64}), "0,540,1920x64");
  EXPECT_EQ(to_string(PixelRegion{}), "whole");
  for (const char* bad : {"", "1,2,3", "1,2,3x", "a,b,cxd", "1,2,-3,4", "1,2,3,4,5", "1,2,3x4x5", "1,,3,4",
                          "1,2,3x4 ", "9999999999,0,1,1"})
    EXPECT_NE(
        testing::error_of<std::invalid_argument>([&] { parse_pixel_region(bad); }).find("expected x,y,"),
        std::string::npos)
        << bad;
}

}  // namespace
}  // namespace tilesplat
