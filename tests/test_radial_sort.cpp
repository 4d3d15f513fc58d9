// Radial sorting (AccuracyModes::SortDepth::kDistance): the depth sort keyed by each centre's distance
// from the camera instead of its view depth. A turn of the camera in place keeps every distance, so it
// keeps the order where view depth order swaps splats (the popping of a turning camera). The GPU keys
// and blends as the float64 reference does, scenes in parts follow the same order, and what has no
// distance to sort by (the orthographic camera) or sorts nothing (the stochastic compositor) refuses it.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
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

AccuracyModes radial() {
  AccuracyModes modes;
  modes.sort_depth = AccuracyModes::SortDepth::kDistance;
  return modes;
}

TEST(RadialSort, IsANamedAccuracyMode) {
  EXPECT_EQ(parse_accuracy_modes("radial"), radial());
  EXPECT_EQ(to_string(radial()), "radial");
  AccuracyModes both = radial();
  both.depth_key_bits = 24;
  EXPECT_EQ(to_string(both), "depth24+radial");
  EXPECT_EQ(parse_accuracy_modes("radial+depth24"), both);
  EXPECT_EQ(to_string(AccuracyModes{}), "reference");
  const std::string unknown =
      testing::error_of<std::invalid_argument>([] { parse_accuracy_modes("radiall"); });
  EXPECT_NE(unknown.find("radial,"), std::string::npos) << unknown;  // listed among the known tokens
}

// Two opaque-ish splats, red at A = (0, 0, 2) and blue at B = (0.6, 0, 1.95): B is nearer in view depth
// from a camera at the origin looking down +z, A nearer in distance (2 against 2.04). Turned in place to
// look at B, the view depths swap (A 1.91, B 2.04); the distances stay.
GaussianScene red_and_blue() {
  GaussianScene scene;
  const float c0 = 0.28209479f;  // the DC term's SH constant: colour = 0.5 + c0 * dc
  auto add = [&](std::array<float, 3> position, std::array<float, 3> colour) {
    scene.positions.insert(scene.positions.end(), position.begin(), position.end());
    scene.log_scales.insert(scene.log_scales.end(), 3, std::log(0.3f));
    scene.rotations.insert(scene.rotations.end(), {1.0f, 0.0f, 0.0f, 0.0f});
    scene.opacity_logits.push_back(3.0f);  // opacity 0.95
    for (float c : colour) scene.sh.push_back((c - 0.5f) / c0);
  };
  add({0.0f, 0.0f, 2.0f}, {1.0f, 0.0f, 0.0f});
  add({0.6f, 0.0f, 1.95f}, {0.0f, 0.0f, 1.0f});
  return scene;
}

// Whether red is in front at the pixel halfway between the two centres' images, where both splats are
// equally dense: the front one's colour dominates there.
bool red_in_front(const RenderImage& image, const Camera& camera, const GaussianScene& scene) {
  std::array<double, 2> middle = {0, 0};
  for (size_t i = 0; i < 2; ++i) {
    const std::array<double, 3> t =
        camera.to_camera({double(scene.positions[3 * i]), double(scene.positions[3 * i + 1]),
                          double(scene.positions[3 * i + 2])});
    middle[0] += 0.5 * (camera.fx * t[0] / t[2] + camera.cx);
    middle[1] += 0.5 * (camera.fy * t[1] / t[2] + camera.cy);
  }
  const size_t pixel = size_t(middle[1]) * size_t(image.width) + size_t(middle[0]);
  const float red = image.rgba[4 * pixel], blue = image.rgba[4 * pixel + 2];
  EXPECT_GT(std::abs(red - blue), 0.1f) << "both splats should cover the pixel, one clearly in front";
  return red > blue;
}

TEST(RadialSort, ATurnInPlaceKeepsTheOrderThatViewDepthSwaps) {
  Renderer& renderer = testing::validated_renderer();
  const GaussianScene scene = red_and_blue();
  renderer.set_scene(scene);
  const Camera ahead = look_at_camera({0, 0, 0}, {0, 0, 1}, {0, -1, 0}, 64, 64, 60);
  const Camera turned = look_at_camera({0, 0, 0}, {0.6, 0, 1.95}, {0, -1, 0}, 64, 64, 60);
  RenderSettings by_depth;
  RenderSettings by_distance;
  by_distance.accuracy = radial();
  for (const bool radial_order : {false, true})
    for (const bool is_turned : {false, true}) {
      const RenderSettings& settings = radial_order ? by_distance : by_depth;
      const Camera& camera = is_turned ? turned : ahead;
      const RenderImage gpu = renderer.render(camera, settings);
      const std::string what = std::string(radial_order ? "radial" : "view depth") +
                               (is_turned ? ", turned to the blue splat" : ", looking ahead");
      // View depth: blue (nearer in z) in front looking ahead, red once turned. Distance: red both times.
      EXPECT_EQ(red_in_front(gpu, camera, scene), radial_order || is_turned) << what;
      testing::expect_matches_reference(gpu, render_reference(scene, camera, settings), 2e-3, what);
    }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// The bundled playbot_lod3, read once for the tests that render it.
const GaussianScene& playbot() {
  static const GaussianScene scene = load_scene(testing::bundled_playbot());
  return scene;
}

RenderSettings radial_settings() {
  RenderSettings settings;
  settings.accuracy = radial();
  return settings;
}

Camera playbot_view(int width, int height) {
  return resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(0).camera, width, height);
}

// A trained scene: the GPU's radial image is the reference's, and not the view depth order's image. With
// 16-bit keys, quantized over the visible distances, it stays close to the 32-bit one.
TEST(RadialSort, GpuMatchesTheReferenceOnATrainedScene) {
  Renderer& renderer = testing::validated_renderer();
  const GaussianScene& scene = playbot();
  renderer.set_scene(scene);
  const Camera camera = playbot_view(240, 135);
  const RenderSettings settings = radial_settings();
  const RenderImage gpu = renderer.render(camera, settings);
  testing::expect_matches_reference(gpu, render_reference(scene, camera, settings), 2e-3, "radial");

  const ImageDifference against_depth_order = compare_images(gpu, renderer.render(camera, RenderSettings{}));
  std::printf("radial against view depth order: %.1f dB, max abs %.3f\n", against_depth_order.psnr_db,
              against_depth_order.max_abs);
  EXPECT_GT(against_depth_order.max_abs, 0.05) << "the order should change some pixels";

  RenderSettings quantized = settings;
  quantized.accuracy.depth_key_bits = 16;
  const ImageDifference d16 = compare_images(renderer.render(camera, quantized), gpu);
  std::printf("depth16+radial against radial: %.1f dB\n", d16.psnr_db);
  EXPECT_GE(d16.psnr_db, 40.0);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// The OpenCV camera's order changes like the pinhole's; the fisheye's and the panorama's were already by
// distance, so radial leaves their images as they were.
TEST(RadialSort, FollowsTheCameraModels) {
  Renderer& renderer = testing::validated_renderer();
  const GaussianScene& scene = playbot();
  renderer.set_scene(scene);
  const Camera pinhole = playbot_view(160, 90);
  Camera opencv = pinhole;
  opencv.model = CameraModel::kOpenCV;
  opencv.distortion = {0.05, -0.01, 0.001, 0.0005};
  const RenderSettings settings = radial_settings();
  testing::expect_matches_reference(renderer.render(opencv, settings),
                                    render_reference(scene, opencv, settings), 2e-3, "radial, OpenCV camera");
  for (const Camera& camera : {fisheye_camera(pinhole, 180), equirectangular_camera(pinhole)}) {
    const RenderImage radial_image = renderer.render(camera, settings);
    const RenderImage depth_image = renderer.render(camera, RenderSettings{});
    EXPECT_EQ(radial_image.rgba, depth_image.rgba) << camera_model_name(camera.model);
  }
  const std::string refused = testing::error_of<std::invalid_argument>(
      [&] { renderer.render(orthographic_camera(pinhole, 3.0), settings); });
  EXPECT_NE(refused.find("orthographic camera has none"), std::string::npos) << refused;
  EXPECT_NE(testing::error_of<std::invalid_argument>([&] {
              render_reference(scene, orthographic_camera(pinhole, 3.0), settings);
            }).find("radial"),
            std::string::npos);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(RadialSort, TheStochasticCompositorRefusesIt) {
  RenderSettings settings = radial_settings();
  settings.compositor = Compositor::kStochastic;
  EXPECT_FALSE(compositor_draws(Compositor::kStochastic, settings.accuracy));
  EXPECT_TRUE(compositor_draws(Compositor::kSorted, settings.accuracy));
  EXPECT_TRUE(compositor_draws(Compositor::kRaster, settings.accuracy));
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(red_and_blue());
  const std::string why = testing::error_of<std::invalid_argument>([&] {
    renderer.render(look_at_camera({0, 0, 0}, {0, 0, 1}, {0, -1, 0}, 32, 32, 60), settings);
  });
  EXPECT_NE(why.find("stochastic compositor: radial"), std::string::npos) << why;
}

// Under a memory budget the scene renders in parts that follow the radial order: the same image as the
// whole scene's, bit for bit.
TEST(RadialSort, AScenesPartsFollowTheRadialOrder) {
  Renderer& renderer = testing::validated_renderer();
  const GaussianScene& scene = playbot();
  renderer.set_scene(scene);
  const Camera camera = playbot_view(240, 135);
  const RenderSettings settings = radial_settings();
  const RenderImage whole = renderer.render(camera, settings);
  // A renderer of its own: the budget counts every buffer a renderer holds.
  RendererOptions options;
  options.validation = true;
  const std::unique_ptr<Renderer> parts_renderer = Renderer::create(options);
  RenderSettings in_parts = settings;
  in_parts.memory_budget = 3ull << 20;
  const RenderImage parts = parts_renderer->render(scene, camera, in_parts);
  EXPECT_GE(parts_renderer->last_frame_stats().scene_parts, 2);
  EXPECT_EQ(parts.rgba, whole.rgba);
  EXPECT_EQ(parts.depth, whole.depth);
  EXPECT_EQ(parts.splat_count, whole.splat_count);
  // View depth parts would have split the scene elsewhere: the radial image is not the view depth one.
  RenderSettings depth_order_parts;
  depth_order_parts.memory_budget = in_parts.memory_budget;
  EXPECT_NE(parts.rgba, parts_renderer->render(scene, camera, depth_order_parts).rgba);
  EXPECT_EQ(renderer.validation_messages(), 0u);
  EXPECT_EQ(parts_renderer->validation_messages(), 0u);
}

}  // namespace
}  // namespace tilesplat
