// The float64 reference: each step checked against values worked out by hand (or from the plain
// formulas, written out independently here), then whole images against independent references.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

constexpr double kC0 = 0.28209479177387814;
constexpr double kC1 = 0.4886025119029199;

using testing::axis_camera;

struct GaussianSpec {
  std::array<float, 3> position = {0, 0, 1};
  std::array<float, 3> log_scale = {-20, -20, -20};  // tiny: the footprint is the 0.3 low-pass alone
  std::array<float, 4> rotation = {1, 0, 0, 0};
  float opacity_logit = 0;
  std::array<float, 3> dc = {0, 0, 0};  // SH DC coefficients (colour = C0 dc + 0.5)
};

void add_gaussian(GaussianScene& scene, const GaussianSpec& spec) {
  scene.positions.insert(scene.positions.end(), spec.position.begin(), spec.position.end());
  scene.log_scales.insert(scene.log_scales.end(), spec.log_scale.begin(), spec.log_scale.end());
  scene.rotations.insert(scene.rotations.end(), spec.rotation.begin(), spec.rotation.end());
  scene.opacity_logits.push_back(spec.opacity_logit);
  const int coefficients = scene.sh_coefficients();
  scene.sh.insert(scene.sh.end(), spec.dc.begin(), spec.dc.end());
  scene.sh.insert(scene.sh.end(), static_cast<size_t>(3 * (coefficients - 1)), 0.0f);
}

GaussianScene scene_of(const std::vector<GaussianSpec>& specs) {
  GaussianScene scene;
  for (const GaussianSpec& spec : specs) add_gaussian(scene, spec);
  return scene;
}

// The DC coefficient that produces `color` before the +0.5 shift, and what the float round trip
// makes of it.
float dc_for(double color) { return static_cast<float>((color - 0.5) / kC0); }
double color_of(float dc) { return kC0 * double(dc) + 0.5; }
double opacity_of(float logit) { return 1.0 / (1.0 + std::exp(-double(logit))); }

// Where a camera-space point (x, y, z) must sit for the axis camera to put it on pixel (px, py).
std::array<float, 3> point_on_pixel(const Camera& camera, double px, double py, double z) {
  return {static_cast<float>((px - camera.cx) * z / camera.fx), static_cast<float>((py - camera.cy) * z / camera.fy),
          static_cast<float>(z)};
}

const float* pixel_rgba(const RenderImage& image, int x, int y) {
  return &image.rgba[(size_t(y) * size_t(image.width) + size_t(x)) * 4];
}

// ---------------------------------------------------------------------------------------------
// covariance3d

TEST(ReferenceCovariance, IdentityRotationIsDiagonalOfSquaredScales) {
  const float log_scale[3] = {std::log(0.5f), std::log(2.0f), std::log(3.0f)};
  const float quat[4] = {1, 0, 0, 0};
  const auto sigma = covariance3d(log_scale, quat);
  const double expected[9] = {0.25, 0, 0, 0, 4, 0, 0, 0, 9};
  for (size_t k = 0; k < 9; ++k) EXPECT_NEAR(sigma[k], expected[k], 1e-6) << "entry " << k;
}

TEST(ReferenceCovariance, NinetyDegreesAboutZSwapsXAndY) {
  // R maps x -> y and y -> -x, so the x extent ends up along y and vice versa; z is untouched.
  const float log_scale[3] = {std::log(0.5f), std::log(2.0f), std::log(3.0f)};
  const float half = static_cast<float>(std::sqrt(0.5));
  const float quat[4] = {half, 0, 0, half};
  const auto sigma = covariance3d(log_scale, quat);
  const double expected[9] = {4, 0, 0, 0, 0.25, 0, 0, 0, 9};
  for (size_t k = 0; k < 9; ++k) EXPECT_NEAR(sigma[k], expected[k], 1e-6) << "entry " << k;
}

TEST(ReferenceCovariance, QuaternionIsNormalizedAndZeroIsIdentity) {
  const float log_scale[3] = {std::log(0.5f), std::log(2.0f), std::log(3.0f)};
  const float half = static_cast<float>(std::sqrt(0.5));
  const float unit[4] = {half, 0, 0, half};
  const float scaled[4] = {3 * half, 0, 0, 3 * half};
  const auto from_unit = covariance3d(log_scale, unit);
  const auto from_scaled = covariance3d(log_scale, scaled);
  for (size_t k = 0; k < 9; ++k) EXPECT_NEAR(from_scaled[k], from_unit[k], 1e-9);

  const float zero[4] = {0, 0, 0, 0};
  const float identity[4] = {1, 0, 0, 0};
  EXPECT_EQ(covariance3d(log_scale, zero), covariance3d(log_scale, identity));
}

TEST(ReferenceCovariance, IsSymmetricForAGeneralRotation) {
  const float log_scale[3] = {-1.0f, 0.3f, -0.2f};
  const float quat[4] = {0.3f, -0.5f, 0.7f, 0.2f};
  const auto sigma = covariance3d(log_scale, quat);
  EXPECT_DOUBLE_EQ(sigma[1], sigma[3]);
  EXPECT_DOUBLE_EQ(sigma[2], sigma[6]);
  EXPECT_DOUBLE_EQ(sigma[5], sigma[7]);
  // A rotation preserves the trace: sum of the squared scales.
  const double trace = std::exp(-2.0) + std::exp(0.6) + std::exp(-0.4);
  EXPECT_NEAR(sigma[0] + sigma[4] + sigma[8], trace, 1e-6);
}

// ---------------------------------------------------------------------------------------------
// eval_sh

TEST(ReferenceSh, DegreeZeroIsC0TimesDc) {
  const float coeffs[3] = {0.5f, -1.0f, 2.0f};
  const auto rgb = eval_sh(0, coeffs, {0, 0, 1});
  EXPECT_DOUBLE_EQ(rgb[0], kC0 * 0.5);
  EXPECT_DOUBLE_EQ(rgb[1], kC0 * -1.0);
  EXPECT_DOUBLE_EQ(rgb[2], kC0 * 2.0);
}

TEST(ReferenceSh, DegreeOneSignsAlongEachAxis) {
  // Coefficient 1 feeds red, 2 green, 3 blue; DC is zero. The 3DGS band-1 term is
  // -C1 y sh1 + C1 z sh2 - C1 x sh3.
  std::vector<float> coeffs(4 * 3, 0.0f);
  coeffs[1 * 3 + 0] = 1;
  coeffs[2 * 3 + 1] = 1;
  coeffs[3 * 3 + 2] = 1;

  const auto along_x = eval_sh(1, coeffs.data(), {1, 0, 0});
  EXPECT_DOUBLE_EQ(along_x[0], 0);
  EXPECT_DOUBLE_EQ(along_x[1], 0);
  EXPECT_DOUBLE_EQ(along_x[2], -kC1);

  const auto along_y = eval_sh(1, coeffs.data(), {0, 1, 0});
  EXPECT_DOUBLE_EQ(along_y[0], -kC1);
  EXPECT_DOUBLE_EQ(along_y[1], 0);
  EXPECT_DOUBLE_EQ(along_y[2], 0);

  const auto along_z = eval_sh(1, coeffs.data(), {0, 0, 1});
  EXPECT_DOUBLE_EQ(along_z[0], 0);
  EXPECT_DOUBLE_EQ(along_z[1], kC1);
  EXPECT_DOUBLE_EQ(along_z[2], 0);

  const auto along_minus_z = eval_sh(1, coeffs.data(), {0, 0, -1});
  EXPECT_DOUBLE_EQ(along_minus_z[1], -kC1);
}

// The sixteen real SH basis functions in the 3DGS order and signs, written as plain polynomials.
std::array<double, 16> sh_basis(double x, double y, double z) {
  return {0.28209479177387814,
          -0.4886025119029199 * y,
          0.4886025119029199 * z,
          -0.4886025119029199 * x,
          1.0925484305920792 * x * y,
          -1.0925484305920792 * y * z,
          0.31539156525252005 * (2 * z * z - x * x - y * y),
          -1.0925484305920792 * x * z,
          0.5462742152960396 * (x * x - y * y),
          -0.5900435899266435 * y * (3 * x * x - y * y),
          2.890611442640554 * x * y * z,
          -0.4570457994644658 * y * (4 * z * z - x * x - y * y),
          0.3731763325901154 * z * (2 * z * z - 3 * x * x - 3 * y * y),
          -0.4570457994644658 * x * (4 * z * z - x * x - y * y),
          1.445305721320277 * z * (x * x - y * y),
          -0.5900435899266435 * x * (x * x - 3 * y * y)};
}

TEST(ReferenceSh, DegreesTwoAndThreeMatchThePolynomials) {
  std::vector<float> coeffs(16 * 3);
  for (size_t k = 0; k < 16; ++k)
    for (size_t c = 0; c < 3; ++c)
      coeffs[k * 3 + c] = static_cast<float>((k % 2 ? -0.1 : 0.1) * double(k + 1) * double(c + 1) / 3.0);
  const double norm = std::sqrt(1.0 + 4.0 + 9.0);
  const std::array<double, 3> dir = {1 / norm, -2 / norm, 3 / norm};
  const auto basis = sh_basis(dir[0], dir[1], dir[2]);

  for (int degree : {2, 3}) {
    const size_t used = size_t((degree + 1) * (degree + 1));
    const auto rgb = eval_sh(degree, coeffs.data(), dir);
    for (size_t c = 0; c < 3; ++c) {
      double expected = 0;
      for (size_t k = 0; k < used; ++k) expected += basis[k] * double(coeffs[k * 3 + c]);
      EXPECT_NEAR(rgb[c], expected, 1e-12) << "degree " << degree << " channel " << c;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// project_gaussian

TEST(ReferenceProjection, IsotropicGaussianOnTheOpticalAxis) {
  const Camera camera = axis_camera(640, 480, 500);
  const double scale = 0.1, z = 5;
  GaussianSpec spec;
  spec.position = {0, 0, static_cast<float>(z)};
  spec.log_scale.fill(static_cast<float>(std::log(scale)));
  spec.opacity_logit = 0;
  spec.dc = {1.0f, 0.0f, -1.0f};
  const GaussianScene scene = scene_of({spec});
  const ProjectedGaussian g = project_gaussian(scene, 0, camera);

  ASSERT_TRUE(g.visible);
  EXPECT_DOUBLE_EQ(g.depth, z);
  EXPECT_DOUBLE_EQ(g.mean[0], 320);
  EXPECT_DOUBLE_EQ(g.mean[1], 240);
  // (f s / z)^2 = (500 * 0.1 / 5)^2 = 100, plus the 0.3 low-pass.
  const double s = std::exp(double(static_cast<float>(std::log(scale))));
  const double variance = (500 * s / z) * (500 * s / z) + 0.3;
  EXPECT_NEAR(g.cov2d[0], variance, 1e-9);
  EXPECT_NEAR(g.cov2d[1], 0, 1e-12);
  EXPECT_NEAR(g.cov2d[2], variance, 1e-9);
  EXPECT_NEAR(g.conic[0], 1 / variance, 1e-12);
  EXPECT_NEAR(g.conic[1], 0, 1e-12);
  EXPECT_NEAR(g.conic[2], 1 / variance, 1e-12);
  // Equal eigenvalues: mid^2 - det = 0, so the 0.1 floor decides lambda.
  const double lambda = variance + std::sqrt(0.1);
  EXPECT_EQ(g.radius, static_cast<int>(std::ceil(3 * std::sqrt(lambda))));
  EXPECT_EQ(g.radius, 31);
  // Tiles: x from floor((320 - 31) / 16) = 18 to floor((320 + 31 + 15) / 16) = 22;
  //        y from floor((240 - 31) / 16) = 13 to floor((240 + 31 + 15) / 16) = 17.
  EXPECT_EQ(g.tile_min[0], 18);
  EXPECT_EQ(g.tile_max[0], 22);
  EXPECT_EQ(g.tile_min[1], 13);
  EXPECT_EQ(g.tile_max[1], 17);
  EXPECT_DOUBLE_EQ(g.opacity, 0.5);
  EXPECT_NEAR(g.color[0], kC0 * 1.0 + 0.5, 1e-12);
  EXPECT_NEAR(g.color[1], 0.5, 1e-12);
  EXPECT_NEAR(g.color[2], kC0 * -1.0 + 0.5, 1e-12);
}

TEST(ReferenceProjection, OffAxisGaussianSeenFromATranslatedCamera) {
  Camera camera = axis_camera(640, 480, 500);
  camera.cx = 300;
  camera.cy = 200;
  camera.position = {0, 0, -5};
  const double scale = 0.25;
  GaussianSpec spec;
  spec.position = {1.0f, -0.5f, -1.0f};  // camera space (1, -0.5, 4)
  spec.log_scale.fill(static_cast<float>(std::log(scale)));
  const GaussianScene scene = scene_of({spec});
  const ProjectedGaussian g = project_gaussian(scene, 0, camera);

  ASSERT_TRUE(g.visible);
  EXPECT_DOUBLE_EQ(g.depth, 4);
  EXPECT_DOUBLE_EQ(g.mean[0], 500 * 1.0 / 4 + 300);   // 425
  EXPECT_DOUBLE_EQ(g.mean[1], 500 * -0.5 / 4 + 200);  // 137.5
  // Isotropic Sigma = s^2 I, so cov2d = s^2 J J^T with J = [[f/z, 0, -f x/z^2], [0, f/z, -f y/z^2]].
  const double s2 = std::pow(std::exp(double(static_cast<float>(std::log(scale)))), 2);
  const double f = 500, x = 1, y = -0.5, z = 4;
  EXPECT_NEAR(g.cov2d[0], s2 * (f * f / (z * z) + f * f * x * x / (z * z * z * z)) + 0.3, 1e-9);
  EXPECT_NEAR(g.cov2d[1], s2 * (f * f * x * y / (z * z * z * z)), 1e-9);
  EXPECT_NEAR(g.cov2d[2], s2 * (f * f / (z * z) + f * f * y * y / (z * z * z * z)) + 0.3, 1e-9);
}

TEST(ReferenceProjection, NearPlaneCullsAtZPointTwo) {
  // The Gaussian sits at the world origin and the camera backs away from it, so that the view
  // depth is exactly the double 0.2 (0.2f as a position would be 0.2000000030).
  Camera camera = axis_camera(640, 480, 500);
  GaussianSpec spec;
  spec.position = {0, 0, 0};
  spec.log_scale.fill(std::log(0.001f));
  const GaussianScene scene = scene_of({spec});

  camera.position = {0, 0, -0.2};
  const ProjectedGaussian at_near = project_gaussian(scene, 0, camera);
  EXPECT_EQ(at_near.depth, 0.2);
  EXPECT_FALSE(at_near.visible);

  camera.position = {0, 0, -0.2001};
  const ProjectedGaussian just_past = project_gaussian(scene, 0, camera);
  EXPECT_TRUE(just_past.visible);
  EXPECT_DOUBLE_EQ(just_past.mean[0], 320);

  camera.position = {0, 0, 3};
  EXPECT_FALSE(project_gaussian(scene, 0, camera).visible);  // behind the camera
}

TEST(ReferenceProjection, FrustumClampChangesCovarianceButNotMean) {
  const Camera camera = axis_camera(640, 480, 500);
  const double f = 500, z = 4, x_over_z = 1.5;  // limit = 1.3 * 320 / 500 = 0.832
  GaussianSpec spec;
  spec.position = {static_cast<float>(x_over_z * z), 0, static_cast<float>(z)};
  spec.log_scale.fill(0.0f);  // s = 1: a footprint wide enough to still reach the image
  const ProjectedGaussian g = project_gaussian(scene_of({spec}), 0, camera);

  EXPECT_TRUE(g.visible);
  EXPECT_DOUBLE_EQ(g.mean[0], f * x_over_z + 320);  // 1070, outside the image: not clamped
  EXPECT_DOUBLE_EQ(g.mean[1], 240);
  const double limit = 1.3 * 640 / (2 * f);
  const double clamped_x = limit * z;
  const double expected_a = f * f / (z * z) + f * f * clamped_x * clamped_x / (z * z * z * z) + 0.3;
  const double unclamped_a = f * f / (z * z) + f * f * x_over_z * x_over_z / (z * z) + 0.3;
  EXPECT_NEAR(g.cov2d[0], expected_a, 1e-9);
  EXPECT_GT(std::abs(g.cov2d[0] - unclamped_a), 1000.0);
  EXPECT_NEAR(g.cov2d[1], 0, 1e-9);
  EXPECT_NEAR(g.cov2d[2], f * f / (z * z) + 0.3, 1e-9);
}

TEST(ReferenceProjection, TileRectsAtCornersAndEdges) {
  // 100x50 is not a multiple of 16: the grid is 7x4 with partial last tiles. A tiny Gaussian's
  // footprint is the 0.3 low-pass alone: lambda = 0.3 + sqrt(0.1), radius = ceil(3 sqrt(lambda)) = 3.
  const Camera camera = axis_camera(100, 50, 100);
  auto project_at = [&](double px, double py) {
    GaussianSpec spec;
    spec.position = point_on_pixel(camera, px, py, 1.0);
    return project_gaussian(scene_of({spec}), 0, camera);
  };

  const ProjectedGaussian top_left = project_at(2, 2);
  ASSERT_TRUE(top_left.visible);
  EXPECT_EQ(top_left.radius, 3);
  EXPECT_EQ(top_left.tile_min[0], 0);  // floor(-1 / 16) = -1, clamped to 0
  EXPECT_EQ(top_left.tile_min[1], 0);
  EXPECT_EQ(top_left.tile_max[0], 1);  // floor(20 / 16)
  EXPECT_EQ(top_left.tile_max[1], 1);

  const ProjectedGaussian bottom_right = project_at(99, 49);
  ASSERT_TRUE(bottom_right.visible);
  EXPECT_EQ(bottom_right.tile_min[0], 6);  // floor(96 / 16)
  EXPECT_EQ(bottom_right.tile_min[1], 2);  // floor(46 / 16)
  EXPECT_EQ(bottom_right.tile_max[0], 7);  // floor(117 / 16) = 7 = grid
  EXPECT_EQ(bottom_right.tile_max[1], 4);  // floor(67 / 16) = 4 = grid

  const ProjectedGaussian on_tile_border = project_at(40, 20);
  ASSERT_TRUE(on_tile_border.visible);
  EXPECT_EQ(on_tile_border.tile_min[0], 2);  // floor(37 / 16)
  EXPECT_EQ(on_tile_border.tile_max[0], 3);  // floor(58 / 16)
  EXPECT_EQ(on_tile_border.tile_min[1], 1);  // floor(17 / 16)
  EXPECT_EQ(on_tile_border.tile_max[1], 2);  // floor(38 / 16)

  // Just off the left edge the footprint still reaches column 0; further off it reaches nothing.
  const ProjectedGaussian grazing = project_at(-2, 25);
  EXPECT_TRUE(grazing.visible);
  EXPECT_EQ(grazing.tile_min[0], 0);
  EXPECT_EQ(grazing.tile_max[0], 1);  // floor(16 / 16)
  EXPECT_FALSE(project_at(-20, 25).visible);  // floor(-2 / 16) = -1 -> 0: zero width
  EXPECT_FALSE(project_at(120, 25).visible);  // floor(117 / 16) = 7 = grid: zero width
}

TEST(ReferenceProjection, HugeGaussianCoversTheGridWithoutOverflow) {
  const Camera camera = axis_camera(100, 50, 100);
  GaussianSpec spec;
  spec.position = {0, 0, 2};
  spec.log_scale.fill(80.0f);  // exp(80) ~ 5.5e34: the radius does not fit an int
  const ProjectedGaussian g = project_gaussian(scene_of({spec}), 0, camera);
  ASSERT_TRUE(g.visible);
  EXPECT_EQ(g.radius, std::numeric_limits<int>::max());
  EXPECT_EQ(g.tile_min[0], 0);
  EXPECT_EQ(g.tile_min[1], 0);
  EXPECT_EQ(g.tile_max[0], 7);
  EXPECT_EQ(g.tile_max[1], 4);
}

TEST(ReferenceProjection, NonFiniteValuesAreNeverVisible) {
  const Camera camera = axis_camera(100, 50, 100);
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  GaussianSpec base;
  base.position = {0, 0, 2};

  GaussianSpec infinite_scale = base;
  infinite_scale.log_scale = {inf, 0, 0};
  GaussianSpec nan_scale = base;
  nan_scale.log_scale = {0, nan, 0};
  GaussianSpec nan_position = base;
  nan_position.position = {nan, 0, 2};
  GaussianSpec nan_depth = base;
  nan_depth.position = {0, 0, nan};
  GaussianSpec infinite_position = base;
  infinite_position.position = {inf, 0, 2};
  GaussianSpec nan_rotation = base;
  nan_rotation.rotation = {nan, 0, 0, 0};
  const GaussianScene scene =
      scene_of({infinite_scale, nan_scale, nan_position, nan_depth, infinite_position, nan_rotation});
  for (size_t i = 0; i < scene.size(); ++i) EXPECT_FALSE(project_gaussian(scene, i, camera).visible) << "case " << i;

  // The renderer draws none of them: the image is the background.
  const RenderImage image = render_reference(scene, camera);
  for (float value : image.rgba) ASSERT_EQ(value, 0.0f);
}

TEST(ReferenceProjection, OpacityIsAStableSigmoid) {
  const Camera camera = axis_camera(100, 50, 100);
  GaussianSpec spec;
  spec.position = {0, 0, 2};
  auto opacity = [&](float logit) {
    spec.opacity_logit = logit;
    const ProjectedGaussian g = project_gaussian(scene_of({spec}), 0, camera);
    EXPECT_TRUE(g.visible);
    return g.opacity;
  };
  EXPECT_EQ(opacity(0), 0.5);
  EXPECT_EQ(opacity(800), 1.0);
  EXPECT_EQ(opacity(-800), 0.0);
  EXPECT_NEAR(opacity(3) / (1 / (1 + std::exp(-3.0))), 1, 1e-14);
  // 1 / (1 + e^30) = 9.3576e-14: the stable form keeps full relative precision.
  EXPECT_NEAR(opacity(-30) / 9.357622968839299e-14, 1, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// render_reference

// One Gaussian of scale 0.02 at depth 2 seen with f = 100: (f s / z)^2 = 1, so cov2d = 1.3 I and
// the conic is I / 1.3. The principal point sits on the centre of pixel (10, 12) so that the
// Gaussian is on the optical axis, where the Jacobian has no off-axis stretch.
struct SingleSplat {
  static constexpr int pixel_x = 10, pixel_y = 12;
  Camera camera = axis_camera(32, 32, 100);
  double depth = 2;

  SingleSplat() {
    camera.cx = pixel_x + 0.5;
    camera.cy = pixel_y + 0.5;
  }
  double colour[3] = {color_of(dc_for(0.8)), color_of(dc_for(0.4)), color_of(dc_for(0.2))};

  GaussianSpec spec(float opacity_logit) const {
    GaussianSpec s;
    s.position = point_on_pixel(camera, pixel_x + 0.5, pixel_y + 0.5, depth);
    s.log_scale.fill(std::log(0.02f));
    s.opacity_logit = opacity_logit;
    s.dc = {dc_for(0.8), dc_for(0.4), dc_for(0.2)};
    return s;
  }
  double variance() const {
    const double s = double(std::log(0.02f));
    return std::pow(100 * std::exp(s) / depth, 2) + 0.3;
  }
};

TEST(ReferenceRender, OneOpaqueGaussianCentredOnAPixel) {
  const SingleSplat setup;
  const float logit = 10;  // opacity 0.99995: capped at 0.99
  const RenderImage image = render_reference(scene_of({setup.spec(logit)}), setup.camera);
  ASSERT_EQ(image.width, 32);
  ASSERT_EQ(image.height, 32);
  ASSERT_EQ(image.depth.size(), image.pixels());
  ASSERT_EQ(image.splat_count.size(), image.pixels());

  const float* centre = pixel_rgba(image, setup.pixel_x, setup.pixel_y);
  for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(centre[c], setup.colour[c] * 0.99, 1e-6) << "channel " << c;
  EXPECT_NEAR(centre[3], 0.99, 1e-6);
  const size_t centre_index = size_t(setup.pixel_y) * 32 + size_t(setup.pixel_x);
  EXPECT_NEAR(image.depth[centre_index], setup.depth, 1e-6);
  EXPECT_EQ(image.splat_count[centre_index], 1u);

  // One pixel to the right: d = (-1, 0), power = -0.5 / 1.3.
  const double alpha_right = std::min(0.99, opacity_of(logit) * std::exp(-0.5 / setup.variance()));
  const float* right = pixel_rgba(image, setup.pixel_x + 1, setup.pixel_y);
  for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(right[c], setup.colour[c] * alpha_right, 1e-6);
  EXPECT_NEAR(right[3], alpha_right, 1e-6);

  // Diagonal neighbour: d = (-1, -1), power = -0.5 (1 + 1) / 1.3.
  const double alpha_diagonal = opacity_of(logit) * std::exp(-1.0 / setup.variance());
  EXPECT_NEAR(pixel_rgba(image, setup.pixel_x + 1, setup.pixel_y + 1)[3], alpha_diagonal, 1e-6);

  // Four pixels away: alpha = exp(-8 / 1.3) = 0.0021 < 1/255, skipped.
  const float* far = pixel_rgba(image, setup.pixel_x + 4, setup.pixel_y);
  EXPECT_EQ(far[3], 0.0f);
  EXPECT_EQ(image.splat_count[centre_index + 4], 0u);
  EXPECT_EQ(image.depth[centre_index + 4], 0.0f);
}

TEST(ReferenceRender, HalfOpaqueGaussianOverABackground) {
  const SingleSplat setup;
  RenderSettings settings;
  settings.background = {0.2f, 0.4f, 0.6f};
  const RenderImage image = render_reference(scene_of({setup.spec(0.0f)}), setup.camera, settings);

  const float* centre = pixel_rgba(image, setup.pixel_x, setup.pixel_y);
  for (size_t c = 0; c < 3; ++c)
    EXPECT_NEAR(centre[c], setup.colour[c] * 0.5 + 0.5 * double(settings.background[c]), 1e-6) << "channel " << c;
  EXPECT_NEAR(centre[3], 0.5, 1e-6);

  // Pixels the splat does not reach show the background exactly, with zero alpha.
  const float* corner = pixel_rgba(image, 31, 31);
  for (size_t c = 0; c < 3; ++c) EXPECT_EQ(corner[c], settings.background[c]);
  EXPECT_EQ(corner[3], 0.0f);
}

TEST(ReferenceRender, EarlyTerminationStopsBeforeTransmittanceDropsBelowTheLimit) {
  // Five layers of opacity 0.95 on one pixel, listed back to front so that the depth sort has
  // work to do. T goes 1 -> 0.05 -> 0.0025 -> 1.25e-4; the fourth layer would take it to
  // 6.25e-6 < 1e-4, so the pixel stops after three layers and the last two are never blended.
  const Camera camera = axis_camera(16, 16, 50);
  const float logit = std::log(19.0f);  // sigmoid = 0.95
  const double opacity = opacity_of(logit);
  const double layer_colour[5] = {0.9, 0.7, 0.5, 0.3, 0.1};
  std::vector<GaussianSpec> specs;
  for (int layer = 4; layer >= 0; --layer) {
    GaussianSpec spec;
    spec.position = point_on_pixel(camera, 8.5, 8.5, 1.0 + layer);
    spec.opacity_logit = logit;
    const float dc = dc_for(layer_colour[layer]);
    spec.dc = {dc, dc, dc};
    specs.push_back(spec);
  }
  const RenderImage image = render_reference(scene_of(specs), camera);

  double transmittance = 1, colour = 0, depth_sum = 0, weight_sum = 0;
  for (int layer = 0; layer < 3; ++layer) {
    const double weight = opacity * transmittance;
    colour += color_of(dc_for(layer_colour[layer])) * weight;
    depth_sum += (1.0 + layer) * weight;
    weight_sum += weight;
    transmittance *= 1 - opacity;
  }
  const float* pixel = pixel_rgba(image, 8, 8);
  EXPECT_NEAR(pixel[0], colour, 1e-6);
  EXPECT_NEAR(pixel[3], 1 - transmittance, 1e-7);
  EXPECT_GT(1.0 - double(pixel[3]), 1e-4);
  EXPECT_EQ(image.splat_count[8 * 16 + 8], 3u);
  EXPECT_NEAR(image.depth[8 * 16 + 8], depth_sum / weight_sum, 1e-6);
}

TEST(ReferenceRender, CappedAlphaAlsoTerminates) {
  // Opacity capped at 0.99: T goes 1 -> 0.01 and the next layer would reach 1e-4 (plus rounding,
  // an ulp above it in double); the third layer would reach 1e-6, so at most two layers blend and
  // the alpha never exceeds 1 - 1e-4.
  const Camera camera = axis_camera(16, 16, 50);
  std::vector<GaussianSpec> specs;
  for (int layer = 0; layer < 20; ++layer) {
    GaussianSpec spec;
    spec.position = point_on_pixel(camera, 8.5, 8.5, 1.0 + 0.1 * layer);
    spec.opacity_logit = 12;
    spec.dc = {dc_for(1.0), dc_for(1.0), dc_for(1.0)};
    specs.push_back(spec);
  }
  const RenderImage image = render_reference(scene_of(specs), camera);
  const uint32_t blended = image.splat_count[8 * 16 + 8];
  EXPECT_GE(blended, 1u);
  EXPECT_LE(blended, 2u);
  const double transmittance = 1.0 - double(pixel_rgba(image, 8, 8)[3]);
  EXPECT_GE(transmittance, 1e-4 - 1e-7);
  EXPECT_NEAR(transmittance, std::pow(0.01, blended), 1e-7);
}

TEST(ReferenceRender, EqualDepthsBlendInIndexOrder) {
  const SingleSplat setup;
  GaussianSpec red = setup.spec(0.0f);
  red.dc = {dc_for(1.0), dc_for(0.0), dc_for(0.0)};
  GaussianSpec green = red;
  green.dc = {dc_for(0.0), dc_for(1.0), dc_for(0.0)};
  const RenderImage red_first = render_reference(scene_of({red, green}), setup.camera);
  const float* pixel = pixel_rgba(red_first, setup.pixel_x, setup.pixel_y);
  EXPECT_NEAR(pixel[0], color_of(red.dc[0]) * 0.5 + color_of(green.dc[0]) * 0.25, 1e-6);
  EXPECT_NEAR(pixel[1], color_of(red.dc[1]) * 0.5 + color_of(green.dc[1]) * 0.25, 1e-6);

  const RenderImage green_first = render_reference(scene_of({green, red}), setup.camera);
  EXPECT_NEAR(pixel_rgba(green_first, setup.pixel_x, setup.pixel_y)[1],
              color_of(green.dc[1]) * 0.5 + color_of(red.dc[1]) * 0.25, 1e-6);
}

TEST(ReferenceRender, EmptySceneIsTheBackground) {
  RenderSettings settings;
  settings.background = {0.25f, 0.5f, 1.0f};
  const RenderImage image = render_reference(GaussianScene{}, axis_camera(37, 23, 30), settings);
  ASSERT_EQ(image.width, 37);
  ASSERT_EQ(image.height, 23);
  ASSERT_EQ(image.rgba.size(), image.pixels() * 4);
  for (size_t p = 0; p < image.pixels(); ++p) {
    for (size_t c = 0; c < 3; ++c) ASSERT_EQ(image.rgba[p * 4 + c], settings.background[c]);
    ASSERT_EQ(image.rgba[p * 4 + 3], 0.0f);
    ASSERT_EQ(image.depth[p], 0.0f);
    ASSERT_EQ(image.splat_count[p], 0u);
  }
}

TEST(ReferenceRender, OptionalChannelsFollowTheSettings) {
  const SingleSplat setup;
  RenderSettings settings;
  settings.depth = false;
  settings.splat_count = false;
  const RenderImage image = render_reference(scene_of({setup.spec(0.0f)}), setup.camera, settings);
  EXPECT_TRUE(image.depth.empty());
  EXPECT_TRUE(image.splat_count.empty());
  EXPECT_EQ(image.rgba.size(), image.pixels() * 4);
}

TEST(ReferenceRender, OneByOneImage) {
  const Camera camera = axis_camera(1, 1, 1);
  GaussianSpec spec;
  spec.position = {0, 0, 3};  // projects onto (0.5, 0.5), the centre of the only pixel
  spec.opacity_logit = 0;
  spec.dc = {dc_for(0.6), dc_for(0.6), dc_for(0.6)};
  const RenderImage image = render_reference(scene_of({spec}), camera);
  ASSERT_EQ(image.pixels(), 1u);
  EXPECT_NEAR(image.rgba[0], color_of(spec.dc[0]) * 0.5, 1e-6);
  EXPECT_NEAR(image.rgba[3], 0.5, 1e-6);
  EXPECT_NEAR(image.depth[0], 3, 1e-6);
  EXPECT_EQ(image.splat_count[0], 1u);
}

TEST(ReferenceRender, RejectsCamerasWithoutASize) {
  EXPECT_THROW(render_reference(GaussianScene{}, axis_camera(0, 10, 10)), std::invalid_argument);
  EXPECT_THROW(render_reference(GaussianScene{}, axis_camera(10, 10, 0)), std::invalid_argument);
}

TEST(ReferenceRender, BundledSh3SceneRendersDeterministically) {
  const GaussianScene scene = load_scene(testing::bundled_sh3());
  const auto views = load_cameras_json(testing::bundled_sh3_cameras());
  const Camera camera = resize_camera(views.at(0).camera, 160, 90);
  const RenderImage first = render_reference(scene, camera);
  const RenderImage second = render_reference(scene, camera);
  EXPECT_EQ(first.rgba, second.rgba);
  size_t covered = 0;
  for (size_t p = 0; p < first.pixels(); ++p) covered += first.rgba[p * 4 + 3] > 0;
  EXPECT_GT(covered, 0u);
}

// ---------------------------------------------------------------------------------------------
// Against the independent float64 reference images of ../shared/scenes/reference.

struct IndependentReference {
  const char* scene;
  int view;
};

// Names the image in ctest's listing instead of dumping the struct's bytes.
void PrintTo(const IndependentReference& reference, std::ostream* os) {
  *os << reference.scene << " view " << reference.view;
}

class ReferenceVsIndependent : public ::testing::TestWithParam<IndependentReference> {};

TEST_P(ReferenceVsIndependent, AgreesAbove60Db) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const IndependentReference& param = GetParam();
  const auto shared = testing::shared_scenes();
  const std::string name = param.scene;
  const auto expected_path = shared / "reference" / (name + "_view" + std::to_string(param.view) + ".exr");
  if (!std::filesystem::exists(expected_path)) TILESPLAT_SKIP_OR_FAIL("no reference image " << expected_path);

  const GaussianScene scene = load_scene(shared / (name + ".ply"));
  const auto views = load_cameras_json(shared / "cameras" / (name + ".json"));
  const Camera camera = resize_camera(views.at(size_t(param.view)).camera, 480, 270);
  RenderSettings settings;
  settings.background = {0, 0, 0};

  const auto start = std::chrono::steady_clock::now();
  const RenderImage rendered = render_reference(scene, camera, settings);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const RenderImage expected = read_exr(expected_path);
  ASSERT_EQ(expected.width, 480);
  ASSERT_EQ(expected.height, 270);
  const ImageDifference difference = compare_images(rendered, expected);

  std::printf("[ reference ] %-24s view %d: PSNR %.2f dB, max |d| %.3g (alpha %.3g) at (%d, %d), %zu splats, %.0f ms\n",
              name.c_str(), param.view, difference.psnr_db, difference.max_abs, difference.max_abs_alpha,
              difference.worst_x, difference.worst_y, scene.size(), ms);
  RecordProperty("psnr_db", std::to_string(difference.psnr_db));
  RecordProperty("max_abs", std::to_string(difference.max_abs));
  EXPECT_GE(difference.psnr_db, 60.0);
  EXPECT_LT(difference.max_abs_alpha, 1e-2);
}

std::string reference_name(const ::testing::TestParamInfo<IndependentReference>& info) {
  return std::string(info.param.scene) + "_view" + std::to_string(info.param.view);
}

INSTANTIATE_TEST_SUITE_P(SharedScenes, ReferenceVsIndependent,
                         ::testing::Values(IndependentReference{"playcanvas_test_64_sh3", 0},
                                           IndependentReference{"playcanvas_test_64_sh3", 3},
                                           IndependentReference{"playbot_lod6_1873_sh2", 0},
                                           IndependentReference{"playbot_lod6_1873_sh2", 3},
                                           IndependentReference{"playbot_lod3_31000_sh2", 0},
                                           IndependentReference{"playbot_lod3_31000_sh2", 3},
                                           IndependentReference{"guitar_90854_sh0", 0},
                                           IndependentReference{"guitar_90854_sh0", 3},
                                           IndependentReference{"plant_113648_sh0", 0},
                                           IndependentReference{"plant_113648_sh0", 3},
                                           IndependentReference{"biker_152746_sh0", 0},
                                           IndependentReference{"biker_152746_sh0", 3}),
                         reference_name);

}  // namespace
}  // namespace tilesplat
