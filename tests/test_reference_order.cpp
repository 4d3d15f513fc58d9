// The float64 reference's per-pixel orders (ReferenceOrder, AccuracyModes::resort_window): the GPU's
// re-sorting composite blends in the order the reference's same window gives, and the exact order
// along each pixel's ray (ReferenceOrder::kRayDepth) is what the window approaches as it grows.
#include <gtest/gtest.h>

#include <cstdio>
#include <stdexcept>

#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

RenderSettings colour_only(int resort_window) {
  RenderSettings settings;
  settings.depth = false;
  settings.splat_count = false;
  settings.accuracy.resort_window = resort_window;
  return settings;
}

Camera playbot_view(int width, int height) {
  return resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(0).camera, width, height);
}

// The same window in float32 on the GPU and in float64 here: the images agree to rounding (two
// splats whose ray depths tie in float32 may swap).
TEST(ReferenceOrder, GpuResortingFollowsTheReferencesWindow) {
  Renderer& renderer = testing::validated_renderer();
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  renderer.set_scene(scene);
  const Camera camera = playbot_view(240, 135);
  for (int window : {4, 8}) {
    const RenderSettings settings = colour_only(window);
    const ImageDifference d =
        compare_images(renderer.render(camera, settings), render_reference(scene, camera, settings));
    std::printf("resort%d: GPU against the reference's window %.1f dB, max abs %.2e\n", window, d.psnr_db,
                d.max_abs);
    EXPECT_GE(d.psnr_db, 70.0) << "resort" << window;
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// The re-sorting composite's two layouts (a pixel an invocation as on GPUs, a 16-pixel column as on
// CPU drivers) offer every pixel the same splats in the same order: the same image bit for bit,
// depth and splat counts included, with every window slot in use.
TEST(ReferenceOrder, GpuResortingLayoutsAgreeBitForBit) {
  RenderSettings settings;
  settings.accuracy.resort_window = 16;
  testing::expect_composite_layouts_identical(load_scene(testing::bundled_playbot()), playbot_view(240, 135),
                                              settings);
}

// Centre-depth order is 32 dB from the exact ray order on playbot; a window of 16 comes within 40 dB.
TEST(ReferenceOrder, TheWindowApproachesTheExactRayOrder) {
  Renderer& renderer = testing::validated_renderer();
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  renderer.set_scene(scene);
  const Camera camera = playbot_view(480, 270);
  const RenderImage exact = render_reference(scene, camera, colour_only(0), ReferenceOrder::kRayDepth);
  double previous = 0;
  for (int window : {0, 4, 16}) {
    const double psnr = compare_images(renderer.render(camera, colour_only(window)), exact).psnr_db;
    std::printf("window %d against the exact ray order: %.1f dB\n", window, psnr);
    EXPECT_GT(psnr, previous) << "window " << window;
    previous = psnr;
  }
  EXPECT_GE(previous, 40.0);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(ReferenceOrder, TheExactOrderNeedsPinholeRaysAndTileLists) {
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  Camera fisheye = playbot_view(32, 32);
  fisheye.model = CameraModel::kFisheye;
  EXPECT_THROW(render_reference(scene, fisheye, {}, ReferenceOrder::kRayDepth), std::invalid_argument);
  RenderSettings raster;
  raster.compositor = Compositor::kRaster;
  EXPECT_THROW(render_reference(scene, playbot_view(32, 32), raster, ReferenceOrder::kRayDepth),
               std::invalid_argument);
  raster.accuracy.resort_window = 4;
  EXPECT_THROW(render_reference(scene, playbot_view(32, 32), raster), std::invalid_argument);
}

}  // namespace
}  // namespace tilesplat
