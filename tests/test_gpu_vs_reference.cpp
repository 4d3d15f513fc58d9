// The GPU pipeline against the engine's float64 CPU reference, and against the independent reference
// images in ../shared/scenes/reference, on real trained scenes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <stdexcept>
#include <string>

#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

constexpr int kWidth = 480, kHeight = 270;  // the size of the independent references

struct SceneCase {
  std::string name;  // file stem, also the cameras/ and reference/ name
  bool bundled;
};

std::filesystem::path scene_path(const SceneCase& c) {
  if (c.name == "playbot_lod3_31000_sh2" && c.bundled) return testing::bundled_playbot();
  if (c.name == "playcanvas_test_64_sh3" && c.bundled) return testing::bundled_sh3();
  return testing::shared_scenes() / (c.name + ".ply");
}
std::filesystem::path cameras_path(const SceneCase& c) {
  if (c.name == "playbot_lod3_31000_sh2" && c.bundled) return testing::bundled_playbot_cameras();
  if (c.name == "playcanvas_test_64_sh3" && c.bundled) return testing::bundled_sh3_cameras();
  return testing::shared_scenes() / "cameras" / (c.name + ".json");
}

void expect_all_finite(const RenderImage& image) {
  size_t bad = 0;
  for (float v : image.rgba) bad += !std::isfinite(v);
  for (float v : image.depth) bad += !std::isfinite(v);
  EXPECT_EQ(bad, 0u) << "non-finite output values";
}

class GpuVsReference : public ::testing::TestWithParam<SceneCase> {};

TEST_P(GpuVsReference, TwoViewsMatchFloat64Reference) {
  const SceneCase& c = GetParam();
  if (!c.bundled) TILESPLAT_REQUIRE_SHARED_SCENES();
  GaussianScene scene = load_scene(scene_path(c));
  auto views = load_cameras_json(cameras_path(c));
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  for (int view : {0, 3}) {
    Camera camera = resize_camera(views.at(size_t(view)).camera, kWidth, kHeight);
    RenderImage gpu = renderer.render(camera);
    RenderImage ref = render_reference(scene, camera);
    expect_all_finite(gpu);
    ImageDifference d = compare_images(gpu, ref);
    std::printf("[ measure  ] %s view %d: GPU vs float64 reference PSNR %.2f dB, max abs %.2e (alpha %.2e)\n",
                c.name.c_str(), view, d.psnr_db, d.max_abs, d.max_abs_alpha);
    EXPECT_GE(d.psnr_db, 60.0) << c.name << " view " << view;
    // Within 2e-3 wherever both blended the same splats; a cut-off decision that float rounding flips
    // (a few pixels on some drivers) changes a pixel by one splat (testing::expect_matches_reference).
    testing::expect_matches_reference(gpu, ref, 2e-3, c.name + " view " + std::to_string(view));

    // Splat counts and depth agree with the reference wherever both blended the same splats.
    size_t count_mismatch = 0;
    for (size_t i = 0; i < gpu.pixels(); ++i) count_mismatch += gpu.splat_count[i] != ref.splat_count[i];
    EXPECT_LE(double(count_mismatch), 1e-3 * double(gpu.pixels())) << "per-pixel splat counts differ";

    const auto reference_exr = testing::shared_scenes() / "reference" / (c.name + "_view" + std::to_string(view) + ".exr");
    if (!testing::shared_scenes().empty() && std::filesystem::exists(reference_exr)) {
      ImageDifference ind = compare_images(gpu, read_exr(reference_exr));
      std::printf("[ measure  ] %s view %d: GPU vs independent reference PSNR %.2f dB, max abs %.2e\n",
                  c.name.c_str(), view, ind.psnr_db, ind.max_abs);
      EXPECT_GE(ind.psnr_db, 50.0) << c.name << " view " << view;
    } else if (testing::skips_forbidden()) {
      ADD_FAILURE() << "no independent reference " << reference_exr << " (TILESPLAT_NO_SKIPS is set)";
    } else {
      // Said, not silent: the bundled cases run without ../shared, but then only against the float64
      // reference.
      std::printf("[ skipped  ] %s view %d: the check against the independent reference (no %s)\n",
                  c.name.c_str(), view, reference_exr.string().c_str());
    }
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

INSTANTIATE_TEST_SUITE_P(RealScenes, GpuVsReference,
                         ::testing::Values(SceneCase{"playbot_lod3_31000_sh2", true},
                                           SceneCase{"playcanvas_test_64_sh3", true},
                                           SceneCase{"playbot_lod6_1873_sh2", false},
                                           SceneCase{"guitar_90854_sh0", false},
                                           SceneCase{"plant_113648_sh0", false},
                                           SceneCase{"biker_152746_sh0", false}),
                         [](const auto& param_info) { return param_info.param.name + (param_info.param.bundled ? "_bundled" : ""); });

TEST(GpuRenderer, EmptySceneIsBackground) {
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(GaussianScene{});
  Camera camera = look_at_camera({0, 0, -5}, {0, 0, 0}, {0, -1, 0}, 37, 21, 50);
  RenderSettings settings;
  settings.background = {0.25f, 0.5f, 0.75f};
  RenderImage image = renderer.render(camera, settings);
  ASSERT_EQ(image.pixels(), 37u * 21u);
  for (size_t i = 0; i < image.pixels(); ++i) {
    ASSERT_EQ(image.rgba[4 * i + 0], 0.25f);
    ASSERT_EQ(image.rgba[4 * i + 1], 0.5f);
    ASSERT_EQ(image.rgba[4 * i + 2], 0.75f);
    ASSERT_EQ(image.rgba[4 * i + 3], 0.0f);
    ASSERT_EQ(image.splat_count[i], 0u);
  }
  EXPECT_EQ(renderer.last_frame_stats().intersections, 0u);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(GpuRenderer, GrowsKeyBuffersWhenIntersectionsExceedCapacity) {
  // A few huge splats near the camera touch every tile of a large image: far more intersections
  // than the initial capacity (4 per Gaussian, at least 65536), forcing a grow-and-retry.
  GaussianScene scene;
  scene.sh_degree = 0;
  for (int i = 0; i < 40; ++i) {
    scene.positions.insert(scene.positions.end(), {0.01f * float(i), 0.0f, 2.0f + 0.01f * float(i)});
    scene.log_scales.insert(scene.log_scales.end(), {1.0f, 1.0f, 1.0f});
    scene.rotations.insert(scene.rotations.end(), {1, 0, 0, 0});
    scene.opacity_logits.push_back(-3.0f);
    scene.sh.insert(scene.sh.end(), {0.5f, 0.2f, -0.3f});
  }
  Camera camera = look_at_camera({0, 0, 0}, {0, 0, 1}, {0, -1, 0}, 1280, 960, 60);
  // A renderer of its own: the shared one keeps the key buffers earlier tests grew, and then
  // nothing would overflow here.
  RendererOptions options;
  options.validation = true;
  const auto owned = Renderer::create(options);
  Renderer& renderer = *owned;
  renderer.set_scene(scene);
  RenderImage gpu = renderer.render(camera);
  const FrameStats& stats = renderer.last_frame_stats();
  EXPECT_GE(stats.retries, 1);
  EXPECT_EQ(stats.intersections, 40u * 80u * 60u);
  RenderImage ref = render_reference(scene, camera);
  ImageDifference d = compare_images(gpu, ref);
  EXPECT_GE(d.psnr_db, 60.0);
  EXPECT_LE(d.max_abs, 2e-3);
  // A second frame reuses the grown buffers.
  renderer.render(camera);
  EXPECT_EQ(renderer.last_frame_stats().retries, 0);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(GpuRenderer, EqualDepthsBlendInGaussianIndexOrder) {
  // 3000 overlapping splats at exactly the same view depth, with colours that differ from one to the
  // next: the frame sorts by depth and then by tile, and only ties broken by Gaussian index in both
  // (as the reference does) give the reference's image. Any other tie order changes the colours by
  // far more than the bound.
  GaussianScene scene;
  scene.sh_degree = 0;
  for (int i = 0; i < 3000; ++i) {
    const float x = float((i * 37) % 101) / 101.0f - 0.5f, y = float((i * 53) % 89) / 89.0f - 0.5f;
    scene.positions.insert(scene.positions.end(), {x, y, 3.0f});
    scene.log_scales.insert(scene.log_scales.end(), {-2.5f, -2.0f, -2.2f});
    scene.rotations.insert(scene.rotations.end(), {1, 0, 0, 0});
    scene.opacity_logits.push_back(1.0f);
    scene.sh.insert(scene.sh.end(), {float(i % 3) - 1.0f, float(i % 5) * 0.4f - 0.8f, float(i % 7) * 0.3f - 0.9f});
  }
  Camera camera = look_at_camera({0, 0, 0}, {0, 0, 1}, {0, -1, 0}, 200, 150, 40);
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  RenderImage gpu = renderer.render(camera);
  EXPECT_GT(renderer.last_frame_stats().intersections, 3000u);  // splats span several tiles
  RenderImage ref = render_reference(scene, camera);
  ImageDifference d = compare_images(gpu, ref);
  EXPECT_GE(d.psnr_db, 60.0);
  EXPECT_LE(d.max_abs, 2e-3);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(GpuRenderer, NearPlaneCullsWhereTheSettingSaysOnTheGpuAndInTheReference) {
  // Splats from 0.15 to 3 in front of the camera: the default near plane (0.2) culls the first ones,
  // a near plane of 1.27 also every splat up to 1.25, 0.01 (gsplat's default) none.
  GaussianScene scene;
  scene.sh_degree = 0;
  for (int i = 0; i < 60; ++i) {
    const float z = 0.15f + 0.05f * float(i);
    const float x = 0.04f * float(i % 7) - 0.12f, y = 0.03f * float(i % 5) - 0.06f;
    scene.positions.insert(scene.positions.end(), {x * z, y * z, z});
    scene.log_scales.insert(scene.log_scales.end(), {-3.5f, -3.2f, -3.4f});
    scene.rotations.insert(scene.rotations.end(), {1, 0, 0, 0});
    scene.opacity_logits.push_back(0.5f);
    scene.sh.insert(scene.sh.end(), {float(i % 3) - 1.0f, float(i % 4) * 0.5f - 0.7f, 0.3f});
  }
  const Camera camera = look_at_camera({0, 0, 0}, {0, 0, 1}, {0, -1, 0}, 160, 120, 60);
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  RenderSettings settings;
  std::vector<uint64_t> visible;
  std::vector<RenderImage> images;
  for (const double near_plane : {kDefaultNearPlane, 1.27, 0.01}) {
    settings.near_plane = near_plane;
    images.push_back(renderer.render(camera, settings));
    visible.push_back(renderer.last_frame_stats().visible);
    const RenderImage ref = render_reference(scene, camera, settings);
    const ImageDifference d = compare_images(images.back(), ref);
    EXPECT_GE(d.psnr_db, 60.0) << "near plane " << near_plane;
    EXPECT_EQ(project_gaussian(scene, 0, camera, Antialiasing::kClassic, {}, near_plane).visible,
              near_plane < 0.15);
  }
  EXPECT_EQ(visible[0], 59u);  // the splat at 0.15
  EXPECT_EQ(visible[1], 37u);  // and those at 0.2 .. 1.25
  EXPECT_EQ(visible[2], 60u);
  EXPECT_LT(compare_images(images[0], images[1]).psnr_db, 40.0);
  // The default is the setting's default: the same frame to the bit.
  EXPECT_EQ(renderer.render(camera).rgba, images[0].rgba);
  for (const double bad : {0.0, -1.0, std::nan("")}) {
    settings.near_plane = bad;
    EXPECT_THROW(renderer.render(camera, settings), std::invalid_argument) << bad;
    EXPECT_THROW(render_reference(scene, camera, settings), std::invalid_argument) << bad;
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(GpuRenderer, MaxAlphaCapsEachSplatOnTheGpuAndInTheReference) {
  // Nearly opaque splats (opacity 0.9997) side by side, overlapping at two depths: every pixel's alpha
  // comes from splats capped at max_alpha, 0.99 by default (the 3DGS trainer's) or 0.999 (gsplat's).
  GaussianScene scene;
  scene.sh_degree = 0;
  for (int i = 0; i < 5; ++i) {
    scene.positions.insert(scene.positions.end(), {0.25f * float(i - 2), 0.0f, 2.0f + 0.1f * float(i % 2)});
    scene.log_scales.insert(scene.log_scales.end(), {-1.2f, -1.4f, -1.6f});
    scene.rotations.insert(scene.rotations.end(), {1, 0, 0, 0});
    scene.opacity_logits.push_back(8.0f);
    scene.sh.insert(scene.sh.end(), {1.0f, float(i) * 0.3f - 0.6f, -0.5f});
  }
  // One wide splat alone: its pixels near the centre would have alpha 0.9996, above either cap.
  GaussianScene lone;
  lone.sh_degree = 0;
  lone.positions = {0, 0, 2};
  lone.log_scales = {0, 0, 0};
  lone.rotations = {1, 0, 0, 0};
  lone.opacity_logits = {12.0f};
  lone.sh = {0.5f, 0.5f, 0.5f};
  const auto max_alpha_of = [](const RenderImage& image) {
    float most = 0;
    for (size_t i = 3; i < image.rgba.size(); i += 4) most = std::max(most, image.rgba[i]);
    return most;
  };
  const Camera camera = look_at_camera({0, 0, 0}, {0, 0, 1}, {0, -1, 0}, 128, 64, 60);
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  RenderSettings settings;
  const RenderImage by_default = renderer.render(camera, settings);
  for (const double max_alpha : {kDefaultMaxAlpha, 0.999, 0.5}) {
    settings.max_alpha = max_alpha;
    renderer.set_scene(scene);
    const RenderImage gpu = renderer.render(camera, settings);
    const ImageDifference d = compare_images(gpu, render_reference(scene, camera, settings));
    EXPECT_GE(d.psnr_db, 60.0) << "max_alpha " << max_alpha;
    float alpha_change = 0;  // the cap changes the image where splats reach it
    for (size_t i = 3; i < gpu.rgba.size(); i += 4)
      alpha_change = std::max(alpha_change, std::abs(gpu.rgba[i] - by_default.rgba[i]));
    EXPECT_GE(alpha_change, max_alpha == kDefaultMaxAlpha ? 0.0f : 0.001f) << max_alpha;
    EXPECT_LE(alpha_change, max_alpha == kDefaultMaxAlpha ? 0.0f : 1.0f) << max_alpha;

    renderer.set_scene(lone);
    EXPECT_FLOAT_EQ(max_alpha_of(renderer.render(camera, settings)), float(max_alpha));
    EXPECT_NEAR(max_alpha_of(render_reference(lone, camera, settings)), max_alpha, 1e-6);
    RenderSettings resorted = settings;  // the per-pixel re-sort composite caps alike
    resorted.accuracy.resort_window = 4;
    EXPECT_FLOAT_EQ(max_alpha_of(renderer.render(camera, resorted)), float(max_alpha));
  }
  renderer.set_scene(scene);
  settings.max_alpha = kDefaultMaxAlpha;
  EXPECT_EQ(renderer.render(camera, settings).rgba, by_default.rgba);  // the default, to the bit
  for (const double bad : {0.0, 1.0 / 255.0, 1.0, 1.5, std::nan("")}) {
    settings.max_alpha = bad;
    EXPECT_THROW(renderer.render(camera, settings), std::invalid_argument) << bad;
    EXPECT_THROW(render_reference(scene, camera, settings), std::invalid_argument) << bad;
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(GpuRenderer, ReportsPassTimingsAndCounts) {
  Renderer& renderer = testing::validated_renderer();
  GaussianScene scene = load_scene(testing::bundled_playbot());
  renderer.set_scene(scene);
  Camera camera = resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(0).camera, 320, 180);
  renderer.render(camera);
  const FrameStats& stats = renderer.last_frame_stats();
  std::vector<std::string> names;
  for (const auto& p : stats.passes) names.push_back(p.name);
  EXPECT_EQ(names, (std::vector<std::string>{"projection", "depth_sort", "prefix_sum", "key_emission", "tile_sort",
                                             "tile_ranges", "composite"}));
  EXPECT_GT(stats.gpu_ms, 0.0);
  EXPECT_EQ(stats.gaussians, scene.size());
  EXPECT_GT(stats.visible, scene.size() / 2);
  EXPECT_GE(stats.intersections, stats.visible);
  EXPECT_EQ(stats.sort_bits, 32u + 8u);  // 20 x 12 = 240 tiles -> 8 tile bits

  // Only tiles the alpha >= 1/255 ellipse reaches are emitted: fewer than the reference rects hold
  // (the images are identical, as the comparisons above show).
  uint64_t rect_intersections = 0;
  for (size_t i = 0; i < scene.size(); ++i) {
    ProjectedGaussian p = project_gaussian(scene, i, camera);
    if (p.visible)
      rect_intersections += uint64_t(p.tile_max[0] - p.tile_min[0]) * uint64_t(p.tile_max[1] - p.tile_min[1]);
  }
  std::printf("[ measure  ] intersections: %llu emitted, %llu in the reference rects\n",
              static_cast<unsigned long long>(stats.intersections), static_cast<unsigned long long>(rect_intersections));
  EXPECT_LT(stats.intersections, rect_intersections);
}

TEST(GpuRenderer, RejectsImpossibleImageSizes) {
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(load_scene(testing::bundled_sh3()));
  Camera camera = look_at_camera({0, 0, -5}, {0, 0, 0}, {0, -1, 0}, 16, 16, 50);
  camera.width = 0;
  EXPECT_THROW(renderer.render(camera), std::runtime_error);
  camera.width = 2'000'000;
  camera.height = 16;
  try {
    renderer.render(camera);
    ADD_FAILURE() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("2000000x16"), std::string::npos) << e.what();
  }
  RenderSettings bad_sort;
  bad_sort.sort = "no-such-sort";
  camera.width = 16;
  EXPECT_THROW(renderer.render(camera, bad_sort), std::invalid_argument);
}

}  // namespace
}  // namespace tilesplat

namespace tilesplat {
namespace {

// The composite picks a 16-pixel column per invocation on CPU drivers and one pixel per invocation
// on GPUs. Both layouts must give bit-identical images; this runs the GPU layout on lavapipe.
TEST(GpuRenderer, CompositeLayoutsGiveIdenticalImages) {
  GaussianScene scene = load_scene(testing::bundled_playbot());
  Camera camera = resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(2).camera, 333, 187);
  testing::expect_composite_layouts_identical(scene, camera);
}

// The layout overrides are read when the renderer is made; a value they do not know is an error
// naming the variable, not a silent default.
TEST(GpuRenderer, LayoutOverridesRejectUnknownValues) {
  ::setenv("TILESPLAT_TEXEL_BUFFERS", "yes", 1);
  const std::string texel = testing::error_of<std::invalid_argument>([] { Renderer::create({}); });
  ::unsetenv("TILESPLAT_TEXEL_BUFFERS");
  EXPECT_EQ(texel, "TILESPLAT_TEXEL_BUFFERS must be 0 or 1, got 'yes'");
  ::setenv("TILESPLAT_COMPOSITE_PIXELS", "3", 1);
  const std::string pixels = testing::error_of<std::invalid_argument>([] { Renderer::create({}); });
  ::unsetenv("TILESPLAT_COMPOSITE_PIXELS");
  EXPECT_EQ(pixels, "TILESPLAT_COMPOSITE_PIXELS must be 1, 2, 4, 8 or 16, got '3'");
}

}  // namespace
}  // namespace tilesplat

namespace tilesplat {
namespace {

// The antialiasing modes (a scene effect): the GPU matches the float64 reference in each, and each
// mode changes the image the way its formula says.
class AntialiasingVsReference : public ::testing::TestWithParam<Antialiasing> {};

TEST_P(AntialiasingVsReference, MatchesFloat64Reference) {
  GaussianScene scene = load_scene(testing::bundled_playbot());
  auto views = load_cameras_json(testing::bundled_playbot_cameras());
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  RenderSettings settings;
  settings.antialiasing = GetParam();
  for (int view : {0, 3}) {
    // Small images: Mip-Splatting's filter matters most where splats are a pixel or less.
    Camera camera = resize_camera(views.at(size_t(view)).camera, 160, 90);
    RenderImage gpu = renderer.render(camera, settings);
    RenderImage ref = render_reference(scene, camera, settings);
    expect_all_finite(gpu);
    ImageDifference d = compare_images(gpu, ref);
    std::printf("[ measure  ] antialiasing %s view %d: GPU vs float64 reference PSNR %.2f dB, max abs %.2e\n",
                to_string(GetParam()).c_str(), view, d.psnr_db, d.max_abs);
    EXPECT_GE(d.psnr_db, 60.0) << to_string(GetParam()) << " view " << view;
    EXPECT_LE(d.max_abs, 2e-3) << to_string(GetParam()) << " view " << view;
    if (GetParam() != Antialiasing::kClassic) {
      // The mode must change the image: classic and this mode differ by far more than the GPU error.
      RenderSettings classic = settings;
      classic.antialiasing = Antialiasing::kClassic;
      ImageDifference vs_classic = compare_images(gpu, renderer.render(camera, classic));
      std::printf("[ measure  ] antialiasing %s view %d vs classic: PSNR %.2f dB\n", to_string(GetParam()).c_str(),
                  view, vs_classic.psnr_db);
      EXPECT_LT(vs_classic.psnr_db, d.psnr_db - 20.0);
    }
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Modes, AntialiasingVsReference,
                         ::testing::Values(Antialiasing::kClassic, Antialiasing::kAntialiased, Antialiasing::kMip),
                         [](const auto& param_info) { return to_string(param_info.param); });

TEST(ReferenceAntialiasing, CompensationAndDilationFollowTheFormulas) {
  // One isotropic Gaussian on the optical axis: its 2D covariance is s^2 f^2 / z^2 on the diagonal.
  GaussianScene scene;
  scene.positions = {0, 0, 2};
  const float s = 0.001f;
  scene.log_scales = {std::log(s), std::log(s), std::log(s)};
  scene.rotations = {1, 0, 0, 0};
  scene.opacity_logits = {2.0f};
  scene.sh = {0, 0, 0};
  Camera camera;
  camera.width = camera.height = 64;
  camera.fx = camera.fy = 1000;
  camera.cx = camera.cy = 32;
  const double var = std::pow(std::exp(double(scene.log_scales[0])) * 1000 / 2, 2);  // ~0.25 px^2
  const double opacity = 1 / (1 + std::exp(-2.0));
  const ProjectedGaussian classic = project_gaussian(scene, 0, camera, Antialiasing::kClassic);
  const ProjectedGaussian antialiased = project_gaussian(scene, 0, camera, Antialiasing::kAntialiased);
  const ProjectedGaussian mip = project_gaussian(scene, 0, camera, Antialiasing::kMip);
  EXPECT_NEAR(classic.cov2d[0], var + 0.3, 1e-9);
  EXPECT_NEAR(mip.cov2d[0], var + 0.1, 1e-9);
  EXPECT_NEAR(classic.opacity, opacity, 1e-12);
  // sqrt(det before / det after) = var / (var + dilation) for an isotropic footprint.
  EXPECT_NEAR(antialiased.opacity, opacity * var / (var + 0.3), 1e-9);
  EXPECT_NEAR(mip.opacity, opacity * var / (var + 0.1), 1e-9);
}

}  // namespace
}  // namespace tilesplat

namespace tilesplat {
namespace {

// llvmpipe ends a shader invocation after 65535 loop iterations, silently: one tile listing 70k faint
// pixel-sized splats (none saturates a pixel, so every one is blended) lost its last ~15k splats
// before the composite blended long lists in chunks (max abs 0.08). The GPU must blend them all.
// 70000 faint splats in front of a 16x16 camera: every one lands in its single tile.
GaussianScene one_crowded_tile(Camera& camera) {
  GaussianScene scene;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  camera = Camera{};
  camera.width = camera.height = 16;  // one tile
  camera.fx = camera.fy = 16;
  camera.cx = camera.cy = 8;
  for (int i = 0; i < 70000; ++i) {
    const float z = 1.f + unit(rng);
    const float px = 0.5f + 15.f * unit(rng), py = 0.5f + 15.f * unit(rng);
    scene.positions.insert(scene.positions.end(), {(px - 8.f) * z / 16.f, (py - 8.f) * z / 16.f, z});
    const float log_scale = std::log(0.01f * z / 16.f);
    scene.log_scales.insert(scene.log_scales.end(), {log_scale, log_scale, log_scale});
    scene.rotations.insert(scene.rotations.end(), {1, 0, 0, 0});
    scene.opacity_logits.push_back(std::log(0.02f / 0.98f));
    scene.sh.insert(scene.sh.end(), {unit(rng), unit(rng), unit(rng)});
  }
  return scene;
}

TEST(GpuRenderer, TileListsLongerThanTheCpuLoopLimitAreBlendedWhole) {
  Camera camera;
  const GaussianScene scene = one_crowded_tile(camera);
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  RenderImage gpu = renderer.render(camera);
  RenderImage ref = render_reference(scene, camera);
  uint64_t blended_gpu = 0, blended_ref = 0;
  for (size_t i = 0; i < gpu.pixels(); ++i) {
    blended_gpu += gpu.splat_count[i];
    blended_ref += ref.splat_count[i];
  }
  std::printf("[ measure  ] 70000 splats in one tile: blended %llu (reference %llu), %d re-render(s)\n",
              static_cast<unsigned long long>(blended_gpu), static_cast<unsigned long long>(blended_ref),
              renderer.last_frame_stats().retries);
  EXPECT_EQ(blended_gpu, blended_ref);
  EXPECT_GT(blended_ref, 200000u);  // the case really blends more than the limit's worth per invocation
  EXPECT_LE(compare_images(gpu, ref).max_abs, 1e-5);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// The composite's chunks (CPU drivers) follow the previous frame's longest list: one crowded frame
// must not leave every later sparse frame paying for its chunks and their per-pixel state (it once
// cost sparse 8192^2 frames 9x the time and 2.3x the memory), and a chunk retry re-runs the
// composite alone.
TEST(GpuRenderer, CompositeChunksFollowEachFrameAndReleaseTheirState) {
  Camera crowded_camera;
  const GaussianScene scene = one_crowded_tile(crowded_camera);
  RendererOptions options;
  options.validation = true;
  auto renderer = Renderer::create(options);
  renderer->set_scene(scene);
  RenderSettings settings;
  settings.reuse_lists = false;
  const RenderImage crowded = renderer->render(crowded_camera, settings);
  const FrameStats first = renderer->last_frame_stats();
  if (first.retries == 0) TILESPLAT_SKIP_OR_FAIL("this device blends any list in one dispatch (no chunks)");
  ASSERT_EQ(first.retries, 1);
  // The retried frame reports every pass it ran, the first attempt's included.
  const auto has_pass = [](const FrameStats& stats, const std::string& name) {
    return std::any_of(stats.passes.begin(), stats.passes.end(), [&](const PassTiming& p) { return p.name == name; });
  };
  EXPECT_TRUE(has_pass(first, "projection"));
  EXPECT_TRUE(has_pass(first, "tile_sort"));

  // A frame starts with the chunks the previous one needed (the next view is usually alike): the
  // first sparse frame still has them, the second not, nor their state.
  Camera empty_camera = crowded_camera;
  empty_camera.position = {1000, 0, 0};  // sees none of the splats
  renderer->render(empty_camera, settings);
  EXPECT_EQ(renderer->last_frame_stats().retries, 0);
  EXPECT_EQ(renderer->last_frame_stats().device_bytes, first.device_bytes);
  renderer->render(empty_camera, settings);
  const FrameStats sparse = renderer->last_frame_stats();
  EXPECT_EQ(sparse.retries, 0);
  EXPECT_EQ(first.device_bytes - sparse.device_bytes, 16u * 16u * 32u);  // the chunk state, released

  const RenderImage again = renderer->render(crowded_camera, settings);
  EXPECT_EQ(renderer->last_frame_stats().retries, 1);  // the chunks grew again, for this frame
  EXPECT_EQ(again.rgba, crowded.rgba);
  EXPECT_EQ(renderer->validation_messages(), 0u);
}

// An output a frame does not ask for is neither computed (a specialization constant) nor held.
TEST(GpuRenderer, OutputsNotAskedForHoldNoMemory) {
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(load_scene(testing::bundled_sh3()));
  const Camera camera = look_at_camera({0, -0.5, 2.5}, {0, 0, 0}, {0, -1, 0}, 64, 36, 45);
  RenderSettings all;
  renderer.render(camera, all);  // drops what an earlier test's frames left (composite chunk state)
  const RenderImage full = renderer.render(camera, all);
  const uint64_t with_both = renderer.last_frame_stats().device_bytes;
  RenderSettings colour_only;
  colour_only.depth = colour_only.splat_count = false;
  const RenderImage colour = renderer.render(camera, colour_only);
  const uint64_t with_none = renderer.last_frame_stats().device_bytes;
  EXPECT_EQ(with_both - with_none, 64u * 36u * 8u);  // a float depth and a uint count per pixel
  EXPECT_TRUE(colour.depth.empty());
  EXPECT_TRUE(colour.splat_count.empty());
  EXPECT_EQ(colour.rgba, full.rgba);
  RenderSettings depth_only = colour_only;
  depth_only.depth = true;
  const RenderImage depth = renderer.render(camera, depth_only);
  EXPECT_EQ(renderer.last_frame_stats().device_bytes, with_none + 64u * 36u * 4u);
  EXPECT_EQ(depth.depth, full.depth);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

}  // namespace
}  // namespace tilesplat
