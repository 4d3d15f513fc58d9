// Renderer::backward (tilesplat/gradients.h) against the float64 reference's backward: random scenes with
// every SH band, classic and antialiased, on a background; a bundled trained scene; the refusals; the
// hard cases kept finite; and the statistics naming the backward passes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "gradient_test_scenes.h"
#include "test_support.h"
#include "tilesplat/camera_sets.h"
#include "tilesplat/gradients.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"

namespace tilesplat {
namespace {

using testing::gradient_camera;

GaussianScene random_scene(size_t n, uint32_t seed, float log_scale = -2.2f) {
  return testing::random_splats(n, seed, log_scale);
}
FrameGradients random_gradients(int width, int height, uint32_t seed) {
  return testing::random_frame_gradients(width, height, seed);
}

// |a - b| / |b| over a parameter group (0 when both are zero).
double relative_error(const std::vector<float>& a, const std::vector<float>& b) {
  double diff = 0, norm = 0;
  for (size_t k = 0; k < b.size(); ++k) {
    diff += (double(a[k]) - double(b[k])) * (double(a[k]) - double(b[k]));
    norm += double(b[k]) * double(b[k]);
  }
  return norm > 0 ? std::sqrt(diff / norm) : std::sqrt(diff);
}

struct GroupErrors {
  double positions, log_scales, rotations, opacity_logits, sh, means2d;
};

GroupErrors compare(const SceneGradients& gpu, const SceneGradients& reference, const std::string& label) {
  EXPECT_EQ(gpu.positions.size(), reference.positions.size());
  EXPECT_EQ(gpu.sh.size(), reference.sh.size());
  const GroupErrors e{relative_error(gpu.positions, reference.positions),
                      relative_error(gpu.log_scales, reference.log_scales),
                      relative_error(gpu.rotations, reference.rotations),
                      relative_error(gpu.opacity_logits, reference.opacity_logits),
                      relative_error(gpu.sh, reference.sh),
                      relative_error(gpu.means2d, reference.means2d)};
  std::printf(
      "%-28s relative error: positions %.2e  log_scales %.2e  rotations %.2e  opacity %.2e  sh %.2e  "
      "means2d %.2e\n",
      label.c_str(), e.positions, e.log_scales, e.rotations, e.opacity_logits, e.sh, e.means2d);
  return e;
}

void expect_within(const GroupErrors& e, double bound) {
  EXPECT_LT(e.positions, bound);
  EXPECT_LT(e.log_scales, bound);
  EXPECT_LT(e.rotations, bound);
  EXPECT_LT(e.opacity_logits, bound);
  EXPECT_LT(e.sh, bound);
  EXPECT_LT(e.means2d, bound);
}

TEST(GpuBackward, MatchesTheReferenceBackwardOnRandomSplats) {
  Renderer& renderer = testing::validated_renderer();
  const Camera camera = gradient_camera(96, 80);
  for (Antialiasing mode : {Antialiasing::kClassic, Antialiasing::kAntialiased}) {
    const GaussianScene scene = random_scene(300, 21, -2.6f);
    RenderSettings settings;
    settings.antialiasing = mode;
    settings.background = {0.2f, 0.4f, 0.6f};
    const FrameGradients g = random_gradients(camera.width, camera.height, 22);
    renderer.set_scene(scene);
    const SceneGradients gpu = renderer.backward(camera, settings, g);
    const SceneGradients reference = reference_backward(scene, camera, settings, g);
    expect_within(compare(gpu, reference, "random 300, " + to_string(mode)), 1e-4);
    EXPECT_EQ(gpu.unformed, 0u);
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(GpuBackward, MatchesTheReferenceBackwardOnATrainedScene) {
  Renderer& renderer = testing::validated_renderer();
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const std::vector<CameraView> views = load_camera_set(testing::bundled_playbot_cameras());
  ASSERT_FALSE(views.empty());
  const Camera& view = views.front().camera;
  const Camera camera = resize_camera(view, 160, int(std::lround(160.0 * view.height / view.width)));
  RenderSettings settings;
  settings.max_alpha = 0.999;
  const FrameGradients g = random_gradients(camera.width, camera.height, 23);
  renderer.set_scene(scene);
  const SceneGradients gpu = renderer.backward(camera, settings, g);
  const SceneGradients reference = reference_backward(scene, camera, settings, g);
  expect_within(compare(gpu, reference, testing::bundled_playbot().filename().string()), 1e-4);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(GpuBackward, StatisticsNameTheBackwardPasses) {
  Renderer& renderer = testing::validated_renderer();
  const Camera camera = gradient_camera(64, 48);
  renderer.set_scene(random_scene(50, 24));
  renderer.backward(camera, {}, random_gradients(64, 48, 25));
  std::vector<std::string> names;
  for (const PassTiming& pass : renderer.last_frame_stats().passes) names.push_back(pass.name);
  ASSERT_GE(names.size(), 2u);
  EXPECT_EQ(names[names.size() - 2], "composite_backward");
  EXPECT_EQ(names.back(), "projection_backward");
}

TEST(GpuBackward, RefusesWhatItDoesNotCoverBeforeAnyWork) {
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(random_scene(10, 26));
  Camera fisheye = gradient_camera(64, 48);
  fisheye.model = CameraModel::kFisheye;
  const FrameGradients g = random_gradients(64, 48, 27);
  EXPECT_THROW(renderer.backward(fisheye, {}, g), NotDifferentiable);
  RenderSettings raster;
  raster.compositor = Compositor::kRaster;
  const std::string message =
      testing::error_of([&] { renderer.backward(gradient_camera(64, 48), raster, g); });
  EXPECT_NE(message.find("Renderer::backward: the backward pass does not cover the raster compositor"),
            std::string::npos)
      << message;
  RenderSettings depth16;
  depth16.accuracy.depth_key_bits = 16;
  EXPECT_THROW(renderer.backward(gradient_camera(64, 48), depth16, g), NotDifferentiable);
  FrameGradients wrong;
  wrong.expected_depth.assign(7, 0.0f);
  EXPECT_THROW(renderer.backward(gradient_camera(64, 48), {}, wrong), std::invalid_argument);
}

// The stability suite's hard cases beside ordinary splats: tiny and huge scales, a quaternion of
// denormals and one just above them, a splat at the near plane and one across the frame's edge, an
// opacity past the cap, a huge colour, and two thousand splats over one spot. The GPU's gradients stay
// finite and agree with the reference's on the ordinary splats.
TEST(GpuBackward, HardCasesStayFinite) {
  GaussianScene scene = random_scene(40, 28);
  auto add = [&](std::array<float, 3> p, float log_scale, std::array<float, 4> q, float logit, float dc) {
    scene.positions.insert(scene.positions.end(), p.begin(), p.end());
    scene.log_scales.insert(scene.log_scales.end(), {log_scale, log_scale, log_scale});
    scene.rotations.insert(scene.rotations.end(), q.begin(), q.end());
    scene.opacity_logits.push_back(logit);
    for (int k = 0; k < 16; ++k)
      for (int c = 0; c < 3; ++c) scene.sh.push_back(k == 0 ? dc : 0.0f);
  };
  add({0.1f, 0.0f, 0.0f}, std::log(1e-8f), {1, 0, 0, 0}, 2.0f, 0.5f);
  add({0.2f, 0.1f, 0.5f}, std::log(1e8f), {1, 0, 0, 0}, -3.0f, 0.5f);
  add({-0.2f, 0.1f, 0.0f}, -2.0f, {1e-39f, 0, 0, 1e-39f}, 2.0f, 0.5f);
  add({-0.3f, -0.1f, 0.0f}, -2.0f, {2e-38f, 1e-38f, 0, 0}, 2.0f, 0.5f);
  add({0.3f, -0.2f, -4.0f + 0.2001f}, -3.0f, {1, 0, 0, 0}, 2.0f, 0.5f);
  add({2.0f, 0.0f, 0.0f}, -1.0f, {1, 0, 0, 0}, 2.0f, 0.5f);
  add({0.0f, 0.3f, 0.0f}, -2.0f, {1, 0, 0, 0}, 30.0f, 0.5f);
  add({0.0f, -0.3f, 0.0f}, -2.0f, {1, 0, 0, 0}, 1.0f, 1e20f);
  for (int k = 0; k < 2000; ++k)
    add({0.05f, 0.05f, 0.5f + 1e-4f * float(k)}, -4.0f, {1, 0, 0, 0}, -4.0f, 0.2f);
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  const Camera camera = gradient_camera(96, 80);
  const FrameGradients g = random_gradients(96, 80, 29);
  const SceneGradients gpu = renderer.backward(camera, {}, g);
  for (const std::vector<float>* values : {&gpu.positions, &gpu.log_scales, &gpu.rotations,
                                           &gpu.opacity_logits, &gpu.sh, &gpu.means2d, &gpu.means2d_abs})
    for (size_t k = 0; k < values->size(); ++k) ASSERT_TRUE(std::isfinite((*values)[k])) << k;
  const SceneGradients reference = reference_backward(scene, camera, {}, g);
  std::printf("hard cases: %llu unformed on the GPU, %llu in the reference, of %zu\n",
              static_cast<unsigned long long>(gpu.unformed),
              static_cast<unsigned long long>(reference.unformed), scene.size());
  // The ordinary splats, in front of the crowd.
  const std::vector<float> ordinary_gpu(gpu.positions.begin(), gpu.positions.begin() + 120);
  const std::vector<float> ordinary_reference(reference.positions.begin(), reference.positions.begin() + 120);
  EXPECT_LT(relative_error(ordinary_gpu, ordinary_reference), 1e-2);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// One tile listing 8,000 faint splats a pixel or two wide: every pixel walks the whole list both ways,
// the most the backward takes in one dispatch on a CPU driver (llvmpipe stops an invocation after 65,535
// loop iterations in all, silently: a walk cut short would leave the later splats without gradients).
TEST(GpuBackward, ALongTileListIsWalkedToItsEnd) {
  const Camera camera = gradient_camera(64, 48);
  std::mt19937 rng(30);
  std::uniform_real_distribution<double> in_tile(16.5, 31.5);
  GaussianScene scene;
  scene.sh_degree = 0;
  for (int k = 0; k < 8000; ++k) {
    const double depth = 4.0 + 1e-4 * k;
    const double cam[3] = {(in_tile(rng) - camera.cx) / camera.fx * depth,
                           (in_tile(rng) - camera.cy) / camera.fy * depth, depth};
    for (size_t row = 0; row < 3; ++row)  // world = W^T cam + position
      scene.positions.push_back(float(camera.rotation[row] * cam[0] + camera.rotation[3 + row] * cam[1] +
                                      camera.rotation[6 + row] * cam[2] + camera.position[row]));
    scene.log_scales.insert(scene.log_scales.end(), {-3.5f, -3.5f, -3.5f});
    scene.rotations.insert(scene.rotations.end(), {1, 0, 0, 0});
    scene.opacity_logits.push_back(-2.5f);
    scene.sh.insert(scene.sh.end(), {0.5f, -0.2f, 0.1f});
  }
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  const FrameGradients g = random_gradients(camera.width, camera.height, 31);
  const SceneGradients gpu = renderer.backward(camera, {}, g);
  const SceneGradients reference = reference_backward(scene, camera, {}, g);
  expect_within(compare(gpu, reference, "8,000 splats in one tile"), 1e-4);
  // The last splats of the list have their gradients too.
  const std::vector<float> last_gpu(gpu.opacity_logits.end() - 500, gpu.opacity_logits.end());
  const std::vector<float> last_reference(reference.opacity_logits.end() - 500,
                                          reference.opacity_logits.end());
  EXPECT_LT(relative_error(last_gpu, last_reference), 1e-4);
  double last_sum = 0;
  for (float v : last_reference) last_sum += std::abs(v);
  EXPECT_GT(last_sum, 0.0);
}

}  // namespace
}  // namespace tilesplat
