// Reads the original trainer's cameras.json: camera centres and camera-to-world rotations.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "camera/json_file.h"
#include "camera/rotation_check.h"
#include "tilesplat/camera.h"
#include "tilesplat/scene_error.h"

namespace tilesplat {
namespace {

using nlohmann::json;

// Builds "FILE: entry N: MESSAGE" errors for one entry of the file.
class EntryContext {
 public:
  EntryContext(std::string file, size_t index) : file_(std::move(file)), index_(index) {}

  [[noreturn]] void fail(const std::string& message) const {
    throw SceneError(file_ + ": entry " + std::to_string(index_) + ": " + message);
  }

  const json& field(const json& entry, const char* name) const {
    const auto it = entry.find(name);
    if (it == entry.end()) fail(std::string("missing field '") + name + "'");
    return *it;
  }

  double finite_number(const json& value, const std::string& what) const {
    if (!value.is_number()) fail(what + " must be a number");
    const double number = value.get<double>();
    if (!std::isfinite(number)) fail(what + " must be a finite number");
    return number;
  }

  double positive_number(const json& entry, const char* name) const {
    const json& value = field(entry, name);
    const std::string what = std::string("'") + name + "'";
    if (!value.is_number()) fail(what + " must be a positive finite number");
    const double number = value.get<double>();
    if (!std::isfinite(number) || !(number > 0)) fail(what + " must be a positive finite number");
    return number;
  }

  int positive_integer(const json& entry, const char* name) const {
    const json& value = field(entry, name);
    const std::string what = std::string("'") + name + "'";
    if (!value.is_number()) fail(what + " must be a positive integer");
    const double number = value.get<double>();
    // Some writers store sizes as 1920.0; accept integral floats, reject everything else.
    if (!std::isfinite(number) || !(number >= 1) || number > 1e9 || std::floor(number) != number)
      fail(what + " must be a positive integer");
    return static_cast<int>(number);
  }

 private:
  std::string file_;
  size_t index_;
};

// cameras.json rotation is camera-to-world with the camera axes as its columns; the engine keeps
// world-to-camera, which for a rotation is the transpose.
std::array<double, 9> read_world_to_camera(const json& entry, const EntryContext& context) {
  const json& rows = context.field(entry, "rotation");
  if (!rows.is_array() || rows.size() != 3) context.fail("'rotation' must be a 3x3 array");
  std::array<double, 9> camera_to_world{};
  for (size_t r = 0; r < 3; ++r) {
    if (!rows[r].is_array() || rows[r].size() != 3) context.fail("'rotation' must be a 3x3 array");
    for (size_t c = 0; c < 3; ++c)
      camera_to_world[r * 3 + c] = context.finite_number(
          rows[r][c], "'rotation'[" + std::to_string(r) + "][" + std::to_string(c) + "]");
  }
  if (const auto problem = rotation_problem(camera_to_world)) context.fail("'rotation' " + *problem);
  return transposed(camera_to_world);
}

CameraView read_entry(const json& entry, size_t index, const std::string& file) {
  const EntryContext context(file, index);
  if (!entry.is_object()) context.fail("must be an object");

  CameraView view;
  view.id = static_cast<int>(index);
  if (const auto it = entry.find("id"); it != entry.end()) {
    if (!it->is_number_integer()) context.fail("'id' must be an integer");
    const auto id = it->get<long long>();
    if (id < std::numeric_limits<int>::min() || id > std::numeric_limits<int>::max())
      context.fail("'id' is out of range");
    view.id = static_cast<int>(id);
  }
  if (const auto it = entry.find("img_name"); it != entry.end()) {
    if (!it->is_string()) context.fail("'img_name' must be a string");
    view.name = it->get<std::string>();
  }

  Camera& camera = view.camera;
  camera.width = context.positive_integer(entry, "width");
  camera.height = context.positive_integer(entry, "height");
  camera.fx = context.positive_number(entry, "fx");
  camera.fy = context.positive_number(entry, "fy");
  camera.cx = camera.width / 2.0;
  camera.cy = camera.height / 2.0;

  const json& position = context.field(entry, "position");
  if (!position.is_array() || position.size() != 3) context.fail("'position' must be an array of 3 numbers");
  for (size_t k = 0; k < 3; ++k)
    camera.position[k] = context.finite_number(position[k], "'position'[" + std::to_string(k) + "]");

  camera.rotation = read_world_to_camera(entry, context);
  return view;
}

}  // namespace

std::vector<CameraView> load_cameras_json(const std::filesystem::path& path) {
  const std::string file = path.string();
  const json document = parse_json_file(path);
  if (!document.is_array()) throw SceneError(file + ": expected a JSON array of cameras");
  if (document.empty()) throw SceneError(file + ": the camera list is empty");

  std::vector<CameraView> views;
  views.reserve(document.size());
  for (size_t index = 0; index < document.size(); ++index) views.push_back(read_entry(document[index], index, file));
  return views;
}

}  // namespace tilesplat
