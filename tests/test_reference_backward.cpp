// The float64 reference's backward (tilesplat/gradients.h): its gradients against central differences of
// its own unrounded forward, its forward against render_reference, its projection's values against
// project_gaussian's, its refusals, and the hard cases kept finite.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "camera/camera_models.h"
#include "gradient_test_scenes.h"
#include "reference/differentiable_projection.h"
#include "reference/reference_backward.h"
#include "tilesplat/gradients.h"
#include "tilesplat/reference.h"

namespace tilesplat {
namespace {

constexpr int kWidth = 48, kHeight = 40;

Camera test_camera() {
  return testing::gradient_camera(kWidth, kHeight);
}
GaussianScene random_scene(size_t n, uint32_t seed) {
  return testing::random_splats(n, seed);
}
FrameGradients random_gradients(uint32_t seed) {
  return testing::random_frame_gradients(kWidth, kHeight, seed);
}

// The loss whose gradient FrameGradients gives: the sum of each output times its gradient.
double loss(const GaussianScene& scene, const Camera& camera, const RenderSettings& settings,
            const FrameGradients& g) {
  const reference::FrameF64 frame = reference::render_f64(scene, camera, settings);
  double sum = 0;
  for (size_t k = 0; k < frame.rgb.size(); ++k) sum += double(g.rgb[k]) * frame.rgb[k];
  for (size_t k = 0; k < frame.alpha.size(); ++k)
    sum += double(g.alpha[k]) * frame.alpha[k] + double(g.expected_depth[k]) * frame.expected_depth[k] +
           double(g.accumulated_depth[k]) * frame.accumulated_depth[k];
  return sum;
}

// Central differences of the loss in each listed parameter against the backward's gradient. The step,
// 2^-20, is exact in a float parameter of magnitude below 8 and small enough that no pixel crosses a
// cut-off (alpha 1/255, T 1e-4, a tile's edge, the depth order) on the way.
void expect_matches_finite_differences(const GaussianScene& scene, const RenderSettings& settings,
                                       uint32_t seed) {
  const Camera camera = test_camera();
  const FrameGradients g = random_gradients(seed);
  const SceneGradients analytic = reference_backward(scene, camera, settings, g);
  EXPECT_EQ(analytic.unformed, 0u);
  struct Group {
    const char* name;
    std::vector<float> GaussianScene::*values;
    const std::vector<float>* gradient;
  };
  const Group groups[] = {{"positions", &GaussianScene::positions, &analytic.positions},
                          {"log_scales", &GaussianScene::log_scales, &analytic.log_scales},
                          {"rotations", &GaussianScene::rotations, &analytic.rotations},
                          {"opacity_logits", &GaussianScene::opacity_logits, &analytic.opacity_logits},
                          {"sh", &GaussianScene::sh, &analytic.sh}};
  const double step = std::ldexp(1.0, -20);
  size_t nonzero = 0;
  for (const Group& group : groups) {
    const size_t count = (scene.*group.values).size();
    // Every parameter, but only every 7th SH coefficient: the SH gradient is linear and cheap to get right.
    const size_t stride = group.values == &GaussianScene::sh ? 7 : 1;
    for (size_t k = 0; k < count; k += stride) {
      GaussianScene plus = scene, minus = scene;
      (plus.*group.values)[k] = float(double((scene.*group.values)[k]) + step);
      (minus.*group.values)[k] = float(double((scene.*group.values)[k]) - step);
      const double numeric = (loss(plus, camera, settings, g) - loss(minus, camera, settings, g)) /
                             (double((plus.*group.values)[k]) - double((minus.*group.values)[k]));
      const double exact = (*group.gradient)[k];
      EXPECT_NEAR(exact, numeric, 2e-5 + 2e-4 * std::abs(numeric)) << group.name << "[" << k << "]";
      if (std::abs(numeric) > 1e-3) ++nonzero;
    }
  }
  // The scene must exercise the gradients: most parameters move the loss.
  EXPECT_GT(nonzero, scene.size() * 8);
}

TEST(ReferenceBackward, MatchesFiniteDifferencesOfItsForward) {
  expect_matches_finite_differences(random_scene(12, 1), RenderSettings{}, 11);
}

TEST(ReferenceBackward, MatchesFiniteDifferencesAntialiasedOnBackground) {
  RenderSettings settings;
  settings.antialiasing = Antialiasing::kAntialiased;
  settings.background = {0.2f, 0.5f, 0.9f};
  settings.max_alpha = 0.999;
  settings.near_plane = 0.01;
  expect_matches_finite_differences(random_scene(12, 2), settings, 12);
}

TEST(ReferenceBackward, ItsForwardIsRenderReferences) {
  const GaussianScene scene = random_scene(40, 3);
  RenderSettings settings;
  settings.background = {0.1f, 0.2f, 0.3f};
  const RenderImage image = render_reference(scene, test_camera(), settings);
  const reference::FrameF64 frame = reference::render_f64(scene, test_camera(), settings);
  double covered = 0;
  for (size_t p = 0; p < image.pixels(); ++p) {
    for (size_t ch = 0; ch < 3; ++ch) EXPECT_EQ(image.rgba[4 * p + ch], float(frame.rgb[3 * p + ch])) << p;
    EXPECT_EQ(image.rgba[4 * p + 3], float(frame.alpha[p])) << p;
    EXPECT_EQ(image.depth[p], float(frame.expected_depth[p])) << p;
    EXPECT_NEAR(frame.accumulated_depth[p], frame.expected_depth[p] * frame.alpha[p], 1e-12) << p;
    covered += frame.alpha[p];
  }
  EXPECT_GT(covered, 0.1 * double(image.pixels()));
}

TEST(ReferenceBackward, ItsProjectionsValuesAreProjectGaussians) {
  const GaussianScene scene = random_scene(40, 4);
  const Camera camera = test_camera();
  size_t visible = 0;
  for (Antialiasing mode : {Antialiasing::kClassic, Antialiasing::kAntialiased, Antialiasing::kMip})
    for (size_t i = 0; i < scene.size(); ++i) {
      const ProjectedGaussian g = project_gaussian(scene, i, camera, mode);
      if (!g.visible) continue;
      ++visible;
      const reference::DifferentiableSplat d =
          reference::project_differentiable(scene, i, camera, camera_models::model_limits(camera), mode);
      auto near = [](double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(b)); };
      EXPECT_TRUE(near(d.mean[0].v, g.mean[0]) && near(d.mean[1].v, g.mean[1])) << i;
      for (size_t k = 0; k < 3; ++k) EXPECT_TRUE(near(d.conic[k].v, g.conic[k])) << i;
      EXPECT_TRUE(near(d.opacity.v, g.opacity)) << i;
      EXPECT_TRUE(near(d.depth.v, g.depth)) << i;
      for (size_t ch = 0; ch < 3; ++ch) EXPECT_TRUE(near(d.colour[ch].v, g.color[ch])) << i;
    }
  EXPECT_GT(visible, 60u);
}

TEST(ReferenceBackward, IsTheSameFromRunToRun) {
  const GaussianScene scene = random_scene(60, 5);
  const FrameGradients g = random_gradients(15);
  const SceneGradients a = reference_backward(scene, test_camera(), {}, g);
  const SceneGradients b = reference_backward(scene, test_camera(), {}, g);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.sh, b.sh);
  EXPECT_EQ(a.means2d_abs, b.means2d_abs);
}

TEST(ReferenceBackward, RefusesWhatItDoesNotCoverNamingIt) {
  const GaussianScene scene = random_scene(4, 6);
  const FrameGradients g = random_gradients(16);
  auto refusal = [&](const Camera& camera, const RenderSettings& settings) -> std::string {
    try {
      reference_backward(scene, camera, settings, g);
    } catch (const NotDifferentiable& e) {
      return e.what();
    }
    return "(accepted)";
  };
  Camera orthographic = test_camera();
  orthographic.model = CameraModel::kOrthographic;
  EXPECT_NE(refusal(orthographic, {}).find("orthographic camera model"), std::string::npos);
  RenderSettings stochastic;
  stochastic.compositor = Compositor::kStochastic;
  EXPECT_NE(refusal(test_camera(), stochastic).find("stochastic compositor"), std::string::npos);
  RenderSettings mode;
  mode.accuracy.resort_window = 8;
  EXPECT_NE(refusal(test_camera(), mode).find("accuracy mode resort8"), std::string::npos);
  RenderSettings region;
  region.region = {0, 0, 16, 16};
  EXPECT_NE(refusal(test_camera(), region).find("region"), std::string::npos);
}

TEST(ReferenceBackward, RefusesGradientsOfTheWrongSizeOrNotFinite) {
  const GaussianScene scene = random_scene(4, 7);
  FrameGradients short_rgb;
  short_rgb.rgb.assign(5, 0.0f);
  EXPECT_THROW(
      {
        try {
          reference_backward(scene, test_camera(), {}, short_rgb);
        } catch (const std::invalid_argument& e) {
          EXPECT_NE(std::string(e.what()).find("FrameGradients::rgb has 5 values"), std::string::npos)
              << e.what();
          throw;
        }
      },
      std::invalid_argument);
  FrameGradients nan_alpha;
  nan_alpha.alpha.assign(size_t(kWidth) * kHeight, 0.0f);
  nan_alpha.alpha[17] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(reference_backward(scene, test_camera(), {}, nan_alpha), std::invalid_argument);
}

// The hard cases of the stability suite, each beside ordinary splats: tiny and huge scales, a quaternion
// of float denormals and one barely above them, a splat at the near plane and one across the frame's edge,
// opacity past the cap, huge SH, and many splats over one pixel. Every gradient stays finite, and the
// ordinary splats' gradients are those they get without the hard cases in front of them... where the hard
// case does not cover them: here, the ordinary splats are checked finite and non-zero.
TEST(ReferenceBackward, HardCasesGiveFiniteGradients) {
  GaussianScene scene = random_scene(10, 8);
  auto add = [&](std::array<float, 3> p, std::array<float, 3> s, std::array<float, 4> q, float logit,
                 float dc) {
    scene.positions.insert(scene.positions.end(), p.begin(), p.end());
    scene.log_scales.insert(scene.log_scales.end(), s.begin(), s.end());
    scene.rotations.insert(scene.rotations.end(), q.begin(), q.end());
    scene.opacity_logits.push_back(logit);
    for (int k = 0; k < 16; ++k)
      for (int c = 0; c < 3; ++c) scene.sh.push_back(k == 0 ? dc : 0.0f);
  };
  const float tiny_scale = std::log(1e-8f), huge_scale = std::log(1e8f);
  add({0.1f, 0.0f, 0.0f}, {tiny_scale, tiny_scale, tiny_scale}, {1, 0, 0, 0}, 2.0f, 0.5f);
  add({0.2f, 0.1f, 0.5f}, {huge_scale, -2.0f, -2.0f}, {1, 0, 0, 0}, -3.0f, 0.5f);
  add({-0.2f, 0.1f, 0.0f}, {-2.0f, -2.0f, -2.0f}, {1e-39f, 0, 0, 1e-39f}, 2.0f, 0.5f);
  add({-0.3f, -0.1f, 0.0f}, {-2.0f, -2.0f, -2.0f}, {2e-38f, 1e-38f, 0, 0}, 2.0f, 0.5f);
  const Camera camera = test_camera();
  add({0.3f, -0.2f, -4.0f + 0.2001f}, {-3.0f, -3.0f, -3.0f}, {1, 0, 0, 0}, 2.0f, 0.5f);  // at the near plane
  add({2.0f, 0.0f, 0.0f}, {-1.0f, -1.0f, -1.0f}, {1, 0, 0, 0}, 2.0f, 0.5f);              // across the edge
  add({0.0f, 0.3f, 0.0f}, {-2.0f, -2.0f, -2.0f}, {1, 0, 0, 0}, 30.0f, 0.5f);             // past the cap
  add({0.0f, -0.3f, 0.0f}, {-2.0f, -2.0f, -2.0f}, {1, 0, 0, 0}, 1.0f, 1e20f);            // huge colour
  for (int k = 0; k < 2000; ++k)
    add({0.05f, 0.05f, 0.5f + 1e-4f * float(k)}, {-4.0f, -4.0f, -4.0f}, {1, 0, 0, 0}, -4.0f, 0.2f);
  const SceneGradients g = reference_backward(scene, camera, {}, random_gradients(18));
  for (const std::vector<float>* values :
       {&g.positions, &g.log_scales, &g.rotations, &g.opacity_logits, &g.sh, &g.means2d, &g.means2d_abs})
    for (size_t k = 0; k < values->size(); ++k) ASSERT_TRUE(std::isfinite((*values)[k])) << k;
  double ordinary = 0;
  for (size_t k = 0; k < 30; ++k) ordinary += std::abs(g.positions[k]);
  EXPECT_GT(ordinary, 0.0);
  std::printf("hard cases: %llu Gaussians of %zu unformed\n", static_cast<unsigned long long>(g.unformed),
              scene.size());
}

}  // namespace
}  // namespace tilesplat
