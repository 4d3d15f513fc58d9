// One small frame through each sort strategy, compositor, accuracy mode and effect: every pass the engine
// has, recorded and run once. The image suites measure these against the reference many times over; this
// suite is what the sanitizer build runs of them (.ci/run's sanitize-tests), where what matters is that each
// pass's host code allocates, records, reads back and releases cleanly, once. Each frame must still be a
// frame: finite, something drawn, the validation layer silent.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/lens.h"
#include "tilesplat/renderer.h"
#include "tilesplat/shutter.h"

namespace tilesplat {
namespace {

class OneFrameEach : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new GaussianScene(load_scene(testing::bundled_sh3()));
    camera_ = new Camera(resize_camera(load_cameras_json(testing::bundled_sh3_cameras()).at(0).camera, 64, 36));
  }
  static void TearDownTestSuite() {
    delete scene_;
    delete camera_;
    scene_ = nullptr;
    camera_ = nullptr;
  }
  void SetUp() override {
    Renderer& renderer = testing::validated_renderer();
    messages_ = renderer.validation_messages();
    renderer.set_scene(*scene_);
  }
  void TearDown() override {
    EXPECT_EQ(testing::validated_renderer().validation_messages(), messages_) << "validation messages";
  }

  // Renders one frame and checks that it is one.
  void expect_frame(const RenderSettings& settings, const std::string& what) {
    SCOPED_TRACE(what);
    const RenderImage image = testing::validated_renderer().render(*camera_, settings);
    ASSERT_EQ(image.rgba.size(), 4 * size_t(camera_->width) * size_t(camera_->height));
    double alpha = 0;
    for (size_t i = 0; i < image.rgba.size(); ++i) {
      ASSERT_TRUE(std::isfinite(image.rgba[i])) << "value " << i;
      if (i % 4 == 3) alpha += image.rgba[i];
    }
    EXPECT_GT(alpha, 1.0) << "nothing drawn";
    for (const float z : image.depth) ASSERT_TRUE(std::isfinite(z));
  }

  static GaussianScene* scene_;
  static Camera* camera_;
  uint64_t messages_ = 0;
};
GaussianScene* OneFrameEach::scene_ = nullptr;
Camera* OneFrameEach::camera_ = nullptr;

TEST_F(OneFrameEach, SortStrategy) {
  for (const std::string& strategy : sort_strategies()) {
    RenderSettings settings;
    settings.sort = strategy;
    expect_frame(settings, strategy);
  }
}

TEST_F(OneFrameEach, Compositor) {
  RenderSettings stochastic;
  stochastic.compositor = Compositor::kStochastic;
  stochastic.stochastic.frames = 2;
  expect_frame(stochastic, "stochastic");
  RenderSettings raster;
  raster.compositor = Compositor::kRaster;
  expect_frame(raster, "raster");
  raster.accuracy.fp16_blend = true;
  expect_frame(raster, "raster fp16-blend");
}

TEST_F(OneFrameEach, AccuracyMode) {
  for (const char* modes : {"depth24", "depth16", "radial", "opacity-extent", "square-tiles", "sh0", "fp16-sh",
                            "fp16-cov", "t-cutoff=0.01", "resort4", "radial+resort4"}) {
    RenderSettings settings;
    settings.accuracy = parse_accuracy_modes(modes);
    expect_frame(settings, modes);
  }
}

TEST_F(OneFrameEach, Effect) {
  RenderSettings antialiased;
  antialiased.antialiasing = Antialiasing::kMip;
  expect_frame(antialiased, "mip antialiasing");

  RenderSettings lit;
  Light light;
  light.direction = {0, 0, 1};
  lit.lighting.lights = {light};
  expect_frame(lit, "relit");

  RenderSettings lens;
  lens.lens.aperture_diameter = 0.05;
  lens.lens.focus_distance = 2;
  lens.lens.samples = 2;
  expect_frame(lens, "thin lens");

  RenderSettings shutter;
  shutter.shutter.close = 1;
  shutter.shutter.samples = 2;
  Camera moved = *camera_;
  moved.position[0] += 0.05;
  shutter.shutter.end_camera = moved;
  expect_frame(shutter, "shutter");

  RenderSettings parts;
  parts.memory_budget = 4ull << 20;  // a few parts of the 31k-Gaussian playbot
  SCOPED_TRACE("memory budget");
  const GaussianScene playbot = load_scene(testing::bundled_playbot());
  const Camera view = resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(0).camera, 64, 36);
  const RenderImage image = testing::validated_renderer().render(playbot, view, parts);
  EXPECT_GT(testing::validated_renderer().last_frame_stats().scene_parts, 1);
  for (const float v : image.rgba) ASSERT_TRUE(std::isfinite(v));

  RenderSettings region;
  region.region = {8, 4, 32, 16};
  testing::validated_renderer().set_scene(*scene_);  // the parts left the renderer holding the last one
  const RenderImage part = testing::validated_renderer().render(*camera_, region);
  EXPECT_EQ(part.width, 32);
  EXPECT_EQ(part.height, 16);
}

}  // namespace
}  // namespace tilesplat
