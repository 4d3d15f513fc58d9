// The camera models' float64 math (engine/src/camera/camera_models.*): each model's Jacobian against
// central differences of its own projection, its inverse (pixel_ray) against the projection, and the
// limits where a model stops drawing.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "camera/camera_models.h"
#include "tilesplat/camera.h"

using namespace tilesplat;
using namespace tilesplat::camera_models;

namespace {

Camera model_camera(CameraModel model, std::array<double, 8> distortion) {
  Camera camera;
  camera.width = 640;
  camera.height = 480;
  camera.fx = 400;
  camera.fy = 410;
  camera.cx = 330;
  camera.cy = 236;
  camera.model = model;
  camera.distortion = distortion;
  return camera;
}

const Camera kCameras[] = {
    model_camera(CameraModel::kPinhole, {}),
    model_camera(CameraModel::kOpenCV, {-0.12, 0.03, 0.001, -0.0015, 0.002, 0.01, -0.003, 0.0005}),
    model_camera(CameraModel::kFisheye, {0.05, -0.01, 0.002, -0.0003}),
    model_camera(CameraModel::kOrthographic, {}),
    equirectangular_camera(model_camera(CameraModel::kPinhole, {})),
};

}  // namespace

TEST(CameraModelMath, JacobiansAreTheDerivativesOfTheProjection) {
  const std::array<double, 3> points[] = {{0.3, -0.2, 2.0}, {-0.5, 0.4, 1.5}, {0.0, 0.0, 3.0}, {1e-9, 0, 2}};
  for (const Camera& camera : kCameras) {
    const ModelLimits limits = model_limits(camera);
    for (const auto& t : points) {
      const CentreProjection centre = project_centre(camera, limits, t, 0.01);
      ASSERT_TRUE(centre.visible) << camera_model_name(camera.model);
      for (size_t axis = 0; axis < 3; ++axis) {
        const double step = 1e-6;
        auto plus = t, minus = t;
        plus[axis] += step;
        minus[axis] -= step;
        const auto a = project_centre(camera, limits, plus, 0.01).pixel;
        const auto b = project_centre(camera, limits, minus, 0.01).pixel;
        const double du = (a[0] - b[0]) / (2 * step), dv = (a[1] - b[1]) / (2 * step);
        EXPECT_NEAR(centre.jacobian_u[axis], du, 1e-4 * (1 + std::abs(du)))
            << camera_model_name(camera.model);
        EXPECT_NEAR(centre.jacobian_v[axis], dv, 1e-4 * (1 + std::abs(dv)))
            << camera_model_name(camera.model);
      }
    }
  }
}

TEST(CameraModelMath, PixelRaysInvertTheProjection) {
  for (const Camera& camera : kCameras) {
    if (camera.model == CameraModel::kOrthographic) continue;  // parallel rays: no centre to invert through
    for (const auto& [u, v] : {std::pair{0.5, 0.5}, {330.0, 236.0}, {639.5, 479.5}, {100.0, 400.0}}) {
      if (camera.model == CameraModel::kEquirectangular && (v < 1 || v > 479)) continue;  // the poles
      std::array<double, 3> ray{};
      ASSERT_TRUE(pixel_ray(camera, u, v, ray)) << camera_model_name(camera.model) << " " << u << "," << v;
      EXPECT_NEAR(std::hypot(ray[0], ray[1], ray[2]), 1.0, 1e-12);
      const auto back = project_point(camera, {3 * ray[0], 3 * ray[1], 3 * ray[2]});
      ASSERT_TRUE(back.visible);
      EXPECT_NEAR(back.pixel[0], u, 1e-7) << camera_model_name(camera.model);
      EXPECT_NEAR(back.pixel[1], v, 1e-7) << camera_model_name(camera.model);
    }
  }
}

TEST(CameraModelMath, ModelsStopWhereTheirMappingFolds) {
  // k1 = -0.3: r (1 - 0.3 r^2) grows until r = 1 / sqrt(0.9).
  const Camera barrel = model_camera(CameraModel::kOpenCV, {-0.3, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_NEAR(model_limits(barrel).reach, 1 / std::sqrt(0.9), 1e-9);
  EXPECT_FALSE(project_point(barrel, {1.1, 0, 1}).visible);  // past the fold: not drawn
  EXPECT_TRUE(project_point(barrel, {1.0, 0, 1}).visible);
  EXPECT_TRUE(std::isinf(model_limits(kCameras[1]).reach) || model_limits(kCameras[1]).reach > 1.5);
  // The equidistant fisheye draws everything but the point straight behind it.
  const Camera fisheye = fisheye_camera(model_camera(CameraModel::kPinhole, {}), 360);
  EXPECT_DOUBLE_EQ(model_limits(fisheye).reach, std::numbers::pi);
  const auto behind = project_point(fisheye, {0.1, 0, -1});  // 174 degrees off the axis
  ASSERT_TRUE(behind.visible);
  EXPECT_NEAR(behind.pixel[0] - fisheye.cx, fisheye.fx * (std::numbers::pi - std::atan(0.1)), 1e-9);
  EXPECT_NEAR(behind.depth, std::hypot(0.1, 1.0), 1e-15);  // a fisheye's depth is the distance
  EXPECT_FALSE(project_point(fisheye, {0, 0, -1}).visible);
  // k1 = -0.2: theta (1 - 0.2 theta^2) grows until theta = sqrt(1 / 0.6).
  Camera folding = fisheye;
  folding.distortion = {-0.2, 0, 0, 0, 0, 0, 0, 0};
  EXPECT_NEAR(model_limits(folding).reach, std::sqrt(1 / 0.6), 1e-9);
}
