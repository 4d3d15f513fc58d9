// Cameras: the trainer's cameras.json, resizing, look-at and orbit framing.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <numbers>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

using Vec3 = std::array<double, 3>;

// Max |R R^T - I| over the entries.
double orthonormality_error(const std::array<double, 9>& r) {
  double worst = 0;
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < 3; ++j) {
      const double row_dot = r[i * 3] * r[j * 3] + r[i * 3 + 1] * r[j * 3 + 1] + r[i * 3 + 2] * r[j * 3 + 2];
      worst = std::max(worst, std::abs(row_dot - (i == j ? 1.0 : 0.0)));
    }
  return worst;
}

double determinant(const std::array<double, 9>& r) {
  return r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) + r[2] * (r[3] * r[7] - r[4] * r[6]);
}

std::array<double, 2> project(const Camera& camera, const Vec3& world) {
  const Vec3 t = camera.to_camera(world);
  return {camera.fx * t[0] / t[2] + camera.cx, camera.fy * t[1] / t[2] + camera.cy};
}

// ---------------------------------------------------------------------------------------------
// load_cameras_json

TEST(CamerasJson, BundledPlaybotLoadsEightViewsMatchingTheFile) {
  const auto path = testing::bundled_playbot_cameras();
  const auto views = load_cameras_json(path);
  ASSERT_EQ(views.size(), 8u);

  std::ifstream stream(path);
  const nlohmann::json raw = nlohmann::json::parse(stream);
  for (size_t v = 0; v < views.size(); ++v) {
    SCOPED_TRACE("view " + std::to_string(v));
    const nlohmann::json& entry = raw[v];
    const Camera& camera = views[v].camera;
    EXPECT_EQ(views[v].id, entry["id"].get<int>());
    EXPECT_EQ(views[v].name, entry["img_name"].get<std::string>());
    EXPECT_EQ(camera.width, 1920);
    EXPECT_EQ(camera.height, 1080);
    EXPECT_EQ(camera.fx, entry["fx"].get<double>());
    EXPECT_EQ(camera.fy, entry["fy"].get<double>());
    EXPECT_EQ(camera.cx, 960);
    EXPECT_EQ(camera.cy, 540);
    for (size_t k = 0; k < 3; ++k) EXPECT_EQ(camera.position[k], entry["position"][k].get<double>());
    EXPECT_LT(orthonormality_error(camera.rotation), 1e-9);
    EXPECT_NEAR(determinant(camera.rotation), 1.0, 1e-9);
    // The file is camera-to-world (axes in its columns); the engine keeps the transpose.
    for (size_t r = 0; r < 3; ++r)
      for (size_t c = 0; c < 3; ++c) EXPECT_EQ(camera.rotation[r * 3 + c], entry["rotation"][c][r].get<double>());
    // The camera sits at its own origin and looks at the scene, which lies ahead of it.
    const Vec3 origin_in_camera = camera.to_camera(camera.position);
    for (double value : origin_in_camera) EXPECT_NEAR(value, 0, 1e-12);
  }
  EXPECT_EQ(views[0].name, "orbit_000");
  EXPECT_DOUBLE_EQ(views[0].camera.position[2], 2.539632365223562);
}

TEST(CamerasJson, SceneCentreIsInFrontOfEveryBundledView) {
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const Bounds bounds = compute_bounds(scene);
  for (const CameraView& view : load_cameras_json(testing::bundled_playbot_cameras())) {
    const Vec3 centre = {bounds.center[0], bounds.center[1], bounds.center[2]};
    const Vec3 t = view.camera.to_camera(centre);
    EXPECT_GT(t[2], 0.5) << view.name;
    const auto pixel = project(view.camera, centre);
    EXPECT_GT(pixel[0], 0);
    EXPECT_LT(pixel[0], view.camera.width);
    EXPECT_GT(pixel[1], 0);
    EXPECT_LT(pixel[1], view.camera.height);
  }
}

// A valid cameras.json entry to start the error cases from.
nlohmann::json good_entry() {
  return {{"id", 0},
          {"img_name", "view"},
          {"width", 64},
          {"height", 32},
          {"position", {1.0, 2.0, 3.0}},
          {"rotation", {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}},
          {"fx", 50.0},
          {"fy", 50.0}};
}

std::filesystem::path write_file(const std::string& name, const std::string& text) {
  const auto path = testing::temp_dir() / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
  return path;
}

// Loads `path` expecting a SceneError whose message names the file and contains every fragment.
void expect_scene_error(const std::filesystem::path& path, std::initializer_list<std::string> fragments) {
  try {
    load_cameras_json(path);
    ADD_FAILURE() << "no error for " << path;
  } catch (const SceneError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(path.filename().string()), std::string::npos) << message;
    for (const std::string& fragment : fragments)
      EXPECT_NE(message.find(fragment), std::string::npos) << "'" << fragment << "' not in: " << message;
  }
}

// Writes a list of four good entries with entry 3 changed by `edit`, and expects the error.
template <typename Edit>
void expect_entry_error(const std::string& file_name, Edit edit, std::initializer_list<std::string> fragments) {
  nlohmann::json list = nlohmann::json::array();
  for (int i = 0; i < 4; ++i) list.push_back(good_entry());
  edit(list[3]);
  std::vector<std::string> all = {"entry 3"};
  all.insert(all.end(), fragments.begin(), fragments.end());
  const auto path = write_file(file_name, list.dump());
  try {
    load_cameras_json(path);
    ADD_FAILURE() << "no error for " << list[3].dump();
  } catch (const SceneError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(file_name), std::string::npos) << message;
    for (const std::string& fragment : all)
      EXPECT_NE(message.find(fragment), std::string::npos) << "'" << fragment << "' not in: " << message;
  }
}

TEST(CamerasJson, GoodEntryLoads) {
  nlohmann::json list = nlohmann::json::array({good_entry()});
  const auto views = load_cameras_json(write_file("good.json", list.dump()));
  ASSERT_EQ(views.size(), 1u);
  EXPECT_EQ(views[0].camera.width, 64);
  EXPECT_EQ(views[0].camera.cx, 32);
  EXPECT_EQ(views[0].camera.cy, 16);
  EXPECT_EQ(views[0].camera.position, (std::array<double, 3>{1, 2, 3}));
}

TEST(CamerasJson, MissingFile) {
  expect_scene_error(testing::temp_dir() / "does_not_exist.json", {"cannot open"});
}

TEST(CamerasJson, InvalidJsonReportsTheParserPosition) {
  expect_scene_error(write_file("broken.json", "[{\"id\": 0,\n \"width\": 64,,}]"), {"invalid JSON", "line 2"});
}

TEST(CamerasJson, NotAnArray) {
  expect_scene_error(write_file("object.json", good_entry().dump()), {"array"});
}

TEST(CamerasJson, EmptyArray) { expect_scene_error(write_file("empty.json", "[]"), {"empty"}); }

TEST(CamerasJson, EntryNotAnObject) {
  expect_entry_error("scalar_entry.json", [](nlohmann::json& e) { e = 42; }, {"object"});
}

TEST(CamerasJson, MissingField) {
  for (const char* field : {"width", "height", "position", "rotation", "fx", "fy"}) {
    SCOPED_TRACE(field);
    expect_entry_error(std::string("missing_") + field + ".json", [&](nlohmann::json& e) { e.erase(field); },
                       {std::string("'") + field + "'", "missing"});
  }
}

TEST(CamerasJson, FocalLengthsMustBePositiveFiniteNumbers) {
  expect_entry_error("fx_zero.json", [](nlohmann::json& e) { e["fx"] = 0.0; },
                     {"'fx' must be a positive finite number"});
  expect_entry_error("fy_negative.json", [](nlohmann::json& e) { e["fy"] = -10.0; },
                     {"'fy' must be a positive finite number"});
  expect_entry_error("fx_string.json", [](nlohmann::json& e) { e["fx"] = "1000"; },
                     {"'fx' must be a positive finite number"});
  expect_entry_error("fy_null.json", [](nlohmann::json& e) { e["fy"] = nullptr; },
                     {"'fy' must be a positive finite number"});
}

TEST(CamerasJson, NonFiniteNumbersAreRejected) {
  // JSON has no NaN or Infinity; an overflowing literal is the closest a file can get.
  std::string text = nlohmann::json::array({good_entry()}).dump();
  text.replace(text.find("\"fx\":50.0"), 9, "\"fx\":1e999");
  expect_scene_error(write_file("fx_overflow.json", text), {"1e999"});
  std::string nan_text = nlohmann::json::array({good_entry()}).dump();
  nan_text.replace(nan_text.find("\"fy\":50.0"), 9, "\"fy\":NaN");
  expect_scene_error(write_file("fy_nan.json", nan_text), {"invalid JSON"});
}

TEST(CamerasJson, SizeMustBeAPositiveInteger) {
  expect_entry_error("width_zero.json", [](nlohmann::json& e) { e["width"] = 0; },
                     {"'width' must be a positive integer"});
  expect_entry_error("height_negative.json", [](nlohmann::json& e) { e["height"] = -5; },
                     {"'height' must be a positive integer"});
  expect_entry_error("width_fraction.json", [](nlohmann::json& e) { e["width"] = 64.5; },
                     {"'width' must be a positive integer"});
  expect_entry_error("height_string.json", [](nlohmann::json& e) { e["height"] = "32"; },
                     {"'height' must be a positive integer"});
}

TEST(CamerasJson, PositionMustBeThreeNumbers) {
  expect_entry_error("position_short.json", [](nlohmann::json& e) { e["position"] = {1.0, 2.0}; },
                     {"'position'"});
  expect_entry_error("position_string.json", [](nlohmann::json& e) { e["position"][1] = "x"; },
                     {"'position'[1]"});
}

TEST(CamerasJson, RotationMustBeThreeByThree) {
  expect_entry_error("rotation_2x3.json",
                     [](nlohmann::json& e) { e["rotation"] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}}; },
                     {"'rotation' must be a 3x3 array"});
  expect_entry_error("rotation_3x2.json", [](nlohmann::json& e) { e["rotation"][2] = {0.0, 1.0}; },
                     {"'rotation' must be a 3x3 array"});
  expect_entry_error("rotation_flat.json",
                     [](nlohmann::json& e) { e["rotation"] = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}; },
                     {"'rotation' must be a 3x3 array"});
  expect_entry_error("rotation_string.json", [](nlohmann::json& e) { e["rotation"][1][1] = "1"; },
                     {"'rotation'[1][1]"});
}

TEST(CamerasJson, RotationMustBeOrthonormal) {
  expect_entry_error("rotation_scaled.json", [](nlohmann::json& e) { e["rotation"][0][0] = 1.01; },
                     {"'rotation' is not orthonormal"});
  expect_entry_error("rotation_sheared.json", [](nlohmann::json& e) { e["rotation"][0][1] = 0.1; },
                     {"'rotation' is not orthonormal"});
  expect_entry_error("rotation_reflection.json", [](nlohmann::json& e) { e["rotation"][2][2] = -1.0; },
                     {"'rotation'", "reflection"});
  // Within the 1e-3 tolerance: accepted (trainer files carry float32-rounded matrices).
  nlohmann::json entry = good_entry();
  entry["rotation"][0][0] = 1.0004;
  EXPECT_NO_THROW(load_cameras_json(write_file("rotation_close.json", nlohmann::json::array({entry}).dump())));
}

// ---------------------------------------------------------------------------------------------
// resize_camera

TEST(ResizeCamera, HalvingTheSizeHalvesTheIntrinsics) {
  const Camera full = load_cameras_json(testing::bundled_playbot_cameras()).at(2).camera;
  const Camera half = resize_camera(full, 960, 540);
  EXPECT_EQ(half.width, 960);
  EXPECT_EQ(half.height, 540);
  EXPECT_DOUBLE_EQ(half.fx, full.fx / 2);
  EXPECT_DOUBLE_EQ(half.fy, full.fy / 2);
  EXPECT_DOUBLE_EQ(half.cx, full.cx / 2);
  EXPECT_DOUBLE_EQ(half.cy, full.cy / 2);
  EXPECT_EQ(half.rotation, full.rotation);
  EXPECT_EQ(half.position, full.position);
  EXPECT_DOUBLE_EQ(half.tan_half_fov_x(), full.tan_half_fov_x());
}

TEST(ResizeCamera, MissingDimensionKeepsTheAspectRatio) {
  Camera camera;
  camera.width = 1920;
  camera.height = 1080;
  camera.fx = camera.fy = 1000;
  camera.cx = 960;
  camera.cy = 540;
  const Camera from_width = resize_camera(camera, 480, 0);
  EXPECT_EQ(from_width.height, 270);
  EXPECT_DOUBLE_EQ(from_width.fy, 250);
  const Camera from_height = resize_camera(camera, -1, 540);
  EXPECT_EQ(from_height.width, 960);
  EXPECT_DOUBLE_EQ(from_height.cx, 480);
  const Camera unchanged = resize_camera(camera, 0, 0);
  EXPECT_EQ(unchanged.width, 1920);
  EXPECT_DOUBLE_EQ(unchanged.fx, 1000);
  // Independent axes scale independently.
  const Camera stretched = resize_camera(camera, 480, 540);
  EXPECT_DOUBLE_EQ(stretched.fx, 250);
  EXPECT_DOUBLE_EQ(stretched.fy, 500);
  EXPECT_DOUBLE_EQ(stretched.cx, 240);
  EXPECT_DOUBLE_EQ(stretched.cy, 270);
}

// ---------------------------------------------------------------------------------------------
// look_at_camera and orbit_camera

TEST(LookAtCamera, TargetLandsOnThePrincipalPoint) {
  const Vec3 eye = {1, -2, 3}, target = {0.5, 0.2, -1}, up = {0, -1, 0};
  const Camera camera = look_at_camera(eye, target, up, 640, 360, 50);
  EXPECT_EQ(camera.width, 640);
  EXPECT_EQ(camera.height, 360);
  EXPECT_DOUBLE_EQ(camera.cx, 320);
  EXPECT_DOUBLE_EQ(camera.cy, 180);
  EXPECT_NEAR(camera.tan_half_fov_y(), std::tan(25.0 * std::numbers::pi / 180.0), 1e-12);
  EXPECT_DOUBLE_EQ(camera.fx, camera.fy);
  EXPECT_LT(orthonormality_error(camera.rotation), 1e-12);
  EXPECT_NEAR(determinant(camera.rotation), 1, 1e-12);

  const Vec3 t = camera.to_camera(target);
  const double distance = std::sqrt(0.25 + 4.84 + 16);
  EXPECT_NEAR(t[0], 0, 1e-12);
  EXPECT_NEAR(t[1], 0, 1e-12);
  EXPECT_NEAR(t[2], distance, 1e-12);
  const auto pixel = project(camera, target);
  EXPECT_NEAR(pixel[0], 320, 1e-9);
  EXPECT_NEAR(pixel[1], 180, 1e-9);

  // A point above the target (along world up) appears above the image centre: camera y is down.
  const auto above = project(camera, {target[0], target[1] - 0.1, target[2]});
  EXPECT_LT(above[1], 180);
  EXPECT_NEAR(above[0], 320, 1e-6);
}

TEST(LookAtCamera, AxesFollowOpenCvConventions) {
  // From +z looking at the origin with -Y up, camera x (right) is world -X and camera y (down) world +Y.
  const Camera camera = look_at_camera({0, 0, 5}, {0, 0, 0}, {0, -1, 0}, 100, 100, 60);
  const std::array<double, 9> expected = {-1, 0, 0, 0, 1, 0, 0, 0, -1};
  for (size_t k = 0; k < 9; ++k) EXPECT_NEAR(camera.rotation[k], expected[k], 1e-12) << k;
}

TEST(LookAtCamera, UpAlongTheViewDirectionStillGivesARotation) {
  const Camera camera = look_at_camera({0, -5, 0}, {0, 0, 0}, {0, -1, 0}, 100, 100, 60);
  EXPECT_LT(orthonormality_error(camera.rotation), 1e-12);
  EXPECT_NEAR(determinant(camera.rotation), 1, 1e-12);
  EXPECT_NEAR(camera.to_camera({0, 0, 0})[2], 5, 1e-12);
  EXPECT_THROW(look_at_camera({1, 1, 1}, {1, 1, 1}, {0, -1, 0}, 100, 100, 60), std::invalid_argument);
}

TEST(OrbitCamera, FramesTheBundledPlaybot) {
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const Bounds bounds = compute_bounds(scene);
  const Vec3 centre = {bounds.center[0], bounds.center[1], bounds.center[2]};

  for (double azimuth : {0.0, 90.0, 200.0}) {
    SCOPED_TRACE("azimuth " + std::to_string(azimuth));
    OrbitParams params;
    params.azimuth_deg = azimuth;
    const Camera camera = orbit_camera(scene, 640, 360, params);
    EXPECT_DOUBLE_EQ(camera.cx, 320);
    EXPECT_DOUBLE_EQ(camera.cy, 180);
    const auto pixel = project(camera, centre);
    EXPECT_NEAR(pixel[0], 320, 1e-6);
    EXPECT_NEAR(pixel[1], 180, 1e-6);
    // Elevated along world up (-Y): the camera is above the centre.
    EXPECT_LT(camera.position[1], centre[1]);

    size_t inside = 0;
    for (size_t i = 0; i < scene.size(); ++i) {
      const Vec3 p = {scene.positions[3 * i], scene.positions[3 * i + 1], scene.positions[3 * i + 2]};
      if (camera.to_camera(p)[2] <= 0.2) continue;
      const auto q = project(camera, p);
      inside += q[0] >= 0 && q[0] < 640 && q[1] >= 0 && q[1] < 360;
    }
    EXPECT_GT(double(inside), 0.9 * double(scene.size())) << inside << " of " << scene.size();
  }
}

TEST(OrbitCamera, OrientationMatchesTheTrainerOrbitViews) {
  // The shipped orbit views are azimuth 45 v degrees at 20 degrees elevation around -Y up; the
  // orientation does not depend on the distance or the framing, so it must match exactly.
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const auto views = load_cameras_json(testing::bundled_playbot_cameras());
  for (size_t v = 0; v < views.size(); ++v) {
    OrbitParams params;
    params.azimuth_deg = 45.0 * double(v);
    params.elevation_deg = 20;
    const Camera camera = orbit_camera(scene, 1920, 1080, params);
    for (size_t k = 0; k < 9; ++k)
      EXPECT_NEAR(camera.rotation[k], views[v].camera.rotation[k], 1e-9) << "view " << v << " entry " << k;
  }
}

TEST(OrbitCamera, DistanceScaleMovesTheCameraAway) {
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const Bounds bounds = compute_bounds(scene);
  const Vec3 centre = {bounds.center[0], bounds.center[1], bounds.center[2]};
  OrbitParams params;
  const double near_distance = orbit_camera(scene, 320, 240, params).to_camera(centre)[2];
  params.distance_scale = 2;
  const double far_distance = orbit_camera(scene, 320, 240, params).to_camera(centre)[2];
  EXPECT_NEAR(far_distance, 2 * near_distance, 1e-9);
  EXPECT_GT(near_distance, bounds.radius);
}

}  // namespace
}  // namespace tilesplat
