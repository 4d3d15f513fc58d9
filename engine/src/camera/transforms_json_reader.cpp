// Reads nerfstudio / instant-ngp transforms.json camera sets, and tells the camera set formats apart.
#include <cctype>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "camera/json_file.h"
#include "camera/rotation_check.h"
#include "tilesplat/camera_sets.h"

namespace tilesplat {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The intrinsics a frame inherits from the top level unless it gives its own.
class FrameFields {
 public:
  FrameFields(const json& top, const json& frame, std::string where)
      : top_(top), frame_(frame), where_(std::move(where)) {}

  std::optional<double> number(const char* name) const {
    const json* value = frame_.contains(name) ? &frame_[name] : top_.contains(name) ? &top_[name] : nullptr;
    if (value == nullptr || value->is_null()) return std::nullopt;
    if (!value->is_number() || !std::isfinite(value->get<double>()))
      fail(std::string("'") + name + "' must be a finite number");
    return value->get<double>();
  }
  std::optional<std::string> text(const char* name) const {
    const json* value = frame_.contains(name) ? &frame_[name] : top_.contains(name) ? &top_[name] : nullptr;
    if (value == nullptr) return std::nullopt;
    if (!value->is_string()) fail(std::string("'") + name + "' must be a string");
    return value->get<std::string>();
  }
  [[noreturn]] void fail(const std::string& message) const { throw SceneError(where_ + ": " + message); }

 private:
  const json& top_;
  const json& frame_;
  std::string where_;
};

int image_dimension(const FrameFields& fields, const char* name) {
  const auto value = fields.number(name);
  if (!value) fields.fail(std::string("missing '") + name + "' (the image size; give w and h)");
  if (!(*value >= 1 && *value <= (1 << 20)) || std::floor(*value) != *value)
    fields.fail(std::string("'") + name + "' must be a positive integer");
  return static_cast<int>(*value);
}

// nerfstudio's camera models: PINHOLE; OPENCV (k1 k2 k3 p1 p2, and the pinhole's default when the
// file names no model) as CameraModel::kOpenCV; OPENCV_FISHEYE (k1..k4) as kFisheye; EQUIRECTANGULAR
// (the focal lengths unused) as kEquirectangular. nerfstudio's k4 of
// OPENCV is a radial r^8 term, which OpenCV's model (a rational k4) does not have: refused unless 0.
void set_model(Camera& camera, const FrameFields& fields) {
  const std::string model = fields.text("camera_model").value_or("OPENCV");
  auto coefficient = [&](const char* name) { return fields.number(name).value_or(0.0); };
  if (model == "OPENCV_FISHEYE") {
    camera.model = CameraModel::kFisheye;
    camera.distortion = {
        coefficient("k1"), coefficient("k2"), coefficient("k3"), coefficient("k4"), 0, 0, 0, 0};
    if (coefficient("p1") != 0 || coefficient("p2") != 0)
      fields.fail("OPENCV_FISHEYE has no tangential distortion, but p1 or p2 is not zero");
  } else if (model == "OPENCV" || model == "PINHOLE") {
    if (coefficient("k4") != 0)
      fields.fail(
          "k4 of an OPENCV camera is nerfstudio's r^8 term, which the renderer's OpenCV model does "
          "not have: undistort the images, or give k4 = 0");
    camera.distortion = {coefficient("k1"),
                         coefficient("k2"),
                         coefficient("p1"),
                         coefficient("p2"),
                         coefficient("k3"),
                         0,
                         0,
                         0};
    if (model == "PINHOLE" && camera.distortion != std::array<double, 8>{})
      fields.fail("camera_model PINHOLE has distortion coefficients: say OPENCV, or give none");
    const bool distorted = camera.distortion != std::array<double, 8>{};
    camera.model = distorted ? CameraModel::kOpenCV : CameraModel::kPinhole;
  } else if (model == "EQUIRECTANGULAR") {
    camera = equirectangular_camera(camera);  // nerfstudio's panoramas span 360x180 degrees of the image
  } else {
    fields.fail(
        "camera_model " + model +
        " is not one the renderer draws (PINHOLE, OPENCV, OPENCV_FISHEYE, EQUIRECTANGULAR): undistort the "
        "images to PINHOLE first");
  }
  for (const double k : camera.distortion)
    if (!std::isfinite(k)) fields.fail("the distortion coefficients must be finite");
}

CameraView read_frame(const json& top, const json& frame, size_t index, const std::string& file) {
  const std::string where = file + ": frame " + std::to_string(index);
  if (!frame.is_object()) throw SceneError(where + ": must be an object");
  const FrameFields fields(top, frame, where);

  CameraView view;
  view.id = static_cast<int>(index);
  if (const auto name = fields.text("file_path")) view.name = *name;
  Camera& camera = view.camera;
  camera.width = image_dimension(fields, "w");
  camera.height = image_dimension(fields, "h");
  auto focal_of_angle = [&](const char* name, int pixels) -> std::optional<double> {
    const auto angle = fields.number(name);
    if (!angle) return std::nullopt;
    if (!(*angle > 0 && *angle < std::numbers::pi))
      fields.fail(std::string("'") + name + "' must be in (0, pi) radians");
    return 0.5 * pixels / std::tan(0.5 * *angle);
  };
  const auto fx =
      fields.number("fl_x") ? fields.number("fl_x") : focal_of_angle("camera_angle_x", camera.width);
  if (!fx) fields.fail("missing the focal length: give fl_x (pixels) or camera_angle_x (radians)");
  auto fy = fields.number("fl_y") ? fields.number("fl_y") : focal_of_angle("camera_angle_y", camera.height);
  camera.fx = *fx;
  camera.fy = fy.value_or(*fx);  // square pixels unless told otherwise
  if (!(camera.fx > 0 && camera.fy > 0)) fields.fail("focal lengths must be positive");
  camera.cx = fields.number("cx").value_or(camera.width / 2.0);
  camera.cy = fields.number("cy").value_or(camera.height / 2.0);
  set_model(camera, fields);

  const json* matrix = frame.contains("transform_matrix") ? &frame["transform_matrix"] : nullptr;
  if (matrix == nullptr || !matrix->is_array() || matrix->size() < 3)
    fields.fail("missing 'transform_matrix' (a 4x4 camera-to-world matrix)");
  std::array<double, 9> camera_to_world{};
  for (size_t r = 0; r < 3; ++r) {
    const json& row = (*matrix)[r];
    if (!row.is_array() || row.size() != 4) fields.fail("'transform_matrix' must be 4 rows of 4 numbers");
    for (size_t c = 0; c < 4; ++c)
      if (!row[c].is_number() || !std::isfinite(row[c].get<double>()))
        fields.fail("'transform_matrix' must hold finite numbers");
    // OpenGL camera axes (y up, z backward) to the engine's (y down, z forward): negate columns 1, 2.
    camera_to_world[r * 3 + 0] = row[0].get<double>();
    camera_to_world[r * 3 + 1] = -row[1].get<double>();
    camera_to_world[r * 3 + 2] = -row[2].get<double>();
    camera.position[r] = row[3].get<double>();
  }
  if (const auto problem = rotation_problem(camera_to_world))
    fields.fail("the rotation of 'transform_matrix' " + *problem);
  camera.rotation = transposed(camera_to_world);
  return view;
}

}  // namespace

std::vector<CameraView> load_transforms_json(const fs::path& path) {
  const std::string file = path.string();
  const json document = parse_json_file(path);
  if (!document.is_object() || !document.contains("frames") || !document["frames"].is_array())
    throw SceneError(file + ": expected an object with a \"frames\" array (a transforms.json)");
  const json& frames = document["frames"];
  if (frames.empty()) throw SceneError(file + ": the frames list is empty");
  std::vector<CameraView> views;
  views.reserve(frames.size());
  for (size_t index = 0; index < frames.size(); ++index)
    views.push_back(read_frame(document, frames[index], index, file));
  return views;
}

std::vector<CameraView> load_camera_set(const fs::path& path) {
  std::error_code error;
  if (fs::is_directory(path, error) || path.extension() == ".bin" || path.extension() == ".txt")
    return load_colmap_cameras(path);
  // JSON: an object of frames is a transforms.json, an array the trainer's cameras.json. Only the
  // first character that is not white space is needed to tell.
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw SceneError(path.string() + ": cannot open file");
  char first = 0;
  while (stream.get(first) && std::isspace(static_cast<unsigned char>(first))) {
  }
  if (first == '{') return load_transforms_json(path);
  return load_cameras_json(path);
}

}  // namespace tilesplat
