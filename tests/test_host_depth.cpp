// Splats inside a host's world: a host's depth image cuts the splats (only those in front of its
// opaque surface blend), and the depth where their alpha reaches a threshold comes back in the host's
// convention; the GPU held to the float64 reference.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "effects_report.h"
#include "process_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"

namespace {

using tilesplat::Camera;
using tilesplat::DepthConvention;
using tilesplat::HostDepth;
using tilesplat::RenderSettings;

// A Vulkan projection (glm::perspectiveRH_ZO with its y flipped) with near and far planes, column-major.
std::array<double, 16> vulkan_projection(double near, double far, bool reversed) {
  std::array<double, 16> p{};
  p[0] = 1;
  p[5] = -1;
  p[11] = -1;  // clip w = -z_view
  if (!reversed) {
    p[10] = far / (near - far);
    p[14] = far * near / (near - far);
  } else {  // reversed-Z, infinite far: d = near / z
    p[10] = 0;
    p[14] = near;
  }
  return p;
}

TEST(HostDepth, ConventionsOfTheProjectionsHostsUse) {
  const DepthConvention standard = DepthConvention::from_projection(vulkan_projection(0.1, 100, false));
  EXPECT_NEAR(standard.window_depth(0.1), 0.0, 1e-12);
  EXPECT_NEAR(standard.window_depth(100), 1.0, 1e-12);
  EXPECT_NEAR(standard.view_depth(standard.window_depth(7.5)), 7.5, 1e-9);
  EXPECT_EQ(standard.far_depth(), 1.0);
  const DepthConvention reversed = DepthConvention::from_projection(vulkan_projection(0.1, 0, true));
  EXPECT_NEAR(reversed.window_depth(0.1), 1.0, 1e-12);
  EXPECT_EQ(reversed.view_depth(0.0), std::numeric_limits<double>::infinity());  // the cleared far value
  EXPECT_EQ(reversed.far_depth(), 0.0);
  // OpenGL: NDC depth in [-1, 1], the depth buffer (window depth) in [0, 1].
  std::array<double, 16> gl = vulkan_projection(0.5, 50, false);
  gl[5] = 1;
  gl[10] = -(50 + 0.5) / (50 - 0.5);
  gl[14] = -2 * 50 * 0.5 / (50 - 0.5);
  const DepthConvention opengl = DepthConvention::from_projection(gl, tilesplat::ClipSpace::opengl());
  EXPECT_NEAR(opengl.window_depth(0.5), 0.0, 1e-12);
  EXPECT_NEAR(opengl.window_depth(50), 1.0, 1e-12);
  std::array<double, 16> orthographic = vulkan_projection(0.1, 100, false);
  orthographic[11] = 0;
  orthographic[15] = 1;
  EXPECT_NE(tilesplat::testing::error_of<std::invalid_argument>([&] {
              DepthConvention::from_projection(orthographic);
            }).find("not a pinhole"),
            std::string::npos);
}

struct Views {
  tilesplat::GaussianScene scene;
  std::vector<Camera> cameras;
};
const Views& playbot_views() {
  static const Views views = [] {
    Views v;
    v.scene = tilesplat::load_scene(tilesplat::testing::bundled_playbot());
    const auto all = tilesplat::load_cameras_json(tilesplat::testing::bundled_playbot_cameras());
    for (int view : {0, 3})
      v.cameras.push_back(tilesplat::resize_camera(all.at(size_t(view)).camera, 480, 270));
    return v;
  }();
  return views;
}

// A host's wall through the scene (the effects bench's plane, tilted 35 degrees about the camera's y).
std::vector<float> tilted_plane(const Views& views, const Camera& camera, const DepthConvention& convention) {
  return tilesplat::effects::plane_through_scene(views.scene, camera, convention);
}

TEST(HostDepth, TiltedPlaneThroughARealSceneMatchesTheReference) {
  const Views& views = playbot_views();
  auto& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(views.scene);
  const DepthConvention convention = DepthConvention::from_projection(vulkan_projection(0.05, 200, false));
  for (const Camera& camera : views.cameras) {
    const std::vector<float> plane = tilted_plane(views, camera, convention);
    RenderSettings settings;
    settings.host = HostDepth{convention, plane, true, 0.5f};
    const tilesplat::RenderImage gpu = renderer.render(camera, settings);
    const tilesplat::RenderImage reference = tilesplat::render_reference(views.scene, camera, settings);
    const tilesplat::ImageDifference difference = tilesplat::compare_images(gpu, reference);
    EXPECT_GE(difference.psnr_db, 60.0);
    tilesplat::testing::expect_matches_reference(gpu, reference, 2e-3, "host depth, a tilted plane");

    // The plane hides part of the scene: the cut image differs from the uncut one, and is darker.
    const tilesplat::RenderImage uncut = renderer.render(camera);
    EXPECT_GT(tilesplat::compare_images(gpu, uncut).max_abs, 0.1);
    double cut_alpha = 0, uncut_alpha = 0;
    for (size_t i = 0; i < gpu.pixels(); ++i)
      cut_alpha += gpu.rgba[4 * i + 3], uncut_alpha += uncut.rgba[4 * i + 3];
    EXPECT_LT(cut_alpha, 0.95 * uncut_alpha);

    // Depth out, in the host's convention: the splat's depth where alpha reached 0.5, else the plane.
    ASSERT_EQ(gpu.host_depth.size(), gpu.pixels());
    size_t reached = 0, differ = 0;
    for (size_t i = 0; i < gpu.pixels(); ++i) {
      if (gpu.host_depth[i] != plane[i]) ++reached;
      if (std::abs(gpu.host_depth[i] - reference.host_depth[i]) > 1e-6f) ++differ;
      EXPECT_LE(gpu.host_depth[i], plane[i])
          << "pixel " << i << ": the splats' surface lies behind the host's";
    }
    std::printf(
        "host depth, a tilted plane: PSNR %.1f dB, max abs %.2g (alpha %.2g); depth out reached at %zu of "
        "%zu "
        "pixels, %zu differ from the reference by more than 1e-6\n",
        difference.psnr_db, difference.max_abs, difference.max_abs_alpha, reached, gpu.pixels(), differ);
    EXPECT_GT(reached, gpu.pixels() / 20) << "too few pixels reach alpha 0.5 for the test to mean anything";
    // A pixel whose accumulated alpha passes 0.5 within float rounding of it may take its depth from the
    // next splat on the GPU: one pixel in 10,000 at most (none on Mesa 22's lavapipe, 1 on Mesa 25's).
    EXPECT_LE(differ, gpu.pixels() / 10000)
        << "pixels whose depth out differs from the reference by more than float rounding";
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// Radial sorting (AccuracyModes::SortDepth::kDistance) blends in distance order, where a splat behind the
// host's surface may come before one in front of it: no pixel may stop at the first splat behind it, and
// the cut image and its depth out stay the reference's in the same order.
TEST(HostDepth, RadialSortingTestsEverySplatAgainstTheSurface) {
  const Views& views = playbot_views();
  auto& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(views.scene);
  const DepthConvention convention = DepthConvention::from_projection(vulkan_projection(0.05, 200, false));
  const Camera& camera = views.cameras.front();
  const std::vector<float> plane = tilted_plane(views, camera, convention);
  RenderSettings settings;
  settings.accuracy.sort_depth = tilesplat::AccuracyModes::SortDepth::kDistance;
  settings.host = HostDepth{convention, plane, true, 0.5f};
  const tilesplat::RenderImage gpu = renderer.render(camera, settings);
  const tilesplat::RenderImage reference = tilesplat::render_reference(views.scene, camera, settings);
  tilesplat::testing::expect_matches_reference(gpu, reference, 2e-3, "host depth, radial sorting");
  size_t differ = 0;
  for (size_t i = 0; i < gpu.pixels(); ++i)
    if (std::abs(gpu.host_depth[i] - reference.host_depth[i]) > 1e-6f) ++differ;
  EXPECT_LE(differ, gpu.pixels() / 10000) << "pixels whose depth out differs from the reference";
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// An OpenGL projection (y up, NDC depth in [-1, 1]) with near and far planes, column-major.
std::array<double, 16> opengl_projection(double near, double far) {
  std::array<double, 16> p = vulkan_projection(near, far, false);
  p[5] = 1;
  p[10] = -(far + near) / (far - near);
  p[14] = -2 * far * near / (far - near);
  return p;
}

// The same tilted wall given in the depth conventions hosts use besides the standard one: reversed-Z
// with an infinite far plane (near ones), and OpenGL's [-1, 1] clip space. Each is rendered against
// the float64 reference with the same depth image, its depth out is the reference's in that convention
// and lies on the camera's side of the wall (larger depth values are nearer in reversed-Z), and the
// colours are the standard convention's but where float rounding moves the wall across a splat.
TEST(HostDepth, ReversedZAndOpenGlWallsMatchTheReference) {
  const Views& views = playbot_views();
  auto& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(views.scene);
  const Camera& camera = views.cameras[0];
  const DepthConvention standard = DepthConvention::from_projection(vulkan_projection(0.05, 200, false));
  const std::vector<float> standard_plane = tilted_plane(views, camera, standard);
  RenderSettings standard_settings;
  standard_settings.host = HostDepth{standard, standard_plane, true, 0.5f};
  const tilesplat::RenderImage standard_image = renderer.render(camera, standard_settings);
  const tilesplat::RenderImage uncut = renderer.render(camera);

  struct Case {
    const char* name;
    DepthConvention convention;
    bool nearer_is_larger;
  };
  const Case cases[] = {
      {"reversed-Z", DepthConvention::from_projection(vulkan_projection(0.05, 0, true)), true},
      // Other planes than the standard case's: with the same ones, OpenGL's window depth equals Vulkan's.
      {"OpenGL",
       DepthConvention::from_projection(opengl_projection(0.1, 100), tilesplat::ClipSpace::opengl()), false},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::vector<float> plane = tilted_plane(views, camera, c.convention);
    ASSERT_NE(plane, standard_plane) << "the convention should change the depth values";
    RenderSettings settings;
    settings.host = HostDepth{c.convention, plane, true, 0.5f};
    const tilesplat::RenderImage gpu = renderer.render(camera, settings);
    const tilesplat::RenderImage reference = tilesplat::render_reference(views.scene, camera, settings);
    const tilesplat::ImageDifference difference = tilesplat::compare_images(gpu, reference);
    EXPECT_GE(difference.psnr_db, 60.0);
    EXPECT_LE(difference.max_abs, 2e-3) << "at (" << difference.worst_x << ", " << difference.worst_y << ")";
    EXPECT_GT(tilesplat::compare_images(gpu, uncut).max_abs, 0.1) << "the wall should hide part of the scene";

    size_t colour_moved = 0, reached = 0, differ = 0;
    for (size_t i = 0; i < gpu.pixels(); ++i) {
      for (size_t k = 0; k < 4; ++k)
        if (std::abs(gpu.rgba[4 * i + k] - standard_image.rgba[4 * i + k]) > 1e-3f) {
          ++colour_moved;
          break;
        }
      reached += gpu.host_depth[i] != plane[i];
      differ += std::abs(gpu.host_depth[i] - reference.host_depth[i]) > 1e-6f * std::max(1.0f, plane[i]);
      if (c.nearer_is_larger)
        EXPECT_GE(gpu.host_depth[i], plane[i]) << "pixel " << i;
      else
        EXPECT_LE(gpu.host_depth[i], plane[i]) << "pixel " << i;
    }
    std::printf(
        "host depth, %s wall: PSNR %.1f dB, max abs %.2g; %zu of %zu pixels differ from the standard "
        "convention's by more than 1e-3; depth out reached at %zu\n",
        c.name, difference.psnr_db, difference.max_abs, colour_moved, gpu.pixels(), reached);
    EXPECT_LE(colour_moved, gpu.pixels() / 200);
    EXPECT_GT(reached, gpu.pixels() / 20);
    EXPECT_EQ(differ, 0u);
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(HostDepth, SurfaceInFrontOfEverySplatLeavesExactlyNothing) {
  const Views& views = playbot_views();
  auto& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(views.scene);
  const DepthConvention convention = DepthConvention::from_projection(vulkan_projection(0.001, 100, false));
  const Camera& camera = views.cameras[0];
  // A wall at view depth 0.01, nearer than the renderer's near plane (0.2): no splat is in front of it.
  const std::vector<float> wall(size_t(camera.width) * size_t(camera.height),
                                float(convention.window_depth(0.01)));
  RenderSettings settings;
  settings.host = HostDepth{convention, wall, true, 0.5f};
  const tilesplat::RenderImage image = renderer.render(camera, settings);
  for (size_t i = 0; i < image.rgba.size(); ++i) ASSERT_EQ(image.rgba[i], 0.0f) << "value " << i;
  for (size_t i = 0; i < image.pixels(); ++i) {
    ASSERT_EQ(image.splat_count[i], 0u);
    ASSERT_EQ(image.host_depth[i], wall[i]);  // the host's own depth where the splats never reach
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(HostDepth, ClearedFarDepthChangesNothing) {
  const Views& views = playbot_views();
  auto& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(views.scene);
  const Camera& camera = views.cameras[1];
  const tilesplat::RenderImage plain = renderer.render(camera);
  // Reversed-Z with an infinite far plane, cleared to 0: every splat is in front of it.
  const DepthConvention convention = DepthConvention::from_projection(vulkan_projection(0.1, 0, true));
  const std::vector<float> cleared(size_t(camera.width) * size_t(camera.height), 0.0f);
  RenderSettings settings;
  settings.host = HostDepth{convention, cleared, true, 0.5f};
  const tilesplat::RenderImage with_host = renderer.render(camera, settings);
  EXPECT_TRUE(with_host.rgba == plain.rgba);
  EXPECT_TRUE(with_host.depth == plain.depth);
  EXPECT_TRUE(with_host.splat_count == plain.splat_count);
  // Depth out without a depth image in: the splats' median depth, or the far value.
  settings.host->depth = {};
  const tilesplat::RenderImage out_only = renderer.render(camera, settings);
  const tilesplat::RenderImage reference = tilesplat::render_reference(views.scene, camera, settings);
  EXPECT_TRUE(out_only.rgba == plain.rgba);
  size_t far = 0, differ = 0;
  for (size_t i = 0; i < out_only.pixels(); ++i) {
    far += out_only.host_depth[i] == 0.0f ? 1u : 0u;
    differ += std::abs(out_only.host_depth[i] - reference.host_depth[i]) > 1e-6f ? 1u : 0u;
  }
  EXPECT_GT(far, 0u);
  EXPECT_LT(far, out_only.pixels());
  EXPECT_LE(differ, out_only.pixels() / 10000);  // the threshold within float rounding, as above
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(HostDepth, EveryCompositeLayoutAgreesBitForBit) {
  const Views& views = playbot_views();
  const Camera& camera = views.cameras[0];
  const DepthConvention convention = DepthConvention::from_projection(vulkan_projection(0.05, 200, false));
  const std::vector<float> plane = tilted_plane(views, camera, convention);
  RenderSettings settings;
  settings.host = HostDepth{convention, plane, true, 0.5f};
  tilesplat::testing::expect_composite_layouts_identical(views.scene, camera, settings);
}

TEST(HostDepth, InvalidDepthImagesAndSettingsAreClearErrors) {
  const Views& views = playbot_views();
  auto& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(views.scene);
  const Camera& camera = views.cameras[0];
  const DepthConvention convention = DepthConvention::from_projection(vulkan_projection(0.05, 200, false));
  std::vector<float> depth(size_t(camera.width) * size_t(camera.height), 0.5f);
  RenderSettings settings;
  auto gpu_and_reference = [&](const std::string& expected) {
    EXPECT_NE(tilesplat::testing::error_of<std::invalid_argument>([&] {
                renderer.render(camera, settings);
              }).find(expected),
              std::string::npos)
        << expected;
    EXPECT_NE(tilesplat::testing::error_of<std::invalid_argument>([&] {
                tilesplat::render_reference(views.scene, camera, settings);
              }).find(expected),
              std::string::npos)
        << expected;
  };
  const std::vector<float> short_image(100, 0.5f);
  settings.host = HostDepth{convention, short_image, false, 0.5f};
  gpu_and_reference("host depth: the depth image has 100 values, the camera's image 480x270 needs 129600");
  depth[481] = std::numeric_limits<float>::quiet_NaN();
  settings.host = HostDepth{convention, depth, false, 0.5f};
  gpu_and_reference("host depth: the depth image is NaN at pixel (1, 1)");
  depth[481] = 0.5f;
  settings.host = HostDepth{convention, depth, true, 0.0f};
  gpu_and_reference("alpha_threshold must be in (0, 1]");
  settings.host = HostDepth{convention, depth, false, 0.5f};
  settings.compositor = tilesplat::Compositor::kStochastic;
  gpu_and_reference("the stochastic compositor does not depth-test");
  settings.compositor = tilesplat::Compositor::kSorted;
  settings.host->convention.b = 0;
  gpu_and_reference("the depth convention must have finite a and b");
  // The renderer still renders after the errors.
  settings.host->convention = convention;
  EXPECT_EQ(renderer.render(camera, settings).width, 480);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(HostDepth, EffectsTableHasTheHostDepthRowBesideTheBase) {
  const auto result =
      tilesplat::testing::run_process("", TILESPLAT_BENCH_EXE,
                                      {tilesplat::testing::bundled_sh3().string(), "--effects", "--width",
                                       "64", "--height", "36", "--warmup", "0", "--repeat", "1"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("host depth in + out (a plane through the scene)"), std::string::npos)
      << result.out;
  EXPECT_NE(result.out.find("base (all off, SH3)"), std::string::npos) << result.out;  // no host depth
  EXPECT_EQ(result.err.find("validation messages"), std::string::npos) << result.err;
}

}  // namespace
