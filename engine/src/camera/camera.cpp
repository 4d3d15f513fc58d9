// Camera helpers: the models' names and checks, world-to-camera transform, resizing, look-at and orbit
// framing.
#include "tilesplat/camera.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "camera/camera_models.h"

namespace tilesplat {
namespace {

using Vec3 = std::array<double, 3>;

Vec3 subtract(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 scaled(const Vec3& v, double s) { return {v[0] * s, v[1] * s, v[2] * s}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double length(const Vec3& v) { return std::sqrt(dot(v, v)); }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

double degrees_to_radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// Rounds a scaled image dimension, never below one pixel.
int scaled_dimension(double value) { return std::max(1, static_cast<int>(std::lround(value))); }

// Rodrigues' rotation of v by `angle` radians about the unit `axis`.
Vec3 rotated(const Vec3& v, const Vec3& axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const Vec3 across = cross(axis, v);
  const double along = dot(axis, v) * (1 - c);
  return {v[0] * c + across[0] * s + axis[0] * along, v[1] * c + across[1] * s + axis[1] * along,
          v[2] * c + across[2] * s + axis[2] * along};
}

}  // namespace

const char* camera_model_name(CameraModel model) {
  switch (model) {
    case CameraModel::kPinhole:
      return "pinhole";
    case CameraModel::kOpenCV:
      return "opencv";
    case CameraModel::kFisheye:
      return "fisheye";
    case CameraModel::kOrthographic:
      return "orthographic";
    case CameraModel::kEquirectangular:
      return "equirectangular";
  }
  return "unknown";
}

CameraModel parse_camera_model(const std::string& name) {
  for (CameraModel model : {CameraModel::kPinhole, CameraModel::kOpenCV, CameraModel::kFisheye,
                            CameraModel::kOrthographic, CameraModel::kEquirectangular})
    if (name == camera_model_name(model)) return model;
  throw std::invalid_argument("unknown camera model '" + name +
                              "' (known: pinhole, opencv, fisheye, orthographic, equirectangular)");
}

void validate(const Camera& camera) {
  auto fail = [](const std::string& why) { throw std::invalid_argument("invalid camera: " + why); };
  if (camera.width <= 0 || camera.height <= 0)
    fail("image size " + std::to_string(camera.width) + "x" + std::to_string(camera.height) + " is not positive");
  if (!std::isfinite(camera.fx) || !std::isfinite(camera.fy) || !(camera.fx > 0) || !(camera.fy > 0))
    fail("focal lengths must be positive and finite");
  if (!std::isfinite(camera.cx) || !std::isfinite(camera.cy)) fail("non-finite principal point");
  auto finite = [](double v) { return std::isfinite(v); };
  if (!std::all_of(camera.rotation.begin(), camera.rotation.end(), finite)) fail("non-finite rotation");
  if (!std::all_of(camera.position.begin(), camera.position.end(), finite)) fail("non-finite position");
  const int coefficients = camera.model == CameraModel::kOpenCV    ? 8
                           : camera.model == CameraModel::kFisheye ? 4
                                                                   : 0;
  if (camera.model != CameraModel::kPinhole && camera.model != CameraModel::kOpenCV &&
      camera.model != CameraModel::kFisheye && camera.model != CameraModel::kOrthographic &&
      camera.model != CameraModel::kEquirectangular)
    fail("unknown camera model " + std::to_string(int(camera.model)));
  for (size_t k = 0; k < camera.distortion.size(); ++k) {
    if (!std::isfinite(camera.distortion[k])) fail("non-finite distortion coefficient " + std::to_string(k));
    if (int(k) >= coefficients && camera.distortion[k] != 0)
      fail(std::string("the ") + camera_model_name(camera.model) + " camera has " +
           std::to_string(coefficients) + " distortion coefficients, but coefficient " + std::to_string(k) +
           " is " + std::to_string(camera.distortion[k]));
  }
}

Camera fisheye_camera(const Camera& camera, double field_of_view_deg) {
  if (!(field_of_view_deg > 0 && field_of_view_deg <= 360))
    throw std::invalid_argument("fisheye_camera: the field of view must be in (0, 360] degrees, got " +
                                std::to_string(field_of_view_deg));
  Camera fisheye = camera;
  fisheye.model = CameraModel::kFisheye;
  fisheye.distortion = {};
  // Equidistant: the pixel radius is f theta, and theta = fov / 2 lands on the shorter side's edge.
  fisheye.fx = fisheye.fy =
      0.5 * std::min(camera.width, camera.height) / degrees_to_radians(0.5 * field_of_view_deg);
  return fisheye;
}

Camera equirectangular_camera(const Camera& camera) {
  Camera panorama = camera;
  panorama.model = CameraModel::kEquirectangular;
  panorama.distortion = {};
  panorama.fx = camera.width / (2 * std::numbers::pi);
  panorama.fy = camera.height / std::numbers::pi;
  panorama.cx = camera.width / 2.0;
  panorama.cy = camera.height / 2.0;
  return panorama;
}

Camera orthographic_camera(const Camera& camera, double view_height) {
  if (!(std::isfinite(view_height) && view_height > 0))
    throw std::invalid_argument("orthographic_camera: the view height must be positive and finite, got " +
                                std::to_string(view_height));
  Camera orthographic = camera;
  orthographic.model = CameraModel::kOrthographic;
  orthographic.distortion = {};
  orthographic.fx = orthographic.fy = camera.height / view_height;
  return orthographic;
}

std::array<double, 3> Camera::to_camera(const std::array<double, 3>& world) const {
  // Evaluated as W x + t with t = -W c, the view-matrix form the trainer's rasterizer uses: equal
  // to W (x - c) mathematically, and rounding the same way keeps near-equal depths in the same
  // order as the independent float64 reference images.
  Vec3 camera_space{};
  for (size_t row = 0; row < 3; ++row) {
    const double* w = &rotation[row * 3];
    const double translation = -(w[0] * position[0] + w[1] * position[1] + w[2] * position[2]);
    camera_space[row] = w[0] * world[0] + w[1] * world[1] + w[2] * world[2] + translation;
  }
  return camera_space;
}

std::optional<std::array<double, 2>> Camera::project(const std::array<double, 3>& world) const {
  const camera_models::CentreProjection centre = camera_models::project_point(*this, to_camera(world));
  if (!centre.visible || !std::isfinite(centre.pixel[0]) || !std::isfinite(centre.pixel[1]))
    return std::nullopt;
  return centre.pixel;
}

std::optional<std::array<double, 3>> Camera::ray_direction(double u, double v) const {
  Vec3 ray{};
  if (!camera_models::pixel_ray(*this, u, v, ray)) return std::nullopt;
  // Camera to world: the rotation's transpose (its rows are the camera's axes in world space).
  Vec3 world{};
  for (size_t k = 0; k < 3; ++k)
    world[k] = rotation[k] * ray[0] + rotation[3 + k] * ray[1] + rotation[6 + k] * ray[2];
  return world;
}

Camera resize_camera(const Camera& camera, int width, int height) {
  if (camera.width <= 0 || camera.height <= 0)
    throw std::invalid_argument("resize_camera: the camera has no size");
  if (width <= 0 && height <= 0) return camera;
  if (width <= 0) width = scaled_dimension(double(height) * camera.width / camera.height);
  if (height <= 0) height = scaled_dimension(double(width) * camera.height / camera.width);

  const double scale_x = double(width) / camera.width;
  const double scale_y = double(height) / camera.height;
  Camera resized = camera;
  resized.width = width;
  resized.height = height;
  resized.fx = camera.fx * scale_x;
  resized.cx = camera.cx * scale_x;
  resized.fy = camera.fy * scale_y;
  resized.cy = camera.cy * scale_y;
  return resized;
}

Camera look_at_camera(const std::array<double, 3>& eye, const std::array<double, 3>& target,
                      const std::array<double, 3>& up, int width, int height, double vertical_fov_deg) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("look_at_camera: width and height must be positive");
  if (!(vertical_fov_deg > 0 && vertical_fov_deg < 180))
    throw std::invalid_argument("look_at_camera: vertical_fov_deg must be in (0, 180)");

  const Vec3 to_target = subtract(target, eye);
  const double distance = length(to_target);
  if (!(distance > 0) || !std::isfinite(distance))
    throw std::invalid_argument("look_at_camera: eye and target must be distinct finite points");
  const Vec3 forward = scaled(to_target, 1.0 / distance);

  // Camera y points down, i.e. along -up with its component along the view direction removed.
  // When up is (nearly) parallel to the view direction any perpendicular will do; pick the
  // world axis least aligned with forward so the result is still well conditioned.
  Vec3 world_up = up;
  const double up_length = length(world_up);
  if (!(up_length > 0) || !std::isfinite(up_length)) world_up = {0, -1, 0};
  world_up = scaled(world_up, 1.0 / length(world_up));
  Vec3 down = scaled(subtract(world_up, scaled(forward, dot(world_up, forward))), -1.0);
  if (length(down) < 1e-9) {
    size_t least_aligned = 0;
    for (size_t k = 1; k < 3; ++k)
      if (std::abs(forward[k]) < std::abs(forward[least_aligned])) least_aligned = k;
    Vec3 axis = {0, 0, 0};
    axis[least_aligned] = 1;
    down = subtract(axis, scaled(forward, dot(axis, forward)));
  }
  down = scaled(down, 1.0 / length(down));
  // Right-handed OpenCV frame: x = y cross z.
  const Vec3 right = cross(down, forward);

  Camera camera;
  camera.width = width;
  camera.height = height;
  camera.fy = height / (2.0 * std::tan(degrees_to_radians(vertical_fov_deg) / 2.0));
  camera.fx = camera.fy;  // square pixels
  camera.cx = width / 2.0;
  camera.cy = height / 2.0;
  // Rows of world-to-camera are the camera axes expressed in world space.
  camera.rotation = {right[0], right[1], right[2], down[0], down[1], down[2], forward[0], forward[1], forward[2]};
  camera.position = eye;
  return camera;
}

Camera orbit_camera(const Bounds& bounds, int width, int height, const OrbitParams& params) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("orbit_camera: width and height must be positive");
  const Vec3 center = {bounds.center[0], bounds.center[1], bounds.center[2]};
  const double radius = (bounds.radius > 0 && std::isfinite(bounds.radius)) ? bounds.radius : 1.0;

  // The sphere of the bounds fits the narrower of the two fields of view.
  const double tan_half_vertical = std::tan(degrees_to_radians(params.vertical_fov_deg) / 2.0);
  const double tan_half_horizontal = tan_half_vertical * width / height;
  const double half_fov = std::atan(std::min(tan_half_vertical, tan_half_horizontal));
  const double distance = radius / std::sin(half_fov) * params.distance_scale;

  // Trainer captures (COLMAP/OpenCV) have -Y up. Azimuth 0 sits on +Z looking toward -Z and
  // positive azimuth turns toward -X, the convention of the shared scenes' orbit cameras.
  const Vec3 world_up = {0, -1, 0};
  const double azimuth = degrees_to_radians(params.azimuth_deg);
  const double elevation = degrees_to_radians(params.elevation_deg);
  const Vec3 offset = {-std::sin(azimuth) * std::cos(elevation), -std::sin(elevation),
                       std::cos(azimuth) * std::cos(elevation)};
  const Vec3 eye = {center[0] + distance * offset[0], center[1] + distance * offset[1],
                    center[2] + distance * offset[2]};
  return look_at_camera(eye, center, world_up, width, height, params.vertical_fov_deg);
}

Camera turn_camera(const Camera& camera, const std::array<double, 3>& pivot, const std::array<double, 3>& axis,
                   double radians) {
  Camera turned = camera;
  const Vec3 offset = rotated(subtract(camera.position, pivot), axis, radians);
  for (int i = 0; i < 3; ++i) turned.position[i] = pivot[i] + offset[i];
  // Row k of the world-to-camera rotation is the camera's axis k in world space: each turns alike.
  for (int k = 0; k < 3; ++k) {
    const Vec3 row = rotated({camera.rotation[3 * k], camera.rotation[3 * k + 1], camera.rotation[3 * k + 2]}, axis,
                             radians);
    std::copy(row.begin(), row.end(), turned.rotation.begin() + 3 * k);
  }
  return turned;
}

}  // namespace tilesplat
