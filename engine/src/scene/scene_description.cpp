// Reads scene descriptions (docs/scene-format.md): every mistake is a SceneError naming the file, the
// JSON path of the bad value, what is wrong and what is allowed.
#include "tilesplat/scene_description.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "camera/rotation_check.h"
#include "scene/json_reader.h"
#include "scene/scene_readers.h"
#include "tilesplat/shutter.h"

namespace tilesplat {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Limits that catch typos and unit mistakes; anything beyond them cannot be meant.
constexpr double kMinScale = 1e-6, kMaxScale = 1e6;
constexpr double kMaxAngleDeg = 360;
constexpr double kMaxFocal = 1e9;           // pixels
constexpr int kMaxImageSide = 65536;
constexpr double kMaxRadiance = 1e6;        // background and light colours, light intensity
constexpr double kMaxExposureStops = 20;
constexpr double kDefaultFovDeg = 50;
constexpr int kFormatVersion = 1;

constexpr auto kTopKeys = std::to_array<std::string_view>({"$schema", "version", "models", "cameras",
                                                      "background", "effects", "outputs"});
constexpr auto kModelKeys = std::to_array<std::string_view>(
    {"path", "translation", "rotation_deg", "quaternion", "scale", "z_up", "motion"});
constexpr auto kMotionKeys =
    std::to_array<std::string_view>({"translation", "rotation_deg", "quaternion", "scale"});
constexpr auto kCameraKeys = std::to_array<std::string_view>(
    {"name", "width", "height", "fx", "fy", "cx", "cy", "position", "rotation", "look_at", "model",
     "distortion", "view_height", "lens", "shutter"});
constexpr auto kShutterKeys = std::to_array<std::string_view>({"open", "close", "samples", "scan", "end"});
constexpr auto kShutterEndKeys = std::to_array<std::string_view>({"position", "rotation", "look_at"});
constexpr auto kShutterScans = std::to_array<std::string_view>(
    {"global", "top-to-bottom", "bottom-to-top", "left-to-right", "right-to-left"});
constexpr auto kLensKeys = std::to_array<std::string_view>(
    {"aperture", "f_stop", "sensor_width_mm", "units_per_metre", "focus_distance", "samples"});
constexpr auto kLookAtKeys = std::to_array<std::string_view>({"eye", "target", "up", "fov_deg"});
constexpr auto kEffectKeys = std::to_array<std::string_view>({"sh_degree", "view_dependent", "antialiasing",
                                                         "lights", "ambient", "exposure", "tone_map"});
constexpr auto kLightKeys = std::to_array<std::string_view>({"type", "direction", "position", "color",
                                                        "colour", "intensity"});
constexpr auto kAntialiasing = std::to_array<std::string_view>({"classic", "antialiased", "mip"});
constexpr auto kToneMaps = std::to_array<std::string_view>({"none", "aces", "reinhard"});
constexpr auto kLightTypes = std::to_array<std::string_view>({"directional", "point"});
constexpr auto kOutputs = std::to_array<std::string_view>({"color", "alpha", "depth", "splat_count"});

using namespace json_reader;

// --- models

ModelTransform read_rotation(const Reader& reader, const Node& model, ModelTransform transform) {
  const auto euler = reader.optional_child(model, "rotation_deg");
  const auto quaternion = reader.optional_child(model, "quaternion");
  if (euler && quaternion)
    reader.fail(model.path, "give either 'rotation_deg' or 'quaternion', not both");
  if (euler) transform.rotation = quaternion_from_euler_xyz_deg(reader.numbers<3>(*euler, -kMaxAngleDeg, kMaxAngleDeg));
  if (quaternion) {
    const auto q = reader.numbers<4>(*quaternion, -2, 2);
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(std::abs(norm - 1) <= 1e-3))
      reader.fail(quaternion->path, "must be a unit quaternion [w, x, y, z] (norm 1 within 0.001), its norm is " +
                                        format_number(norm));
    transform.rotation = {q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm};
  }
  return transform;
}

std::array<double, 3> read_scale(const Reader& reader, const Node& node) {
  std::array<double, 3> scale{};
  if (node.value.is_number()) {
    const double s = reader.number(node, kMinScale, kMaxScale);
    scale = {s, s, s};
  } else if (node.value.is_array()) {
    scale = reader.numbers<3>(node, kMinScale, kMaxScale);
  } else {
    reader.fail(node.path, "must be a number from " + format_number(kMinScale) + " to " + format_number(kMaxScale) +
                               " (one uniform scale), got " + type_name(node.value));
  }
  ModelTransform probe;
  probe.scale = scale;
  try {
    validate(probe);
  } catch (const std::invalid_argument& error) {
    reader.fail(node.path, error.what());
  }
  return scale;
}

// A placement's translation, rotation and scale over `base` (a model's, or where its motion ends).
ModelTransform read_placement(const Reader& reader, const Node& node, ModelTransform base) {
  if (const auto t = reader.optional_child(node, "translation"))
    base.translation = reader.numbers<3>(*t, -kMaxCoordinate, kMaxCoordinate);
  base = read_rotation(reader, node, base);
  if (const auto s = reader.optional_child(node, "scale")) base.scale = read_scale(reader, *s);
  return base;
}

SceneModel read_model(const Reader& reader, const Node& model) {
  reader.expect_object(model, kModelKeys);
  SceneModel out;
  out.path = reader.existing_file(reader.required_child(model, "path", "the splat file (.ply) to load"), "splat file");
  out.transform = read_placement(reader, model, out.transform);
  if (const auto z_up = reader.optional_child(model, "z_up")) out.transform.z_up = reader.boolean(*z_up);
  // "motion": where the model is at time 1, each key over the model's own (and its z_up).
  if (const auto motion = reader.optional_child(model, "motion")) {
    reader.expect_object(*motion, kMotionKeys);
    out.motion = read_placement(reader, *motion, out.transform);
  }
  return out;
}

std::vector<SceneModel> read_models(const Reader& reader, const Node& root) {
  const Node models = reader.required_child(root, "models", "a list of {\"path\": \"file.ply\", ...}");
  const json& list = reader.array(models, "a non-empty list of models");
  if (list.empty()) reader.fail(models.path, "must list at least one model");
  std::vector<SceneModel> out;
  for (size_t i = 0; i < list.size(); ++i)
    out.push_back(read_model(reader, Node{list[i], element_path(models.path, i)}));
  return out;
}

// --- cameras

// A world-to-camera matrix given as three rows; it must be a rotation.
std::array<double, 9> read_camera_rotation(const Reader& reader, const Node& node) {
  if (!node.value.is_array() || node.value.size() != 3)
    reader.fail(node.path, "must be a 3x3 world-to-camera rotation given as 3 rows of 3 numbers, got " +
                               type_name(node.value));
  std::array<double, 9> m{};
  for (size_t r = 0; r < 3; ++r) {
    const auto row = reader.numbers<3>(Node{node.value[r], element_path(node.path, r)}, -1.001, 1.001);
    std::copy(row.begin(), row.end(), m.begin() + static_cast<std::ptrdiff_t>(r * 3));
  }
  if (const std::optional<std::string> problem = rotation_problem(m))
    reader.fail(node.path, "must be a rotation, but it " + *problem);
  return m;
}

// A look_at camera: the pinhole it describes, its distance to the target (a lens's default focus), and for
// a fisheye the field of view, which may reach 360 degrees (the pinhole then has a 50-degree one, for
// fisheye_camera() to replace).
struct LookAt {
  Camera camera;
  double target_distance = 0;
  double fisheye_fov = kDefaultFovDeg;
};
LookAt read_look_at(const Reader& reader, const Node& node, int width, int height, bool fisheye) {
  reader.expect_object(node, kLookAtKeys);
  const auto eye = reader.numbers<3>(reader.required_child(node, "eye", "the camera centre [x, y, z]"),
                                     -kMaxCoordinate, kMaxCoordinate);
  const Node target_node = reader.required_child(node, "target", "the point looked at [x, y, z]");
  const auto target = reader.numbers<3>(target_node, -kMaxCoordinate, kMaxCoordinate);
  std::array<double, 3> up = {0, -1, 0};  // the engine's world up (OpenCV/COLMAP captures)
  const auto up_node = reader.optional_child(node, "up");
  if (up_node) up = reader.nonzero_vector(*up_node);
  double fov = kDefaultFovDeg;
  LookAt out;
  if (fisheye) {
    if (const auto fov_node = reader.optional_child(node, "fov_deg")) {
      out.fisheye_fov = reader.number(*fov_node, 0, 360);
      if (!(out.fisheye_fov > 0))
        reader.fail(fov_node->path, "a fisheye's field of view must be above 0 and at most 360 degrees");
    }
  } else if (const auto fov_node = reader.optional_child(node, "fov_deg")) {
    fov = reader.number(*fov_node, 0, 180);
    if (!(fov > 0 && fov < 180))
      reader.fail(fov_node->path, "must be strictly between 0 and 180 degrees, got " + format_number(fov));
  }
  const std::array<double, 3> forward = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]};
  const double distance = std::hypot(forward[0], forward[1], forward[2]);
  if (!(distance > 0)) reader.fail(target_node.path, "must differ from 'eye'");
  const std::array<double, 3> side = {up[1] * forward[2] - up[2] * forward[1], up[2] * forward[0] - up[0] * forward[2],
                                      up[0] * forward[1] - up[1] * forward[0]};
  const double up_length = std::hypot(up[0], up[1], up[2]);
  if (std::hypot(side[0], side[1], side[2]) <= 1e-6 * up_length * distance)
    reader.fail(up_node ? up_node->path : node.path, "'up' is parallel to the view direction (eye to target): "
                                                     "the camera's roll is undefined");
  out.camera = look_at_camera(eye, target, up, width, height, fov);
  out.target_distance = distance;
  return out;
}

Camera read_pinhole(const Reader& reader, const Node& node, int width, int height) {
  Camera camera;
  camera.width = width;
  camera.height = height;
  const std::string focal = "the focal length in pixels (or use 'look_at')";
  camera.fx = reader.positive(reader.required_child(node, "fx", focal), kMaxFocal);
  camera.fy = reader.positive(reader.required_child(node, "fy", focal), kMaxFocal);
  camera.cx = width / 2.0;
  camera.cy = height / 2.0;
  if (const auto cx = reader.optional_child(node, "cx")) camera.cx = reader.number(*cx, -kMaxFocal, kMaxFocal);
  if (const auto cy = reader.optional_child(node, "cy")) camera.cy = reader.number(*cy, -kMaxFocal, kMaxFocal);
  camera.position = reader.numbers<3>(reader.required_child(node, "position", "the camera centre [x, y, z]"),
                                      -kMaxCoordinate, kMaxCoordinate);
  camera.rotation = read_camera_rotation(
      reader, reader.required_child(node, "rotation", "the world-to-camera rotation, 3 rows of 3 numbers"));
  return camera;
}

// "model": the camera's model (CameraModel); pinhole when absent.
CameraModel read_model_name(const Reader& reader, const Node& node) {
  const auto model_node = reader.optional_child(node, "model");
  if (!model_node) return CameraModel::kPinhole;
  return parse_camera_model(std::string(reader.choice(
      *model_node,
      std::to_array<std::string_view>({"pinhole", "opencv", "fisheye", "orthographic", "equirectangular"}))));
}

// "distortion" and "view_height" of a camera of `model`: its coefficients in OpenCV's order (k1 k2 p1 p2
// k3 k4 k5 k6; a fisheye's k1..k4; missing ones are 0), and an orthographic look_at camera's height in
// world units. `fisheye_fov`: a look_at fisheye's field of view across the shorter side. A look_at
// equirectangular camera spans 360x180 degrees of its image (equirectangular_camera).
void read_model(const Reader& reader, const Node& node, CameraModel model, bool look_at, double fisheye_fov,
                Camera& camera) {
  const auto distortion = reader.optional_child(node, "distortion");
  const auto view_height = reader.optional_child(node, "view_height");
  const size_t coefficients = model == CameraModel::kOpenCV ? 8 : model == CameraModel::kFisheye ? 4 : 0;
  if (look_at && model == CameraModel::kOpenCV)
    reader.fail(node.path,
                "an OpenCV camera's distortion is in units of its focal length: give fx and fy "
                "instead of 'look_at'");
  if (view_height && !(look_at && model == CameraModel::kOrthographic))
    reader.fail(view_height->path,
                "belongs to an orthographic camera with 'look_at' (with fx and fy, an "
                "orthographic camera's scale is in pixels per world unit)");
  if (look_at && model == CameraModel::kOrthographic && !view_height)
    reader.fail(node.path,
                "an orthographic 'look_at' camera needs 'view_height' (its height in world units)");
  if (look_at && model == CameraModel::kFisheye) camera = fisheye_camera(camera, fisheye_fov);
  if (look_at && model == CameraModel::kEquirectangular) camera = equirectangular_camera(camera);
  if (look_at && model == CameraModel::kOrthographic)
    camera = orthographic_camera(camera, reader.positive(*view_height, kMaxCoordinate));
  camera.model = model;
  if (distortion) {
    const json& values = reader.array(*distortion, "the distortion coefficients");
    if (values.size() > coefficients)
      reader.fail(distortion->path, "the " + std::string(camera_model_name(model)) + " camera has " +
                                        std::to_string(coefficients) + " distortion coefficients, got " +
                                        std::to_string(values.size()));
    for (size_t i = 0; i < values.size(); ++i)
      camera.distortion[i] = reader.number(Node{values[i], element_path(distortion->path, i)}, -1e6, 1e6);
  }
}

// A camera's "lens": the aperture as a diameter in scene units or as an f-number (with the sensor's width
// in millimetres and the scene's units per metre, aperture_for_f_stop), the focus distance (default: a
// look_at camera's distance to its target) and the samples.
ThinLens read_lens(const Reader& reader, const Node& node, const Camera& camera,
                   std::optional<double> target_distance) {
  reader.expect_object(node, kLensKeys);
  const auto aperture = reader.optional_child(node, "aperture");
  const auto f_stop = reader.optional_child(node, "f_stop");
  if (aperture.has_value() == f_stop.has_value())
    reader.fail(node.path,
                "give the aperture as 'aperture' (a diameter in scene units) or 'f_stop', one of them");
  for (const char* key : {"sensor_width_mm", "units_per_metre"})
    if (const auto child = reader.optional_child(node, key); child && !f_stop)
      reader.fail(child->path, "applies to 'f_stop' only");
  ThinLens lens;
  if (aperture) {
    lens.aperture_diameter = reader.positive(*aperture, kMaxCoordinate);
  } else {
    const double sensor = reader.optional_child(node, "sensor_width_mm")
                              ? reader.positive(*reader.optional_child(node, "sensor_width_mm"), 1e4)
                              : 36.0;
    const double units = reader.optional_child(node, "units_per_metre")
                             ? reader.positive(*reader.optional_child(node, "units_per_metre"), 1e9)
                             : 1.0;
    lens.aperture_diameter = aperture_for_f_stop(camera, reader.positive(*f_stop, 1e6), sensor, units);
  }
  if (const auto focus = reader.optional_child(node, "focus_distance"))
    lens.focus_distance = reader.positive(*focus, kMaxCoordinate);
  else if (target_distance)
    lens.focus_distance = *target_distance;
  else
    reader.fail(node.path,
                "missing 'focus_distance' (the view depth in focus; a 'look_at' camera focuses on its "
                "target)");
  if (const auto samples = reader.optional_child(node, "samples"))
    lens.samples = reader.integer(*samples, 1, kMaxLensSamples);
  if (camera.model != CameraModel::kPinhole)
    reader.fail(node.path,
                "depth of field needs a pinhole camera, not " + std::string(camera_model_name(camera.model)));
  return lens;
}

// A camera's "shutter": open and close times in [0, 1] of the frame's time, the samples (or a rolling
// shutter's bands), the scan, and "end", the camera at time 1: the same camera (size, intrinsics, model)
// at another pose, given as "position" and "rotation" or as "look_at" (eye, target, up). Without "end"
// the camera stays still, and the shutter blurs the models that move.
Shutter read_shutter(const Reader& reader, const Node& node, const Camera& camera) {
  reader.expect_object(node, kShutterKeys);
  Shutter shutter;
  if (const auto open = reader.optional_child(node, "open")) shutter.open = reader.number(*open, 0, 1);
  const Node close = reader.required_child(node, "close", "when the shutter closes, in (open, 1]");
  shutter.close = reader.number(close, 0, 1);
  if (!shutter.opens())
    reader.fail(close.path, "must be after 'open' (" + format_number(shutter.open) + "), got " +
                                format_number(shutter.close));
  if (const auto samples = reader.optional_child(node, "samples"))
    shutter.samples = reader.integer(*samples, 1, kMaxShutterSamples);
  if (const auto scan = reader.optional_child(node, "scan"))
    shutter.scan = parse_shutter_scan(std::string(reader.choice(*scan, kShutterScans)));
  if (const auto end = reader.optional_child(node, "end")) {
    reader.expect_object(*end, kShutterEndKeys);
    Camera moved = camera;
    if (const auto look_at = reader.optional_child(*end, "look_at")) {
      for (const char* key : {"position", "rotation"})
        if (const auto conflict = reader.optional_child(*end, key))
          reader.fail(conflict->path, "not allowed with 'look_at', which sets the pose");
      if (const auto fov = reader.optional_child(*look_at, "fov_deg"))
        reader.fail(fov->path, "the end camera keeps the camera's intrinsics: give its pose only");
      const Camera aimed = read_look_at(reader, *look_at, camera.width, camera.height, false).camera;
      moved.position = aimed.position;
      moved.rotation = aimed.rotation;
    } else {
      moved.position =
          reader.numbers<3>(reader.required_child(*end, "position", "the camera centre at time 1"),
                            -kMaxCoordinate, kMaxCoordinate);
      moved.rotation = read_camera_rotation(
          reader, reader.required_child(*end, "rotation", "the world-to-camera rotation at time 1, 3 rows"));
    }
    shutter.end_camera = moved;
  }
  return shutter;
}

CameraView read_camera(const Reader& reader, const Node& node, size_t index, ThinLens& lens,
                       Shutter& shutter) {
  reader.expect_object(node, kCameraKeys);
  CameraView view;
  view.id = static_cast<int>(index);
  if (const auto name = reader.optional_child(node, "name")) view.name = reader.string(*name);
  const int width = reader.integer(reader.required_child(node, "width", "the image width in pixels"), 1, kMaxImageSide);
  const int height =
      reader.integer(reader.required_child(node, "height", "the image height in pixels"), 1, kMaxImageSide);
  const auto look_at = reader.optional_child(node, "look_at");
  const CameraModel model = read_model_name(reader, node);
  double fisheye_fov = kDefaultFovDeg;
  std::optional<double> target_distance;  // a look_at camera's: its lens's default focus
  if (look_at) {
    for (const char* key : {"fx", "fy", "cx", "cy", "position", "rotation"})
      if (const auto conflict = reader.optional_child(node, key))
        reader.fail(conflict->path, "not allowed with 'look_at', which sets the pose and the focal length");
    const LookAt aimed = read_look_at(reader, *look_at, width, height, model == CameraModel::kFisheye);
    view.camera = aimed.camera;
    fisheye_fov = aimed.fisheye_fov;
    target_distance = aimed.target_distance;
  } else {
    view.camera = read_pinhole(reader, node, width, height);
  }
  read_model(reader, node, model, look_at.has_value(), fisheye_fov, view.camera);
  if (const auto lens_node = reader.optional_child(node, "lens"))
    lens = read_lens(reader, *lens_node, view.camera, target_distance);
  if (const auto shutter_node = reader.optional_child(node, "shutter"))
    shutter = read_shutter(reader, *shutter_node, view.camera);
  return view;
}

void read_cameras(const Reader& reader, const Node& node, SceneDescription& out) {
  if (node.value.is_string()) {
    out.cameras_file = reader.existing_file(node, "cameras file");
    try {
      out.cameras = load_cameras_json(out.cameras_file);
    } catch (const SceneError& error) {
      reader.fail(node.path, error.what());
    }
    return;
  }
  const json& list = reader.array(node, "a cameras.json path or a list of cameras");
  if (list.empty()) reader.fail(node.path, "must list at least one camera (leave 'cameras' out for none)");
  out.lenses.resize(list.size());
  out.shutters.resize(list.size());
  for (size_t i = 0; i < list.size(); ++i)
    out.cameras.push_back(
        read_camera(reader, Node{list[i], element_path(node.path, i)}, i, out.lenses[i], out.shutters[i]));
}

// --- effects and outputs

SceneLight read_light(const Reader& reader, const Node& node) {
  reader.expect_object(node, kLightKeys);
  SceneLight light;
  const Node type = reader.required_child(node, "type", "'directional' or 'point'");
  light.type = reader.choice(type, kLightTypes) == "point" ? SceneLight::Type::kPoint : SceneLight::Type::kDirectional;
  const auto direction = reader.optional_child(node, "direction");
  const auto position = reader.optional_child(node, "position");
  if (light.type == SceneLight::Type::kDirectional) {
    if (position) reader.fail(position->path, "a directional light has a 'direction', not a 'position'");
    const auto d = reader.nonzero_vector(reader.required_child(node, "direction", "where the light travels [x, y, z]"));
    const double length = std::hypot(d[0], d[1], d[2]);
    light.direction = {d[0] / length, d[1] / length, d[2] / length};
  } else {
    if (direction) reader.fail(direction->path, "a point light has a 'position', not a 'direction'");
    light.position = reader.numbers<3>(reader.required_child(node, "position", "the light's position [x, y, z]"),
                                       -kMaxCoordinate, kMaxCoordinate);
  }
  const auto color = reader.optional_child(node, "color");
  const auto colour = reader.optional_child(node, "colour");
  if (color && colour) reader.fail(colour->path, "give 'color' or 'colour' (the same thing), not both");
  if (color || colour) light.color = reader.numbers<3>(color ? *color : *colour, 0, kMaxRadiance);
  if (const auto intensity = reader.optional_child(node, "intensity"))
    light.intensity = reader.number(*intensity, 0, kMaxRadiance);
  return light;
}

std::optional<int> read_sh_degree(const Reader& reader, const Node& effects) {
  const auto degree_node = reader.optional_child(effects, "sh_degree");
  const auto view_dependent_node = reader.optional_child(effects, "view_dependent");
  std::optional<int> degree;
  if (degree_node) degree = reader.integer(*degree_node, 0, 3);
  if (!view_dependent_node) return degree;
  const bool view_dependent = reader.boolean(*view_dependent_node);
  if (degree && view_dependent != (*degree > 0))
    reader.fail(view_dependent_node->path, std::string("contradicts 'sh_degree': ") + std::to_string(*degree) +
                                               (view_dependent ? " is the DC colour alone, not view-dependent"
                                                               : " keeps view-dependent bands") +
                                               "; give one of the two");
  if (!view_dependent) return 0;
  return degree;
}

SceneEffects read_effects(const Reader& reader, const Node& node) {
  reader.expect_object(node, kEffectKeys);
  SceneEffects effects;
  effects.sh_degree = read_sh_degree(reader, node);
  if (const auto aa = reader.optional_child(node, "antialiasing")) {
    const auto mode = reader.choice(*aa, kAntialiasing);
    effects.antialiasing = mode == "mip"           ? Antialiasing::kMip
                           : mode == "antialiased" ? Antialiasing::kAntialiased
                                                   : Antialiasing::kClassic;
  }
  if (const auto lights = reader.optional_child(node, "lights")) {
    const json& list = reader.array(*lights, "a list of lights");
    for (size_t i = 0; i < list.size(); ++i)
      effects.lights.push_back(read_light(reader, Node{list[i], element_path(lights->path, i)}));
  }
  if (const auto ambient = reader.optional_child(node, "ambient")) {
    effects.ambient = reader.numbers<3>(*ambient, 0, kMaxRadiance);
    // Relighting is on only with lights: an ambient alone would be silently ignored.
    if (effects.lights.empty())
      reader.fail(ambient->path, "applies only to relighting: list at least one light in 'lights' (an ambient alone "
                                 "would be ignored)");
  }
  if (const auto exposure = reader.optional_child(node, "exposure"))
    effects.exposure_stops = reader.number(*exposure, -kMaxExposureStops, kMaxExposureStops);
  if (const auto tone_map = reader.optional_child(node, "tone_map")) {
    const auto mode = reader.choice(*tone_map, kToneMaps);
    effects.tone_map = mode == "aces" ? ToneMap::kAces : mode == "reinhard" ? ToneMap::kReinhard : ToneMap::kNone;
  }
  return effects;
}

SceneOutputs read_outputs(const Reader& reader, const Node& node) {
  const json& list = reader.array(node, "a list of outputs from " + quoted_list(kOutputs));
  SceneOutputs outputs{false, false, false, false};
  std::set<std::string_view> seen;
  for (size_t i = 0; i < list.size(); ++i) {
    const Node item{list[i], element_path(node.path, i)};
    const std::string_view output = reader.choice(item, kOutputs);
    if (!seen.insert(output).second) reader.fail(item.path, single_quoted(output) + " is listed twice");
    outputs.color |= output == "color";
    outputs.alpha |= output == "alpha";
    outputs.depth |= output == "depth";
    outputs.splat_count |= output == "splat_count";
  }
  if (!outputs.color) reader.fail(node.path, "must include 'color': every render writes the colour channels");
  return outputs;
}

void read_version(const Reader& reader, const Node& root) {
  const auto version = reader.optional_child(root, "version");
  if (version && reader.integer(*version, 1, 1000000) != kFormatVersion)
    reader.fail(version->path, "this reader knows format version " + std::to_string(kFormatVersion) + " only");
  if (const auto schema = reader.optional_child(root, "$schema")) reader.string(*schema);
}

std::string read_text(const fs::path& path) {
  std::error_code error;
  const auto status = fs::status(path, error);
  if (!fs::exists(status)) throw SceneError(path.string() + ": the scene description does not exist");
  if (fs::is_directory(status)) throw SceneError(path.string() + ": is a directory, not a scene description");
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw SceneError(path.string() + ": cannot open the scene description");
  return {std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>()};
}

}  // namespace

SceneDescription parse_scene_description(std::string_view text, const fs::path& file) {
  const Reader reader(file);
  const json document = reader.parse(text);
  const Node root{document, ""};
  if (document.is_array())
    reader.fail(root.path, "must be an object {\"models\": [...], ...}, got an array (a trainer cameras.json? "
                           "name it in \"cameras\", or pass it to the apps with --cameras)");
  reader.expect_object(root, kTopKeys);
  read_version(reader, root);

  SceneDescription description;
  description.file = file;
  description.models = read_models(reader, root);
  if (const auto cameras = reader.optional_child(root, "cameras")) read_cameras(reader, *cameras, description);
  if (const auto background = reader.optional_child(root, "background")) {
    const auto rgb = reader.numbers<3>(*background, 0, kMaxRadiance);
    description.background = {float(rgb[0]), float(rgb[1]), float(rgb[2])};
  }
  if (const auto effects = reader.optional_child(root, "effects")) description.effects = read_effects(reader, *effects);
  if (const auto outputs = reader.optional_child(root, "outputs")) description.outputs = read_outputs(reader, *outputs);
  return description;
}

SceneDescription load_scene_description(const fs::path& path) { return parse_scene_description(read_text(path), path); }

bool is_scene_description(const fs::path& path) {
  if (lowercase(path.extension().string()) != ".json") return false;
  // A SOG's meta.json is a scene of its own (load_scene reads it), not a scene description.
  std::ifstream in(path, std::ios::binary);
  if (!in) return true;  // load_scene_description reports why it cannot be read
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Nor is a LOD set's index (tilesplat/lod_set.h).
  return !detail::is_sog_meta(text) && !detail::is_lod_index(text);
}

}  // namespace tilesplat
