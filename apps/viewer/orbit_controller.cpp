#include "orbit_controller.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace tilesplat::viewer {

namespace {

using Vec3 = std::array<double, 3>;

constexpr Vec3 kWorldUp = {0, -1, 0};

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Camera::rotation is world to camera, row-major: row k is the camera's axis k (x right, y down,
// z forward) in world space.
Vec3 axis(const Camera& camera, int k) {
  return {camera.rotation[3 * k], camera.rotation[3 * k + 1], camera.rotation[3 * k + 2]};
}

}  // namespace

OrbitController::OrbitController(const Camera& camera, const Bounds& scene_bounds)
    : camera_(camera),
      pivot_{scene_bounds.center[0], scene_bounds.center[1], scene_bounds.center[2]},
      min_depth_(1e-3 * (scene_bounds.radius > 0 ? scene_bounds.radius : 1.0)) {}

void OrbitController::set_camera(const Camera& camera) {
  const int width = camera_.width, height = camera_.height;
  camera_ = camera;
  resize(width, height);
}

void OrbitController::resize(int width, int height) {
  if (width == camera_.width && height == camera_.height) return;
  const double scale = double(height) / camera_.height;
  camera_.fx *= scale;  // fx too follows the height: pixels stay square
  camera_.fy *= scale;
  camera_.cx *= double(width) / camera_.width;
  camera_.cy *= scale;
  camera_.width = width;
  camera_.height = height;
}

void OrbitController::orbit(double dx, double dy) {
  const double radians_per_pixel = std::numbers::pi / camera_.height;
  camera_ = turn_camera(camera_, pivot_, kWorldUp, -dx * radians_per_pixel);
  // Tilting past the pole would turn the image upside down and make the next horizontal drag
  // go the wrong way: such a step is not taken.
  const Camera tilted = turn_camera(camera_, pivot_, axis(camera_, 0), -dy * radians_per_pixel);
  if (std::abs(dot(axis(tilted, 2), kWorldUp)) < 0.99) camera_ = tilted;
}

void OrbitController::turn(double degrees) {
  camera_ = turn_camera(camera_, pivot_, kWorldUp, degrees * std::numbers::pi / 180.0);
}

void OrbitController::pan(double dx, double dy) {
  const Vec3 to_pivot = {pivot_[0] - camera_.position[0], pivot_[1] - camera_.position[1],
                         pivot_[2] - camera_.position[2]};
  const double depth = std::max(dot(to_pivot, axis(camera_, 2)), min_depth_);
  const Vec3 right = axis(camera_, 0), down = axis(camera_, 1);
  for (int i = 0; i < 3; ++i) {
    const double shift = -(dx * depth / camera_.fx) * right[i] - (dy * depth / camera_.fy) * down[i];
    camera_.position[i] += shift;
    pivot_[i] += shift;
  }
}

void OrbitController::zoom(double steps) {
  const Vec3 forward = axis(camera_, 2);
  const Vec3 to_pivot = {pivot_[0] - camera_.position[0], pivot_[1] - camera_.position[1],
                         pivot_[2] - camera_.position[2]};
  const double depth = std::max(dot(to_pivot, forward), min_depth_);
  const double move = depth * (1 - std::pow(0.85, steps));
  for (int i = 0; i < 3; ++i) camera_.position[i] += move * forward[i];
}

}  // namespace tilesplat::viewer
