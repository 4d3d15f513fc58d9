// Camera paths for videos: orbits, and keyframes read from JSON and interpolated (Catmull-Rom
// positions, slerped rotations, linear field of view).
#include "tilesplat/camera_path.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "camera/json_file.h"
#include "camera/rotation_check.h"
#include "camera/rotation_interpolation.h"

namespace tilesplat {
namespace {

using nlohmann::json;
using Vec3 = std::array<double, 3>;
// The uniform Catmull-Rom segment from p1 (s = 0) to p2 (s = 1).
Vec3 catmull_rom(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3, double s) {
  Vec3 point;
  for (size_t k = 0; k < 3; ++k)
    point[k] = 0.5 * (2 * p1[k] + (p2[k] - p0[k]) * s + (2 * p0[k] - 5 * p1[k] + 4 * p2[k] - p3[k]) * s * s +
                      (3 * p1[k] - p0[k] - 3 * p2[k] + p3[k]) * s * s * s);
  return point;
}

// "FILE: keyframe N: MESSAGE".
[[noreturn]] void fail(const std::string& file, size_t key, const std::string& message) {
  throw SceneError(file + ": keyframe " + std::to_string(key) + ": " + message);
}

Vec3 read_vector(const json& key, const char* name, const std::string& file, size_t index) {
  const json& value = key.at(name);
  if (!value.is_array() || value.size() != 3)
    fail(file, index, std::string("'") + name + "' must be 3 numbers");
  Vec3 vector;
  for (size_t k = 0; k < 3; ++k) {
    if (!value[k].is_number() || !std::isfinite(value[k].get<double>()))
      fail(file, index, std::string("'") + name + "' must be 3 finite numbers");
    vector[k] = value[k].get<double>();
  }
  return vector;
}

CameraKeyframe read_keyframe(const json& key, const std::string& file, size_t index) {
  if (!key.is_object()) fail(file, index, "must be an object");
  CameraKeyframe keyframe;
  if (!key.contains("position")) fail(file, index, "missing 'position'");
  keyframe.position = read_vector(key, "position", file, index);
  if (const auto fov = key.find("fov"); fov != key.end()) {
    if (!fov->is_number() || !(fov->get<double>() > 0 && fov->get<double>() < 180))
      fail(file, index, "'fov' must be a vertical field of view in degrees, in (0, 180)");
    keyframe.vertical_fov_deg = fov->get<double>();
  }

  const bool has_rotation = key.contains("rotation"), has_look_at = key.contains("look_at");
  if (has_rotation == has_look_at) fail(file, index, "give exactly one of 'rotation' and 'look_at'");
  if (has_look_at) {
    const Vec3 target = read_vector(key, "look_at", file, index);
    const Vec3 up = key.contains("up") ? read_vector(key, "up", file, index) : Vec3{0, -1, 0};
    try {
      keyframe.rotation =
          look_at_camera(keyframe.position, target, up, 1, 1, keyframe.vertical_fov_deg).rotation;
    } catch (const std::invalid_argument&) {
      fail(file, index, "'look_at' must differ from 'position'");
    }
    return keyframe;
  }
  // Camera-to-world with the camera axes as columns, as in the trainer's cameras.json.
  const json& rows = key.at("rotation");
  std::array<double, 9> camera_to_world{};
  if (!rows.is_array() || rows.size() != 3) fail(file, index, "'rotation' must be a 3x3 array");
  for (size_t r = 0; r < 3; ++r) {
    if (!rows[r].is_array() || rows[r].size() != 3) fail(file, index, "'rotation' must be a 3x3 array");
    for (size_t c = 0; c < 3; ++c) {
      if (!rows[r][c].is_number() || !std::isfinite(rows[r][c].get<double>()))
        fail(file, index, "'rotation' must hold finite numbers");
      camera_to_world[r * 3 + c] = rows[r][c].get<double>();
    }
  }
  if (const auto problem = rotation_problem(camera_to_world)) fail(file, index, "'rotation' " + *problem);
  keyframe.rotation = transposed(camera_to_world);
  return keyframe;
}

void check_size(int width, int height) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("camera path: width and height must be positive");
}

}  // namespace

CameraPath load_camera_path(const std::filesystem::path& path) {
  const std::string file = path.string();
  const json document = parse_json_file(path);
  if (!document.is_object() || !document.contains("keyframes") || !document.at("keyframes").is_array())
    throw SceneError(file + ": expected an object with a \"keyframes\" array (docs/camera-paths.md)");
  CameraPath camera_path;
  if (const auto loop = document.find("loop"); loop != document.end()) {
    if (!loop->is_boolean()) throw SceneError(file + ": 'loop' must be true or false");
    camera_path.loop = loop->get<bool>();
  }
  const json& keys = document.at("keyframes");
  for (size_t index = 0; index < keys.size(); ++index)
    camera_path.keys.push_back(read_keyframe(keys[index], file, index));
  if (camera_path.keys.size() < 2)
    throw SceneError(file + ": a camera path needs at least 2 keyframes, found " +
                     std::to_string(keys.size()));
  return camera_path;
}

Camera camera_on_path(const CameraPath& path, double t, int width, int height) {
  check_size(width, height);
  const auto& keys = path.keys;
  if (keys.size() < 2) throw std::invalid_argument("camera_on_path: a path needs at least 2 keyframes");
  if (!(t >= 0 && t <= 1)) throw std::invalid_argument("camera_on_path: t must be in [0, 1]");

  const auto count = static_cast<long>(keys.size());
  const long segments = path.loop ? count : count - 1;
  const double u = t * static_cast<double>(segments);
  const long segment = std::min(static_cast<long>(u), segments - 1);
  const double s = u - static_cast<double>(segment);
  // A loop wraps around; an open path repeats its end keys.
  auto key = [&](long i) -> const CameraKeyframe& {
    if (path.loop) return keys[static_cast<size_t>(((i % count) + count) % count)];
    return keys[static_cast<size_t>(std::clamp(i, 0L, count - 1))];
  };
  const CameraKeyframe& from = key(segment);
  const CameraKeyframe& to = key(segment + 1);

  const Vec3 position =
      catmull_rom(key(segment - 1).position, from.position, to.position, key(segment + 2).position, s);
  const double fov = (1 - s) * from.vertical_fov_deg + s * to.vertical_fov_deg;
  Camera camera = look_at_camera({0, 0, 0}, {0, 0, 1}, {0, -1, 0}, width, height, fov);  // the intrinsics
  camera.position = position;
  camera.rotation =
      s == 0 ? from.rotation : matrix_of(slerp(quaternion_of(from.rotation), quaternion_of(to.rotation), s));
  return camera;
}

std::vector<Camera> sample_camera_path(const CameraPath& path, int frames, int width, int height) {
  if (frames < 1) throw std::invalid_argument("sample_camera_path: frames must be at least 1");
  std::vector<Camera> cameras;
  cameras.reserve(static_cast<size_t>(frames));
  const double steps = path.loop ? frames : std::max(frames - 1, 1);
  for (int f = 0; f < frames; ++f) cameras.push_back(camera_on_path(path, f / steps, width, height));
  return cameras;
}

std::vector<Camera> orbit_cameras(const Bounds& bounds, int frames, int width, int height,
                                  const OrbitParams& params) {
  if (frames < 1) throw std::invalid_argument("orbit_cameras: frames must be at least 1");
  check_size(width, height);
  std::vector<Camera> cameras;
  cameras.reserve(static_cast<size_t>(frames));
  for (int f = 0; f < frames; ++f) {
    OrbitParams at = params;
    at.azimuth_deg = params.azimuth_deg + 360.0 * f / frames;
    cameras.push_back(orbit_camera(bounds, width, height, at));
  }
  return cameras;
}

}  // namespace tilesplat
