// Camera sets where datasets keep them (COLMAP sparse models, binary and text; nerfstudio and
// instant-ngp transforms.json) read as the same cameras as the trainer's cameras.json, and camera
// paths through keyframes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "process_support.h"
#include "test_support.h"
#include "tilesplat/camera_path.h"
#include "tilesplat/camera_sets.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"

namespace {

namespace fs = std::filesystem;
using tilesplat::Camera;
using tilesplat::CameraView;
using tilesplat::testing::fresh_output_dir;

void expect_near_camera(const Camera& a, const Camera& b, double tolerance = 1e-9) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_NEAR(a.fx, b.fx, tolerance);
  EXPECT_NEAR(a.fy, b.fy, tolerance);
  EXPECT_NEAR(a.cx, b.cx, tolerance);
  EXPECT_NEAR(a.cy, b.cy, tolerance);
  for (size_t k = 0; k < 9; ++k) EXPECT_NEAR(a.rotation[k], b.rotation[k], tolerance) << k;
  for (size_t k = 0; k < 3; ++k) EXPECT_NEAR(a.position[k], b.position[k], tolerance) << k;
}

// COLMAP's quaternion (w, x, y, z) of a world-to-camera rotation, and its translation t = -R c.
std::array<double, 7> colmap_pose(const Camera& camera) {
  const auto& r = camera.rotation;
  // The largest of |w|, |x|, |y|, |z| first, the others from it (exact for half-turns too).
  const double w2 = 1 + r[0] + r[4] + r[8], x2 = 1 + r[0] - r[4] - r[8], y2 = 1 - r[0] + r[4] - r[8],
               z2 = 1 - r[0] - r[4] + r[8];
  double w, x, y, z;
  if (w2 >= std::max({x2, y2, z2})) {
    w = std::sqrt(w2) / 2;
    x = (r[7] - r[5]) / (4 * w), y = (r[2] - r[6]) / (4 * w), z = (r[3] - r[1]) / (4 * w);
  } else if (x2 >= std::max(y2, z2)) {
    x = std::sqrt(x2) / 2;
    w = (r[7] - r[5]) / (4 * x), y = (r[1] + r[3]) / (4 * x), z = (r[2] + r[6]) / (4 * x);
  } else if (y2 >= z2) {
    y = std::sqrt(y2) / 2;
    w = (r[2] - r[6]) / (4 * y), x = (r[1] + r[3]) / (4 * y), z = (r[5] + r[7]) / (4 * y);
  } else {
    z = std::sqrt(z2) / 2;
    w = (r[3] - r[1]) / (4 * z), x = (r[2] + r[6]) / (4 * z), y = (r[5] + r[7]) / (4 * z);
  }
  std::array<double, 7> pose = {w, x, y, z, 0, 0, 0};
  for (size_t row = 0; row < 3; ++row)
    pose[4 + row] = -(r[row * 3] * camera.position[0] + r[row * 3 + 1] * camera.position[1] +
                      r[row * 3 + 2] * camera.position[2]);
  return pose;
}

template <typename T>
void put(std::string& bytes, T value) {
  bytes.append(reinterpret_cast<const char*>(&value), sizeof value);
}

// A COLMAP model of the views, each with its own PINHOLE camera, in COLMAP's binary and text layouts.
void write_colmap(const std::vector<CameraView>& views, const fs::path& folder, bool binary) {
  fs::create_directories(folder);
  if (binary) {
    std::string cameras, images;
    put<uint64_t>(cameras, views.size());
    put<uint64_t>(images, views.size());
    // Written in reverse: the reader orders the views by image name, as the trainer does.
    for (size_t i = views.size(); i-- > 0;) {
      const Camera& c = views[i].camera;
      put<int32_t>(cameras, int32_t(i + 1));
      put<int32_t>(cameras, 1);  // PINHOLE
      put<uint64_t>(cameras, uint64_t(c.width));
      put<uint64_t>(cameras, uint64_t(c.height));
      for (double p : {c.fx, c.fy, c.cx, c.cy}) put<double>(cameras, p);
      put<int32_t>(images, int32_t(100 + i));
      for (double p : colmap_pose(c)) put<double>(images, p);
      put<int32_t>(images, int32_t(i + 1));
      images += views[i].name;
      images += '\0';
      put<uint64_t>(images, 2);  // two 2D points, skipped by the reader
      for (int k = 0; k < 2; ++k) {
        put<double>(images, 1.5);
        put<double>(images, 2.5);
        put<int64_t>(images, -1);
      }
    }
    std::ofstream(folder / "cameras.bin", std::ios::binary) << cameras;
    std::ofstream(folder / "images.bin", std::ios::binary) << images;
    return;
  }
  std::ofstream cameras(folder / "cameras.txt"), images(folder / "images.txt");
  cameras.precision(17);
  images.precision(17);
  cameras
      << "# Camera list with one line of data per camera:\n#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n";
  images << "# Image list with two lines of data per image:\n";
  for (size_t i = views.size(); i-- > 0;) {
    const Camera& c = views[i].camera;
    cameras << i + 1 << " PINHOLE " << c.width << " " << c.height << " " << c.fx << " " << c.fy << " " << c.cx
            << " " << c.cy << "\n";
    const auto pose = colmap_pose(c);
    images << 100 + i;
    for (double p : pose) images << " " << p;
    images << " " << i + 1 << " " << views[i].name << "\n" << (i % 2 ? "1.5 2.5 -1 3.5 4.5 7\n" : "\n");
  }
}

std::vector<CameraView> reference_views() {
  return tilesplat::load_cameras_json(tilesplat::testing::bundled_playbot_cameras());
}

TEST(CameraSets, ColmapBinaryAndTextModelsReadAsTheSameCameras) {
  const auto views = reference_views();
  const fs::path out = fresh_output_dir();
  for (const bool binary : {true, false}) {
    const fs::path model = out / (binary ? "bin" : "txt") / "sparse" / "0";
    write_colmap(views, model, binary);
    // The dataset root (with sparse/0), the model folder and one of its files all name the model.
    for (const fs::path& path :
         {out / (binary ? "bin" : "txt"), model, model / (binary ? "images.bin" : "cameras.txt")}) {
      const auto read = tilesplat::load_camera_set(path);
      ASSERT_EQ(read.size(), views.size()) << path;
      for (size_t i = 0; i < views.size(); ++i) {
        EXPECT_EQ(read[i].name, views[i].name);
        EXPECT_EQ(read[i].id, int(100 + i));
        expect_near_camera(read[i].camera, views[i].camera);
      }
    }
  }
}

TEST(CameraSets, ColmapLensModelsAreReadIntoTheirParameters) {
  const auto views = reference_views();
  const fs::path out = fresh_output_dir();
  write_colmap(views, out / "models", false);
  using tilesplat::CameraModel;
  struct Case {
    const char* line;
    CameraModel model;
    std::array<double, 4> intrinsics;  // fx fy cx cy
    std::array<double, 8> distortion;
  };
  const Case cases[] = {
      {"SIMPLE_RADIAL 640 480 500 320 240 0.01", CameraModel::kOpenCV, {500, 500, 320, 240}, {0.01}},
      {"RADIAL 640 480 500 320 240 0.01 -0.002", CameraModel::kOpenCV, {500, 500, 320, 240}, {0.01, -0.002}},
      {"OPENCV 640 480 500 510 320 240 0.01 -0.002 0.0003 -0.0004",
       CameraModel::kOpenCV,
       {500, 510, 320, 240},
       {0.01, -0.002, 0.0003, -0.0004}},
      {"FULL_OPENCV 640 480 500 510 320 240 0.01 -0.002 0.0003 -0.0004 0.001 0.02 0.003 0.0004",
       CameraModel::kOpenCV,
       {500, 510, 320, 240},
       {0.01, -0.002, 0.0003, -0.0004, 0.001, 0.02, 0.003, 0.0004}},
      {"OPENCV_FISHEYE 640 480 300 310 320 240 0.05 -0.01 0.002 -0.0003",
       CameraModel::kFisheye,
       {300, 310, 320, 240},
       {0.05, -0.01, 0.002, -0.0003}},
      {"SIMPLE_RADIAL_FISHEYE 640 480 300 320 240 0.05", CameraModel::kFisheye, {300, 300, 320, 240}, {0.05}},
      {"RADIAL_FISHEYE 640 480 300 320 240 0.05 -0.01",
       CameraModel::kFisheye,
       {300, 300, 320, 240},
       {0.05, -0.01}},
      {"PINHOLE 640 480 500 510 320 240", CameraModel::kPinhole, {500, 510, 320, 240}, {}},
  };
  const tilesplat::GaussianScene playbot = tilesplat::load_scene(tilesplat::testing::bundled_playbot());
  tilesplat::Renderer& renderer = tilesplat::testing::validated_renderer();
  for (const Case& c : cases) {
    {
      std::ofstream cameras(out / "models" / "cameras.txt");
      for (size_t id = 1; id <= views.size(); ++id) cameras << id << " " << c.line << "\n";
    }
    const auto loaded = tilesplat::load_colmap_cameras(out / "models");
    ASSERT_EQ(loaded.size(), views.size()) << c.line;
    const tilesplat::Camera& camera = loaded.front().camera;
    EXPECT_EQ(camera.model, c.model) << c.line;
    EXPECT_EQ((std::array<double, 4>{camera.fx, camera.fy, camera.cx, camera.cy}), c.intrinsics) << c.line;
    EXPECT_EQ(camera.distortion, c.distortion) << c.line;
    for (size_t k = 0; k < 9; ++k) EXPECT_NEAR(camera.rotation[k], views.front().camera.rotation[k], 1e-12);
    // The camera read renders the bundled playbot through its lens on the GPU as the float64 reference does.
    const tilesplat::Camera small = tilesplat::resize_camera(camera, 160, 120);
    renderer.set_scene(playbot);
    const tilesplat::RenderImage gpu = renderer.render(small);
    const tilesplat::ImageDifference d =
        tilesplat::compare_images(gpu, tilesplat::render_reference(playbot, small));
    EXPECT_GE(d.psnr_db, 60.0) << c.line;
    EXPECT_GT(*std::max_element(gpu.rgba.begin(), gpu.rgba.end()), 0.2f)
        << c.line << ": the scene is in view";
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
  // The models the renderer does not have are refused by name.
  for (const char* line :
       {"FOV 640 480 500 510 320 240 0.9", "THIN_PRISM_FISHEYE 640 480 500 510 320 240 0 0 0 0 0 0 0 0"}) {
    std::ofstream(out / "models" / "cameras.txt") << "1 " << line << "\n";
    const std::string error =
        tilesplat::testing::error_of([&] { tilesplat::load_colmap_cameras(out / "models"); });
    EXPECT_NE(error.find(std::string("uses the ") + std::string(line).substr(0, std::string(line).find(' ')) +
                         " model, which the renderer does not have"),
              std::string::npos)
        << error;
  }
}

TEST(CameraSets, ColmapTruncationAndMissingCamerasAreErrors) {
  const auto views = reference_views();
  const fs::path out = fresh_output_dir();
  write_colmap(views, out / "radial", false);
  std::ofstream(out / "radial" / "cameras.txt") << "7 PINHOLE 640 480 500 500 320 240\n";
  EXPECT_NE(tilesplat::testing::error_of([&] {
              tilesplat::load_colmap_cameras(out / "radial");
            }).find("is not in cameras.txt"),
            std::string::npos);

  write_colmap(views, out / "cut", true);
  const fs::path images = out / "cut" / "images.bin";
  fs::resize_file(images, fs::file_size(images) - 30);
  const std::string truncated =
      tilesplat::testing::error_of([&] { tilesplat::load_colmap_cameras(out / "cut"); });
  EXPECT_NE(truncated.find(images.string()), std::string::npos) << truncated;
  EXPECT_NE(truncated.find("truncated"), std::string::npos) << truncated;
  {
    std::string huge;
    put<uint64_t>(huge, uint64_t(1) << 60);
    std::ofstream(out / "cut" / "cameras.bin", std::ios::binary) << huge;
  }
  EXPECT_NE(tilesplat::testing::error_of([&] {
              tilesplat::load_colmap_cameras(out / "cut");
            }).find("more than the file holds"),
            std::string::npos);
  EXPECT_NE(tilesplat::testing::error_of([&] {
              tilesplat::load_colmap_cameras(out / "nothing");
            }).find("not found"),
            std::string::npos);
}

// transforms.json keeps camera-to-world in the OpenGL convention: the engine's y and z axes negated.
std::string transforms_json(const std::vector<CameraView>& views, const std::string& extra_top = "") {
  char number[64];
  std::snprintf(number, sizeof number, "%.17g", views[0].camera.fx);
  std::string text = "{" + extra_top + "\"fl_x\": " + number +
                     ", \"w\": " + std::to_string(views[0].camera.width) +
                     ", \"h\": " + std::to_string(views[0].camera.height) + ", \"frames\": [";
  for (size_t i = 0; i < views.size(); ++i) {
    const Camera& c = views[i].camera;
    const auto& r = c.rotation;  // world-to-camera: camera-to-world is its transpose
    text += std::string(i ? "," : "") + "{\"file_path\": \"images/" + views[i].name + "\", \"fl_y\": ";
    std::snprintf(number, sizeof number, "%.17g", c.fy);
    text += number;
    text += ", \"transform_matrix\": [";
    for (size_t row = 0; row < 3; ++row) {
      const double values[4] = {r[0 * 3 + row], -r[1 * 3 + row], -r[2 * 3 + row], c.position[row]};
      text += "[";
      for (size_t col = 0; col < 4; ++col) {
        std::snprintf(number, sizeof number, "%.17g", values[col]);
        text += std::string(col ? ", " : "") + number;
      }
      text += "], ";
    }
    text += "[0, 0, 0, 1]]}";
  }
  return text + "]}";
}

TEST(CameraSets, TransformsJsonReadsAsTheSameCameras) {
  auto views = reference_views();
  for (auto& view : views) view.camera.fx = views[0].camera.fx;  // one shared fl_x at the top level
  const fs::path out = fresh_output_dir();
  std::ofstream(out / "transforms.json") << transforms_json(views);
  const auto read = tilesplat::load_camera_set(out / "transforms.json");
  ASSERT_EQ(read.size(), views.size());
  for (size_t i = 0; i < views.size(); ++i) {
    EXPECT_EQ(read[i].name, "images/" + views[i].name);
    expect_near_camera(read[i].camera, views[i].camera, 1e-12);
  }
  // instant-ngp's camera_angle_x gives the focal length from the width.
  std::ofstream(out / "ngp.json") << R"({"camera_angle_x": 1.5707963267948966, "w": 800, "h": 600, "frames": [
      {"file_path": "a", "transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]}]})";
  const auto ngp = tilesplat::load_transforms_json(out / "ngp.json");
  EXPECT_NEAR(ngp[0].camera.fx, 400, 1e-9);
  EXPECT_NEAR(ngp[0].camera.fy, 400, 1e-9);
  // Looking down -z in OpenGL is looking down +z in the engine's frame: the camera at z = 4 sees the origin.
  EXPECT_NEAR(ngp[0].camera.to_camera({0, 0, 0})[2], 4, 1e-12);

  // Distortion without a model is OPENCV's (instant-ngp's files); nerfstudio's fisheye is Kannala-Brandt.
  std::ofstream(out / "distorted.json")
      << transforms_json(views, "\"k1\": 0.05, \"p2\": 0.001, \"k3\": 0.002, ");
  const auto distorted = tilesplat::load_camera_set(out / "distorted.json");
  EXPECT_EQ(distorted[0].camera.model, tilesplat::CameraModel::kOpenCV);
  EXPECT_EQ(distorted[0].camera.distortion, (std::array<double, 8>{0.05, 0, 0, 0.001, 0.002, 0, 0, 0}));
  std::ofstream(out / "fisheye.json")
      << transforms_json(views, "\"camera_model\": \"OPENCV_FISHEYE\", \"k1\": 0.1, \"k4\": -0.01, ");
  const auto fisheye = tilesplat::load_camera_set(out / "fisheye.json");
  EXPECT_EQ(fisheye[0].camera.model, tilesplat::CameraModel::kFisheye);
  EXPECT_EQ(fisheye[0].camera.distortion, (std::array<double, 8>{0.1, 0, 0, -0.01, 0, 0, 0, 0}));
  std::ofstream(out / "k4.json") << transforms_json(views, "\"camera_model\": \"OPENCV\", \"k4\": 0.01, ");
  EXPECT_NE(tilesplat::testing::error_of([&] {
              tilesplat::load_camera_set(out / "k4.json");
            }).find("frame 0: k4 of an OPENCV camera is nerfstudio's r^8 term"),
            std::string::npos);
  std::ofstream(out / "panorama.json") << transforms_json(views, "\"camera_model\": \"EQUIRECTANGULAR\", ");
  const auto panorama = tilesplat::load_camera_set(out / "panorama.json");
  EXPECT_EQ(panorama[0].camera, tilesplat::equirectangular_camera(panorama[0].camera));
  std::ofstream(out / "fov.json") << transforms_json(views, "\"camera_model\": \"FOV\", ");
  EXPECT_NE(tilesplat::testing::error_of([&] {
              tilesplat::load_camera_set(out / "fov.json");
            }).find("camera_model FOV is not one the renderer draws"),
            std::string::npos);
  std::ofstream(out / "sizeless.json")
      << R"({"fl_x": 500, "frames": [{"transform_matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}]})";
  EXPECT_NE(tilesplat::testing::error_of([&] {
              tilesplat::load_camera_set(out / "sizeless.json");
            }).find("missing 'w'"),
            std::string::npos);
}

TEST(CameraSets, RendersFromEverySetAgree) {
  // The same view read from the three formats renders the same image (the rotations differ by
  // rounding only, far below what moves a pixel's value beyond float noise).
  const auto views = reference_views();
  const fs::path out = fresh_output_dir();
  write_colmap(views, out / "colmap", true);
  const auto from_colmap = tilesplat::load_camera_set(out / "colmap");
  auto& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(tilesplat::load_scene(tilesplat::testing::bundled_playbot()));
  const Camera json_camera = tilesplat::resize_camera(views[3].camera, 160, 90);
  const Camera colmap_camera = tilesplat::resize_camera(from_colmap[3].camera, 160, 90);
  const auto expected = renderer.render(json_camera);
  const auto actual = renderer.render(colmap_camera);
  const auto difference = tilesplat::compare_images(expected, actual);
  EXPECT_GT(difference.psnr_db, 80.0);
  EXPECT_LT(difference.max_abs, 1e-4);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(CameraPaths, KeysAreMetAndTheMotionIsSmooth) {
  tilesplat::CameraPath path;
  path.keys.resize(3);
  path.keys[0].position = {0, 0, -4};
  path.keys[1].position = {4, 0, 0};
  path.keys[2].position = {0, 0, 4};
  path.keys[1].vertical_fov_deg = 30;
  for (auto& key : path.keys)
    key.rotation = tilesplat::look_at_camera(key.position, {0, 0, 0}, {0, -1, 0}, 1, 1, 50).rotation;
  const auto cameras = tilesplat::sample_camera_path(path, 9, 64, 32);
  ASSERT_EQ(cameras.size(), 9u);
  EXPECT_EQ(cameras[0].position, path.keys[0].position);
  EXPECT_EQ(cameras[0].rotation, path.keys[0].rotation);
  for (const int k : {0, 1, 2}) {
    const Camera& at_key = cameras[size_t(k * 4)];
    for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(at_key.position[i], path.keys[size_t(k)].position[i], 1e-12);
    for (size_t i = 0; i < 9; ++i) EXPECT_NEAR(at_key.rotation[i], path.keys[size_t(k)].rotation[i], 1e-12);
    EXPECT_NEAR(at_key.tan_half_fov_y(),
                std::tan(path.keys[size_t(k)].vertical_fov_deg * std::numbers::pi / 360), 1e-12);
  }
  // Between the keys every rotation is a rotation, and consecutive frames turn by similar angles.
  for (const Camera& camera : cameras) {
    const auto& r = camera.rotation;
    for (size_t i = 0; i < 3; ++i)
      EXPECT_NEAR(r[i * 3] * r[i * 3] + r[i * 3 + 1] * r[i * 3 + 1] + r[i * 3 + 2] * r[i * 3 + 2], 1, 1e-12);
    // The slerp between look-at keys keeps the origin near the image centre.
    const auto origin = camera.to_camera({0, 0, 0});
    EXPECT_GT(origin[2], 0);
  }
  // A loop comes back to the first key after the last.
  path.loop = true;
  const Camera closing = tilesplat::camera_on_path(path, 1.0, 64, 32);
  for (size_t i = 0; i < 3; ++i) EXPECT_NEAR(closing.position[i], path.keys[0].position[i], 1e-12);
  EXPECT_THROW(tilesplat::camera_on_path(path, 1.5, 64, 32), std::invalid_argument);
  path.keys.resize(1);
  EXPECT_THROW(tilesplat::sample_camera_path(path, 3, 64, 32), std::invalid_argument);
}

TEST(CameraPaths, KeyframeFileMistakesNameTheKey) {
  const fs::path out = fresh_output_dir();
  auto error_for = [&](const std::string& text) {
    std::ofstream(out / "keys.json") << text;
    return tilesplat::testing::error_of([&] { tilesplat::load_camera_path(out / "keys.json"); });
  };
  const std::string good = R"({"position": [0, 0, 4], "look_at": [0, 0, 0]})";
  EXPECT_NE(error_for(R"({"keyframes": [)" + good + "]}").find("at least 2 keyframes, found 1"),
            std::string::npos);
  EXPECT_NE(error_for(R"({"keyframes": [)" + good + R"(, {"position": [1, 0, 4], "look_at": [1, 0, 4]}]})")
                .find("keyframe 1: 'look_at' must differ from 'position'"),
            std::string::npos);
  EXPECT_NE(error_for(R"({"keyframes": [)" + good +
                      R"(, {"position": [1, 0, 4], "rotation": [[2,0,0],[0,1,0],[0,0,1]]}]})")
                .find("keyframe 1: 'rotation' is not orthonormal"),
            std::string::npos);
  EXPECT_NE(error_for(R"({"keyframes": [)" + good +
                      R"(, {"position": [1, 0, 4], "look_at": [0, 0, 0], "fov": 180}]})")
                .find("keyframe 1: 'fov' must be"),
            std::string::npos);
  EXPECT_NE(error_for(R"({"keyframes": [)" + good + R"(, {"position": [1, 0, 4]}]})").find("exactly one of"),
            std::string::npos);
  EXPECT_NE(error_for(R"([1, 2])").find("expected an object"), std::string::npos);
  EXPECT_NE(error_for(R"({"keyframes": [)").find("invalid JSON"), std::string::npos);
}

}  // namespace

namespace {

// Files written in the layouts COLMAP and nerfstudio document, not by this project's writer
// (tests/data/camera_models/make_camera_models.py): views 2 and 5 of the bundled playbot's cameras.json.
const fs::path kCameraModels = fs::path(TILESPLAT_SOURCE_DIR) / "tests" / "data" / "camera_models";

std::vector<CameraView> bundled_views() {
  return tilesplat::load_cameras_json(tilesplat::testing::bundled_playbot_cameras());
}

TEST(DatasetCameras, ColmapTextModelWithSimplePinholeReadsAsTheTrainersCameras) {
  const auto views = tilesplat::load_camera_set(kCameraModels / "colmap" / "sparse" / "0");
  const auto expected = bundled_views();
  ASSERT_EQ(views.size(), 2u);
  EXPECT_EQ(views[0].name, "frame_00001.jpg");
  EXPECT_EQ(views[1].name, "frame_00002.jpg");
  // Camera 1 is SIMPLE_PINHOLE (f cx cy): one focal length for both axes.
  EXPECT_EQ(views[0].camera.fx, 1662.7687752661222);
  EXPECT_EQ(views[0].camera.fy, 1662.7687752661222);
  EXPECT_EQ(views[0].camera.cx, 960.0);
  EXPECT_EQ(views[0].camera.cy, 540.0);
  expect_near_camera(views[0].camera, expected[2].camera, 1e-12);
  expect_near_camera(views[1].camera, expected[5].camera, 1e-12);

  // Rendered: the same images as the trainer's cameras (rotations equal to rounding).
  auto& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(tilesplat::load_scene(tilesplat::testing::bundled_playbot()));
  for (const auto& [colmap, trainer] : {std::pair{0, 2}, std::pair{1, 5}}) {
    const auto a = renderer.render(tilesplat::resize_camera(views[size_t(colmap)].camera, 160, 90));
    const auto b = renderer.render(tilesplat::resize_camera(expected[size_t(trainer)].camera, 160, 90));
    EXPECT_LT(tilesplat::compare_images(a, b).max_abs, 1e-4) << "COLMAP image " << colmap;
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(DatasetCameras, NerfstudioTransformsJsonReadsAndItsOffCentreFrameRendersShifted) {
  const auto views = tilesplat::load_camera_set(kCameraModels / "nerfstudio" / "transforms.json");
  const auto expected = bundled_views();
  ASSERT_EQ(views.size(), 2u);
  EXPECT_EQ(views[0].name, "images/frame_00001.png");
  expect_near_camera(views[0].camera, expected[2].camera, 1e-12);
  // Frame 1 gives its own principal point, (+64, +128) pixels off the centre: the frame's fields win
  // over the file's.
  EXPECT_EQ(views[1].camera.cx, 1024.0);
  EXPECT_EQ(views[1].camera.cy, 668.0);

  // At a quarter of the size the principal point moves by (16, 32) pixels, one tile and two: the
  // image moves with it, right and down, and the tiles see the same splats, so the overlap agrees to
  // float rounding.
  auto& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(tilesplat::load_scene(tilesplat::testing::bundled_playbot()));
  const auto centred = renderer.render(tilesplat::resize_camera(views[0].camera, 480, 270));
  const auto shifted = renderer.render(tilesplat::resize_camera(views[1].camera, 480, 270));
  double worst = 0, changed = 0;
  for (int y = 32; y < 270; ++y)
    for (int x = 16; x < 480; ++x)
      for (size_t c = 0; c < 4; ++c) {
        const size_t at = 4 * (size_t(y) * 480 + size_t(x)) + c;
        const size_t from = 4 * (size_t(y - 32) * 480 + size_t(x - 16)) + c;
        worst = std::max(worst, double(std::abs(shifted.rgba[at] - centred.rgba[from])));
        changed = std::max(changed, double(std::abs(shifted.rgba[at] - centred.rgba[at])));
      }
  // 2e-4: the two frames' float rounding differs by up to 1.05e-4 on Mesa 25's lavapipe (below 1e-4
  // on Mesa 22); a wrong shift differs by more than 0.1.
  EXPECT_LT(worst, 2e-4) << "the off-centre frame is not the centred one moved by (16, 32)";
  EXPECT_GT(changed, 0.1) << "the principal point did not move the image";
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// The app takes the model folder and the transforms.json as --cameras, as a user would.
TEST(DatasetCameras, RenderAppTakesBothFiles) {
  const fs::path out = fresh_output_dir();
  for (const fs::path& cameras :
       {kCameraModels / "colmap" / "sparse" / "0", kCameraModels / "nerfstudio" / "transforms.json"}) {
    const auto result = tilesplat::testing::run_process(
        "", TILESPLAT_RENDER_EXE,
        {tilesplat::testing::bundled_playbot().string(), "--cameras", cameras.string(), "--views", "all",
         "--width", "96", "-o", (out / (cameras.filename().string() + "_%02d.exr")).string(),
         "--validation"});
    ASSERT_EQ(result.exit_code, 0) << result.err;
    EXPECT_EQ(result.err.find("validation messages"), std::string::npos) << result.err;
    EXPECT_TRUE(fs::exists(out / (cameras.filename().string() + "_00.exr")));
    EXPECT_TRUE(fs::exists(out / (cameras.filename().string() + "_01.exr")));
  }
}

}  // namespace
