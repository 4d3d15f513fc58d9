// Scene descriptions (docs/scene-format.md): the reader and its errors, model transforms with the
// exact rotation of spherical harmonics, merging, and the images a composed scene renders to.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "test_math.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"

namespace {

namespace fs = std::filesystem;
using namespace tilesplat;
using tilesplat::testing::bundled_playbot;
using tilesplat::testing::bundled_playbot_cameras;
using tilesplat::testing::bundled_sh3;
using tilesplat::testing::bundled_sh3_cameras;
using tilesplat::testing::temp_dir;
using tilesplat::testing::validated_renderer;

using Vec3 = std::array<double, 3>;
using Matrix3 = std::array<double, 9>;
using Quaternion = std::array<double, 4>;

constexpr double kShC0 = 0.28209479177387814;

// Images smaller than the views' 1920x1080 keep the float64 reference fast.
constexpr int kWidth = 240;
constexpr int kHeight = 135;

// Rendering a scene and the same scene moved (with the camera moved alike) differs only by float
// rounding of the moved positions, rotations and SH coefficients: 96 dB at worst in the float64
// reference on the bundled scenes (lavapipe, 2024), so 80 dB leaves room for a near-tie in depth
// order to flip. Leaving the SH unrotated instead gives 20 to 32 dB.
constexpr double kInvarianceMinPsnrDb = 80.0;
// GPU against GPU: the project's bound for the GPU against the reference, since a device with a
// float32 projection may flip such near-ties where the float64 one does not (162 dB on lavapipe).
constexpr double kGpuMinPsnrDb = 60.0;

fs::path write_text(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string number(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return buffer;
}

std::string json_vector(const Vec3& v) { return "[" + number(v[0]) + ", " + number(v[1]) + ", " + number(v[2]) + "]"; }

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

Camera view_of(const fs::path& cameras, size_t index) {
  return resize_camera(load_cameras_json(cameras).at(index).camera, kWidth, kHeight);
}

// --- independent small math (not the library's) for the hand-built scenes

using tilesplat::testing::math::multiply;
using tilesplat::testing::math::times;

Vec3 transposed_times(const Matrix3& m, const Vec3& v) {
  return {m[0] * v[0] + m[3] * v[1] + m[6] * v[2], m[1] * v[0] + m[4] * v[1] + m[7] * v[2],
          m[2] * v[0] + m[5] * v[1] + m[8] * v[2]};
}

// Extrinsic X, Y, Z Euler angles as documented: R = Rz Ry Rx.
Matrix3 euler_matrix_deg(const Vec3& degrees) {
  const double x = degrees[0] * std::numbers::pi / 180, y = degrees[1] * std::numbers::pi / 180,
               z = degrees[2] * std::numbers::pi / 180;
  const Matrix3 rx = {1, 0, 0, 0, std::cos(x), -std::sin(x), 0, std::sin(x), std::cos(x)};
  const Matrix3 ry = {std::cos(y), 0, std::sin(y), 0, 1, 0, -std::sin(y), 0, std::cos(y)};
  const Matrix3 rz = {std::cos(z), -std::sin(z), 0, std::sin(z), std::cos(z), 0, 0, 0, 1};
  return multiply(rz, multiply(ry, rx));
}

// Shepperd's method: the quaternion of a rotation matrix.
Quaternion quaternion_of(const Matrix3& m) {
  const double trace = m[0] + m[4] + m[8];
  Quaternion q{};
  if (trace > 0) {
    const double s = 2 * std::sqrt(1 + trace);
    q = {s / 4, (m[7] - m[5]) / s, (m[2] - m[6]) / s, (m[3] - m[1]) / s};
  } else if (m[0] > m[4] && m[0] > m[8]) {
    const double s = 2 * std::sqrt(1 + m[0] - m[4] - m[8]);
    q = {(m[7] - m[5]) / s, s / 4, (m[1] + m[3]) / s, (m[2] + m[6]) / s};
  } else if (m[4] > m[8]) {
    const double s = 2 * std::sqrt(1 + m[4] - m[0] - m[8]);
    q = {(m[2] - m[6]) / s, (m[1] + m[3]) / s, s / 4, (m[5] + m[7]) / s};
  } else {
    const double s = 2 * std::sqrt(1 + m[8] - m[0] - m[4]);
    q = {(m[3] - m[1]) / s, (m[2] + m[6]) / s, (m[5] + m[7]) / s, s / 4};
  }
  return q;
}

Quaternion hamilton(const Quaternion& a, const Quaternion& b) {
  return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3], a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
          a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1], a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}

Vec3 normalized(const Vec3& v) {
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return {v[0] / n, v[1] / n, v[2] / n};
}

// The scene moved by (R, s, t) by hand, for one camera: the view-dependent colour is baked into SH
// degree 0 by evaluating the ORIGINAL coefficients at the direction the camera sees each Gaussian
// from, taken back into the capture's frame (R^T d). An exact, independent stand-in for SH rotation.
GaussianScene move_and_bake(const GaussianScene& source, const Matrix3& r, double s, const Vec3& t,
                            const Camera& camera) {
  GaussianScene out;
  out.sh_degree = 0;
  const Quaternion q_r = quaternion_of(r);
  const size_t k = size_t(source.sh_coefficients());
  for (size_t i = 0; i < source.size(); ++i) {
    const Vec3 p = times(r, {source.positions[3 * i], source.positions[3 * i + 1], source.positions[3 * i + 2]});
    std::array<float, 3> moved{};
    for (size_t a = 0; a < 3; ++a) {
      moved[a] = float(s * p[a] + t[a]);
      out.positions.push_back(moved[a]);
      out.log_scales.push_back(float(double(source.log_scales[3 * i + a]) + std::log(s)));
    }
    const float* q = &source.rotations[4 * i];
    Quaternion rotated = hamilton(q_r, {q[0], q[1], q[2], q[3]});
    const double n = std::sqrt(rotated[0] * rotated[0] + rotated[1] * rotated[1] + rotated[2] * rotated[2] +
                               rotated[3] * rotated[3]);
    for (double component : rotated) out.rotations.push_back(float(component / n));
    out.opacity_logits.push_back(source.opacity_logits[i]);
    const Vec3 seen_from = normalized({moved[0] - camera.position[0], moved[1] - camera.position[1],
                                       moved[2] - camera.position[2]});
    const auto colour = eval_sh(source.sh_degree, &source.sh[i * k * 3], transposed_times(r, seen_from));
    for (double c : colour) out.sh.push_back(float(c / kShC0));
  }
  return out;
}

void append_scene(GaussianScene& out, const GaussianScene& part) {
  out.positions.insert(out.positions.end(), part.positions.begin(), part.positions.end());
  out.log_scales.insert(out.log_scales.end(), part.log_scales.begin(), part.log_scales.end());
  out.rotations.insert(out.rotations.end(), part.rotations.begin(), part.rotations.end());
  out.opacity_logits.insert(out.opacity_logits.end(), part.opacity_logits.begin(), part.opacity_logits.end());
  out.sh.insert(out.sh.end(), part.sh.begin(), part.sh.end());
}

// A binary little-endian 3DGS PLY of the scene (f_rest channel-major, as the trainer writes it).
void write_ply(const fs::path& path, const GaussianScene& scene) {
  const size_t k = size_t(scene.sh_coefficients());
  std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(scene.size()) + "\n";
  std::vector<std::string> names = {"x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2"};
  for (size_t r = 0; r < 3 * (k - 1); ++r) names.push_back("f_rest_" + std::to_string(r));
  for (const char* name : {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
    names.push_back(name);
  for (const auto& name : names) header += "property float " + name + "\n";
  header += "end_header\n";
  std::vector<float> values;
  for (size_t i = 0; i < scene.size(); ++i) {
    for (size_t a = 0; a < 3; ++a) values.push_back(scene.positions[3 * i + a]);
    for (size_t c = 0; c < 3; ++c) values.push_back(scene.sh[i * k * 3 + c]);
    for (size_t c = 0; c < 3; ++c)
      for (size_t coefficient = 1; coefficient < k; ++coefficient)
        values.push_back(scene.sh[(i * k + coefficient) * 3 + c]);
    values.push_back(scene.opacity_logits[i]);
    for (size_t a = 0; a < 3; ++a) values.push_back(scene.log_scales[3 * i + a]);
    for (size_t a = 0; a < 4; ++a) values.push_back(scene.rotations[4 * i + a]);
  }
  std::ofstream out(path, std::ios::binary);
  out << header;
  out.write(reinterpret_cast<const char*>(values.data()), std::streamsize(values.size() * sizeof(float)));
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

void expect_bit_identical(const GaussianScene& a, const GaussianScene& b) {
  EXPECT_EQ(a.sh_degree, b.sh_degree);
  EXPECT_TRUE(same_bits(a.positions, b.positions));
  EXPECT_TRUE(same_bits(a.log_scales, b.log_scales));
  EXPECT_TRUE(same_bits(a.rotations, b.rotations));
  EXPECT_TRUE(same_bits(a.opacity_logits, b.opacity_logits));
  EXPECT_TRUE(same_bits(a.sh, b.sh));
  EXPECT_TRUE(same_bits(a.normals, b.normals));
}

RenderImage render_gpu(const GaussianScene& scene, const Camera& camera, const RenderSettings& settings = {}) {
  Renderer& renderer = validated_renderer();
  renderer.set_scene(scene);
  RenderImage image = renderer.render(camera, settings);
  EXPECT_EQ(renderer.validation_messages(), 0u);
  return image;
}

Quaternion random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Quaternion q = {normal(rng), normal(rng), normal(rng), normal(rng)};
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double& c : q) c /= n;
  return q;
}

Vec3 random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  return normalized({normal(rng), normal(rng), normal(rng)});
}

// ---------------------------------------------------------------------------------------------
// Reading

TEST(SceneDescription, ParsesAValidDescription) {
  const fs::path dir = temp_dir();
  fs::copy_file(bundled_sh3(), dir / "model.ply", fs::copy_options::overwrite_existing);
  fs::copy_file(bundled_sh3_cameras(), dir / "cams.json", fs::copy_options::overwrite_existing);
  const fs::path file = write_text(dir / "scene.json", R"({
    "$schema": "../docs/scene.schema.json",
    "version": 1,
    "models": [
      {"path": "model.ply"},
      {"path": ")" + bundled_playbot().string() + R"(", "translation": [1, 2, 3], "rotation_deg": [0, 90, 0],
       "scale": 2, "z_up": true},
      {"path": "model.ply", "quaternion": [0, 0, 0, 1], "scale": [0.5, 0.5, 0.5]}
    ],
    "cameras": [
      {"name": "pinhole", "width": 640, "height": 360, "fx": 500, "fy": 510, "cy": 170,
       "position": [0, 0, -3], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]},
      {"width": 320, "height": 240, "look_at": {"eye": [0, -1, -4], "target": [0, 0, 0], "fov_deg": 40}}
    ],
    "background": [0.25, 0.5, 1],
    "effects": {"sh_degree": 1, "antialiasing": "mip", "exposure": -1.5, "tone_map": "aces",
                "lights": [{"type": "directional", "direction": [0, 2, 0], "color": [1, 0.9, 0.8]},
                           {"type": "point", "position": [1, -2, 0], "colour": [1, 1, 1], "intensity": 5}],
                "ambient": [0.1, 0.2, 0.3]},
    "outputs": ["color", "depth", "splat_count"]
  })");

  const SceneDescription d = load_scene_description(file);
  EXPECT_EQ(d.file, file);
  ASSERT_EQ(d.models.size(), 3u);
  EXPECT_EQ(d.models[0].path, dir / "model.ply");
  EXPECT_TRUE(d.models[0].transform.is_identity());
  EXPECT_EQ(d.models[1].path, bundled_playbot());
  EXPECT_EQ(d.models[1].transform.translation, (Vec3{1, 2, 3}));
  const Quaternion y90 = d.models[1].transform.rotation;
  EXPECT_NEAR(y90[0], std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(y90[2], std::sqrt(0.5), 1e-15);
  EXPECT_EQ(d.models[1].transform.scale, (Vec3{2, 2, 2}));
  EXPECT_TRUE(d.models[1].transform.z_up);
  EXPECT_EQ(d.models[2].transform.rotation, (Quaternion{0, 0, 0, 1}));
  EXPECT_EQ(d.models[2].transform.scale, (Vec3{0.5, 0.5, 0.5}));

  ASSERT_EQ(d.cameras.size(), 2u);
  EXPECT_EQ(d.cameras[0].name, "pinhole");
  EXPECT_EQ(d.cameras[0].camera.width, 640);
  EXPECT_EQ(d.cameras[0].camera.fy, 510);
  EXPECT_EQ(d.cameras[0].camera.cx, 320);  // the image centre by default
  EXPECT_EQ(d.cameras[0].camera.cy, 170);
  EXPECT_EQ(d.cameras[0].camera.position, (Vec3{0, 0, -3}));
  const Camera expected_look_at = look_at_camera({0, -1, -4}, {0, 0, 0}, {0, -1, 0}, 320, 240, 40);
  EXPECT_EQ(d.cameras[1].camera.rotation, expected_look_at.rotation);
  EXPECT_EQ(d.cameras[1].camera.fy, expected_look_at.fy);
  EXPECT_TRUE(d.cameras_file.empty());

  EXPECT_EQ(d.background, (std::array<float, 3>{0.25f, 0.5f, 1.0f}));
  EXPECT_EQ(d.effects.sh_degree, 1);
  EXPECT_EQ(d.effects.antialiasing, Antialiasing::kMip);
  EXPECT_EQ(d.effects.exposure_stops, -1.5);
  EXPECT_EQ(d.effects.tone_map, ToneMap::kAces);
  ASSERT_EQ(d.effects.lights.size(), 2u);
  EXPECT_EQ(d.effects.lights[0].type, SceneLight::Type::kDirectional);
  EXPECT_EQ(d.effects.lights[0].direction, (Vec3{0, 1, 0}));  // normalised
  EXPECT_EQ(d.effects.lights[0].color, (Vec3{1, 0.9, 0.8}));
  EXPECT_EQ(d.effects.lights[1].type, SceneLight::Type::kPoint);
  EXPECT_EQ(d.effects.lights[1].position, (Vec3{1, -2, 0}));
  EXPECT_EQ(d.effects.lights[1].intensity, 5);
  EXPECT_EQ(d.effects.ambient, (Vec3{0.1, 0.2, 0.3}));
  EXPECT_TRUE(d.outputs.color);
  EXPECT_FALSE(d.outputs.alpha);
  EXPECT_TRUE(d.outputs.depth);
  EXPECT_TRUE(d.outputs.splat_count);

  // Cameras may instead name a trainer cameras.json, relative to the scene file.
  const fs::path with_file =
      write_text(dir / "with_cameras_file.json", R"({"models": [{"path": "model.ply"}], "cameras": "cams.json"})");
  const SceneDescription from_file = load_scene_description(with_file);
  EXPECT_EQ(from_file.cameras_file, dir / "cams.json");
  EXPECT_EQ(from_file.cameras.size(), load_cameras_json(bundled_sh3_cameras()).size());
}

TEST(SceneDescription, DefaultsAreOffAndViewDependentFalseMeansDegreeZero) {
  const fs::path dir = temp_dir();
  const std::string model = R"({"models": [{"path": ")" + bundled_sh3().string() + R"("}])";
  const SceneDescription plain = parse_scene_description(model + "}", dir / "plain.json");
  EXPECT_TRUE(plain.cameras.empty());
  EXPECT_EQ(plain.background, (std::array<float, 3>{0, 0, 0}));
  EXPECT_FALSE(plain.effects.sh_degree.has_value());
  EXPECT_EQ(plain.effects.antialiasing, Antialiasing::kClassic);
  EXPECT_TRUE(plain.effects.lights.empty());
  EXPECT_EQ(plain.effects.ambient, (Vec3{0, 0, 0}));
  EXPECT_EQ(plain.effects.exposure_stops, 0);
  EXPECT_EQ(plain.effects.tone_map, ToneMap::kNone);
  EXPECT_TRUE(plain.outputs.color && plain.outputs.alpha);
  EXPECT_FALSE(plain.outputs.depth || plain.outputs.splat_count);

  const auto flat = parse_scene_description(model + R"(, "effects": {"view_dependent": false}})", dir / "flat.json");
  EXPECT_EQ(flat.effects.sh_degree, 0);
  const auto full = parse_scene_description(model + R"(, "effects": {"view_dependent": true}})", dir / "full.json");
  EXPECT_FALSE(full.effects.sh_degree.has_value());
}

struct Mistake {
  std::string json;       // $PLY stands for a splat file that exists
  std::string json_path;  // where the message must say the mistake is
  std::vector<std::string> phrases;
};

TEST(SceneDescription, EveryMistakeNamesTheFileAndTheJsonPath) {
  const std::vector<Mistake> mistakes = {
      {R"({"model": [{"path": "$PLY"}]})", "model", {"unknown key", "did you mean 'models'?", "allowed:"}},
      {R"({"background": [0, 0, 0]})", "top level", {"missing 'models'"}},
      {R"({"models": []})", "models", {"at least one model"}},
      {R"({"models": [{"path": "missing.ply"}]})", "models[0].path", {"does not exist", "$DIR/missing.ply"}},
      {R"({"models": [{"path": "$PLY", "scael": 2}]})", "models[0].scael", {"did you mean 'scale'?"}},
      {R"({"models": [{"path": "$PLY", "scale": [1, 2, 1]}]})",
       "models[0].scale",
       {"non-uniform scale", "spherical harmonics"}},
      {R"({"models": [{"path": "$PLY", "scale": 0}]})",
       "models[0].scale",
       {"from 1e-06 to 1000000", "got 0"}},
      {R"({"models": [{"path": "$PLY", "scale": "big"}]})",
       "models[0].scale",
       {"must be a number", "got a string"}},
      {R"({"models": [{"path": "$PLY", "translation": [0, 1e12, 0]}]})",
       "models[0].translation[1]",
       {"from -1000000000 to 1000000000", "got 1e+12"}},
      {R"({"models": [{"path": "$PLY", "translation": [0, 1]}]})",
       "models[0].translation",
       {"array of 3 numbers", "got 2 values"}},
      {R"({"models": [{"path": "$PLY", "rotation_deg": [0, 400, 0]}]})",
       "models[0].rotation_deg[1]",
       {"from -360 to 360"}},
      {R"({"models": [{"path": "$PLY", "rotation_deg": [0, 0, 0], "quaternion": [1, 0, 0, 0]}]})",
       "models[0]",
       {"either 'rotation_deg' or 'quaternion', not both"}},
      {R"({"models": [{"path": "$PLY", "quaternion": [1, 1, 0, 0]}]})",
       "models[0].quaternion",
       {"unit quaternion", "norm is 1.41"}},
      {R"({"models": [{"path": "$PLY", "z_up": "yes"}]})",
       "models[0].z_up",
       {"true or false", "got a string"}},
      {R"({"models": [{"path": "$PLY"}], "cameras": "nowhere.json"})",
       "cameras",
       {"cameras file", "$DIR/nowhere.json", "does not exist"}},
      {R"({"models": [{"path": "$PLY"}], "cameras": [{"width": 0, "height": 10, "fx": 1, "fy": 1,
          "position": [0, 0, 0], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}]})",
       "cameras[0].width",
       {"from 1 to 65536", "got 0"}},
      {R"({"models": [{"path": "$PLY"}], "cameras": [{"width": 10.5, "height": 10, "fx": 1, "fy": 1,
          "position": [0, 0, 0], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}]})",
       "cameras[0].width",
       {"must be an integer from 1 to 65536", "got 10.5"}},
      {R"({"models": [{"path": "$PLY"}], "cameras": [{"width": 10, "height": 10, "fx": 1, "fy": 1,
          "position": [0, 0, 0], "rotation": [[1, 0, 0], [0, 2, 0], [0, 0, 1]]}]})",
       "cameras[0].rotation[1][1]",
       {"from -1.001 to 1.001"}},
      {R"({"models": [{"path": "$PLY"}], "cameras": [{"width": 10, "height": 10, "fx": 1, "fy": 1,
          "position": [0, 0, 0], "rotation": [[1, 0, 0], [0, 0.8, 0], [0, 0, 1]]}]})",
       "cameras[0].rotation",
       {"not orthonormal"}},
      {R"({"models": [{"path": "$PLY"}], "cameras": [{"width": 10, "height": 10, "fx": 5,
          "look_at": {"eye": [0, 0, 0], "target": [0, 0, 1]}}]})",
       "cameras[0].fx",
       {"not allowed with 'look_at'"}},
      {R"({"models": [{"path": "$PLY"}], "cameras": [{"width": 10, "height": 10,
          "look_at": {"eye": [0, 0, 0], "target": [0, 0, 1], "up": [0, 0, 2]}}]})",
       "cameras[0].look_at.up",
       {"parallel to the view direction"}},
      {R"({"models": [{"path": "$PLY"}], "cameras": [{"width": 10, "height": 10, "model": "fish-eye",
          "look_at": {"eye": [0, 0, 0], "target": [0, 0, 1]}}]})",
       "cameras[0].model",
       {"unknown value 'fish-eye'", "did you mean 'fisheye'?"}},
      {R"({"models": [{"path": "$PLY"}], "cameras": [{"width": 10, "height": 10, "model": "fisheye",
          "distortion": [0.1, 0, 0, 0, 0.2], "look_at": {"eye": [0, 0, 0], "target": [0, 0, 1]}}]})",
       "cameras[0].distortion",
       {"the fisheye camera has 4 distortion coefficients, got 5"}},
      {R"({"models": [{"path": "$PLY"}], "cameras": [{"width": 10, "height": 10, "distortion": [0.1],
          "look_at": {"eye": [0, 0, 0], "target": [0, 0, 1]}}]})",
       "cameras[0].distortion",
       {"the pinhole camera has 0 distortion coefficients, got 1"}},
      {R"({"models": [{"path": "$PLY"}], "cameras": [{"width": 10, "height": 10, "model": "orthographic",
          "look_at": {"eye": [0, 0, 0], "target": [0, 0, 1]}}]})",
       "cameras[0]",
       {"needs 'view_height'"}},
      {R"({"models": [{"path": "$PLY"}], "cameras": [{"width": 10, "height": 10, "model": "opencv",
          "look_at": {"eye": [0, 0, 0], "target": [0, 0, 1]}}]})",
       "cameras[0]",
       {"give fx and fy instead of 'look_at'"}},
      {R"({"models": [{"path": "$PLY"}], "cameras": [{"width": 10, "height": 10, "model": "fisheye",
          "look_at": {"eye": [0, 0, 0], "target": [0, 0, 1], "fov_deg": 400}}]})",
       "cameras[0].look_at.fov_deg",
       {"from 0 to 360"}},
      {R"({"models": [{"path": "$PLY"}], "background": "white"})",
       "background",
       {"array of 3 numbers", "got a string"}},
      {R"({"models": [{"path": "$PLY"}], "effects": {"antialias": "mip"}})",
       "effects.antialias",
       {"unknown key", "did you mean 'antialiasing'?"}},
      {R"({"models": [{"path": "$PLY"}], "effects": {"antialiasing": "mipp"}})",
       "effects.antialiasing",
       {"unknown value 'mipp'", "did you mean 'mip'?", "'classic', 'antialiased', 'mip'"}},
      {R"({"models": [{"path": "$PLY"}], "effects": {"sh_degree": 4}})",
       "effects.sh_degree",
       {"from 0 to 3", "got 4"}},
      {R"({"models": [{"path": "$PLY"}], "effects": {"sh_degree": 2, "view_dependent": false}})",
       "effects.view_dependent",
       {"contradicts 'sh_degree'"}},
      {R"({"models": [{"path": "$PLY"}], "effects": {"lights": [{"type": "point", "position": [0, 0, 0]},
          {"type": "spot", "position": [0, 0, 0]}]}})",
       "effects.lights[1].type",
       {"unknown value 'spot'", "'directional', 'point'"}},
      {R"({"models": [{"path": "$PLY"}], "effects": {"lights": [{"type": "directional", "position": [0, 0, 0]}]}})",
       "effects.lights[0].position",
       {"directional light has a 'direction'"}},
      {R"({"models": [{"path": "$PLY"}], "effects": {"lights": [{"type": "point", "position": [0, 0, 0]}],
          "ambient": [0.1, -0.1, 0]}})",
       "effects.ambient[1]",
       {"from 0 to"}},
      {R"({"models": [{"path": "$PLY"}], "effects": {"ambient": [0.1, 0.1, 0.1]}})",
       "effects.ambient",
       {"applies only to relighting", "at least one light in 'lights'"}},
      {R"({"models": [{"path": "$PLY"}], "effects": {"exposure": 50}})",
       "effects.exposure",
       {"from -20 to 20"}},
      {R"({"models": [{"path": "$PLY"}], "effects": {"tone_map": "filmic"}})",
       "effects.tone_map",
       {"'none', 'aces', 'reinhard'"}},
      {R"({"models": [{"path": "$PLY"}], "outputs": ["depth"]})", "outputs", {"must include 'color'"}},
      {R"({"models": [{"path": "$PLY"}], "outputs": ["color", "color"]})", "outputs[1]", {"listed twice"}},
      {R"({"models": [{"path": "$PLY"}], "outputs": ["colour"]})", "outputs[0]", {"did you mean 'color'?"}},
      {R"({"models": [{"path": "$PLY", "path": "$PLY"}]})", "models[0].path", {"duplicate key"}},
      {R"({"version": 2, "models": [{"path": "$PLY"}]})", "version", {"format version 1 only"}},
      {R"([{"path": "$PLY"}])", "top level", {"must be an object", "got an array", "cameras.json?"}},
  };
  const fs::path dir = temp_dir();
  const fs::path file = dir / "mistake.json";
  for (const Mistake& mistake : mistakes) {
    SCOPED_TRACE(mistake.json);
    write_text(file, replace_all(mistake.json, "$PLY", bundled_sh3().string()));
    try {
      load_scene_description(file);
      ADD_FAILURE() << "no error";
    } catch (const SceneError& error) {
      const std::string message = error.what();
      EXPECT_EQ(message.rfind(file.string() + ": " + mistake.json_path + ": ", 0), 0u) << message;
      for (const auto& phrase : mistake.phrases)
        EXPECT_NE(message.find(replace_all(phrase, "$DIR", dir.string())), std::string::npos)
            << "missing '" << phrase << "' in: " << message;
    }
  }
}

TEST(SceneDescription, CamerasHaveModels) {
  const fs::path dir = temp_dir();
  const std::string text = replace_all(R"({"models": [{"path": "$PLY"}], "cameras": [
      {"width": 64, "height": 48, "fx": 50, "fy": 52, "position": [0, 0, -3],
       "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "model": "opencv", "distortion": [-0.1, 0.02, 0.001]},
      {"width": 64, "height": 48, "model": "fisheye", "distortion": [0.05],
       "look_at": {"eye": [0, 0, -3], "target": [0, 0, 0], "fov_deg": 270}},
      {"width": 64, "height": 48, "model": "orthographic", "view_height": 2.5,
       "look_at": {"eye": [0, 0, -3], "target": [0, 0, 0]}},
      {"width": 64, "height": 32, "model": "equirectangular", "look_at": {"eye": [0, 0, -3], "target": [0, 0, 0]}}]})",
                                       "$PLY", bundled_sh3().string());
  const SceneDescription d = load_scene_description(write_text(dir / "models.json", text));
  ASSERT_EQ(d.cameras.size(), 4u);
  EXPECT_EQ(d.cameras[0].camera.model, CameraModel::kOpenCV);
  EXPECT_EQ(d.cameras[0].camera.distortion, (std::array<double, 8>{-0.1, 0.02, 0.001, 0, 0, 0, 0, 0}));
  EXPECT_EQ(d.cameras[0].camera.fy, 52);
  EXPECT_EQ(d.cameras[1].camera.model, CameraModel::kFisheye);
  EXPECT_EQ(d.cameras[1].camera.distortion[0], 0.05);
  EXPECT_NEAR(d.cameras[1].camera.fx, 24 / (135 * std::numbers::pi / 180), 1e-12);  // 270 degrees over 48 px
  EXPECT_EQ(d.cameras[2].camera.model, CameraModel::kOrthographic);
  EXPECT_NEAR(d.cameras[2].camera.fy, 48 / 2.5, 1e-12);
  EXPECT_EQ(d.cameras[3].camera, equirectangular_camera(d.cameras[3].camera));
}

TEST(SceneDescription, CamerasHaveLenses) {
  const fs::path dir = temp_dir();
  const std::string text = replace_all(R"({"models": [{"path": "$PLY"}], "cameras": [
      {"width": 64, "height": 48, "fx": 50, "fy": 50, "position": [0, 0, -3],
       "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "lens": {"aperture": 0.1, "focus_distance": 2.5}},
      {"width": 64, "height": 48, "look_at": {"eye": [0, 0, -4], "target": [0, 0, 0], "fov_deg": 40},
       "lens": {"f_stop": 2, "sensor_width_mm": 24, "units_per_metre": 10, "samples": 12}},
      {"width": 64, "height": 48, "look_at": {"eye": [0, 0, -4], "target": [0, 0, 0]}}]})",
                                       "$PLY", bundled_sh3().string());
  const SceneDescription d = load_scene_description(write_text(dir / "lenses.json", text));
  ASSERT_EQ(d.lenses.size(), 3u);
  EXPECT_EQ(d.lenses[0].aperture_diameter, 0.1);
  EXPECT_EQ(d.lenses[0].focus_distance, 2.5);
  EXPECT_EQ(d.lenses[0].samples, ThinLens{}.samples);
  // f/2 on a 24 mm sensor, the scene in decimetres: the focal length over 2, in scene units.
  EXPECT_DOUBLE_EQ(d.lenses[1].aperture_diameter, aperture_for_f_stop(d.cameras[1].camera, 2, 24, 10));
  EXPECT_DOUBLE_EQ(d.lenses[1].focus_distance, 4.0);  // a look_at camera focuses on its target
  EXPECT_EQ(d.lenses[1].samples, 12);
  EXPECT_FALSE(d.lenses[2].enabled());

  const std::string camera =
      R"("width": 64, "height": 48, "look_at": {"eye": [0, 0, -4], "target": [0, 0, 0]})";
  const std::vector<std::pair<std::string, std::string>> mistakes = {
      {R"("lens": {"aperture": 0.1, "f_stop": 2})",
       "'aperture' (a diameter in scene units) or 'f_stop', one of them"},
      {R"("lens": {"focus_distance": 2})", "or 'f_stop', one of them"},
      {R"("lens": {"aperture": 0.1, "sensor_width_mm": 24})", "applies to 'f_stop' only"},
      {R"("lens": {"aperture": -1})", "cameras[0].lens.aperture"},
      {R"("lens": {"aperture": 0.1, "samples": 0})", "cameras[0].lens.samples"},
      {R"("lens": {"aperture": 0.1, "focal": 3})", "unknown key"},
      {R"("model": "fisheye", "lens": {"aperture": 0.1})",
       "depth of field needs a pinhole camera, not fisheye"},
  };
  for (const auto& [lens, phrase] : mistakes) {
    const std::string bad =
        replace_all(R"({"models": [{"path": "$PLY"}], "cameras": [{)" + camera + ", " + lens + "}]}", "$PLY",
                    bundled_sh3().string());
    const std::string message =
        tilesplat::testing::error_of([&] { load_scene_description(write_text(dir / "bad.json", bad)); });
    EXPECT_NE(message.find(phrase), std::string::npos) << lens << ": " << message;
  }
  const std::string no_focus =
      replace_all(R"({"models": [{"path": "$PLY"}], "cameras": [{"width": 64, "height": 48,
      "fx": 50, "fy": 50, "position": [0, 0, -3], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
      "lens": {"aperture": 0.1}}]})",
                  "$PLY", bundled_sh3().string());
  EXPECT_NE(tilesplat::testing::error_of([&] {
              load_scene_description(write_text(dir / "no_focus.json", no_focus));
            }).find("cameras[0].lens: missing 'focus_distance'"),
            std::string::npos);
}

TEST(SceneDescription, ModelsMoveAndCamerasHaveShutters) {
  const fs::path dir = temp_dir();
  const std::string text = replace_all(R"({"models": [
      {"path": "$PLY"},
      {"path": "$PLY", "translation": [1, 0, 0], "rotation_deg": [0, 30, 0], "scale": 2,
       "motion": {"translation": [-1, 0, 0.5]}},
      {"path": "$PLY", "z_up": true, "motion": {"rotation_deg": [0, 90, 0], "scale": 3}}],
    "cameras": [
      {"width": 64, "height": 48, "look_at": {"eye": [0, 0, -4], "target": [0, 0, 0]},
       "shutter": {"close": 0.5, "samples": 8, "end": {"look_at": {"eye": [1, 0, -4], "target": [0, 0, 0]}}}},
      {"width": 64, "height": 48, "fx": 50, "fy": 50, "position": [0, 0, -3],
       "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
       "shutter": {"open": 0.25, "close": 1, "scan": "bottom-to-top",
                   "end": {"position": [0, 0.5, -3], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}}},
      {"width": 64, "height": 48, "look_at": {"eye": [0, 0, -4], "target": [0, 0, 0]},
       "shutter": {"close": 1}},
      {"width": 64, "height": 48, "look_at": {"eye": [0, 0, -4], "target": [0, 0, 0]}}]})",
                                       "$PLY", bundled_sh3().string());
  const SceneDescription d = load_scene_description(write_text(dir / "moving.json", text));
  ASSERT_EQ(d.models.size(), 3u);
  EXPECT_FALSE(d.models[0].motion.has_value());
  ASSERT_TRUE(d.models[1].motion.has_value());
  // Each key the model's own where the motion leaves it out.
  EXPECT_EQ(d.models[1].motion->translation, (std::array<double, 3>{-1, 0, 0.5}));
  EXPECT_EQ(d.models[1].motion->rotation, d.models[1].transform.rotation);
  EXPECT_EQ(d.models[1].motion->scale, d.models[1].transform.scale);
  ASSERT_TRUE(d.models[2].motion.has_value());
  EXPECT_TRUE(d.models[2].motion->z_up);
  EXPECT_EQ(d.models[2].motion->rotation, quaternion_from_euler_xyz_deg({0, 90, 0}));
  EXPECT_EQ(d.models[2].motion->scale, (std::array<double, 3>{3, 3, 3}));
  const SceneInstances instances = load_scene_instances(d);
  EXPECT_TRUE(instances.moves());
  EXPECT_EQ(instances.instances[1].at(1).translation, d.models[1].motion->translation);
  // At time 0 the models are where the file places them: load_described_scene's scene.
  EXPECT_EQ(merge_instances(instances, 0).positions, load_described_scene(d).positions);

  ASSERT_EQ(d.shutters.size(), 4u);
  EXPECT_EQ(d.shutters[0].open, 0.0);
  EXPECT_EQ(d.shutters[0].close, 0.5);
  EXPECT_EQ(d.shutters[0].samples, 8);
  ASSERT_TRUE(d.shutters[0].end_camera.has_value());
  EXPECT_EQ(d.shutters[0].end_camera->fx, d.cameras[0].camera.fx);  // the same camera, moved
  EXPECT_EQ(d.shutters[0].end_camera->position, (std::array<double, 3>{1, 0, -4}));
  EXPECT_TRUE(d.shutters[0].enabled());
  EXPECT_EQ(d.shutters[1].open, 0.25);
  EXPECT_EQ(d.shutters[1].scan, ShutterScan::kBottomToTop);
  EXPECT_EQ(d.shutters[1].end_camera->position, (std::array<double, 3>{0, 0.5, -3}));
  EXPECT_EQ(d.shutters[1].samples, Shutter{}.samples);
  // Open over a still camera: it blurs the moving models alone.
  EXPECT_EQ(d.shutters[2].close, 1.0);
  EXPECT_FALSE(d.shutters[2].end_camera.has_value());
  EXPECT_EQ(d.shutters[3], Shutter{});

  const std::string camera =
      R"("width": 64, "height": 48, "look_at": {"eye": [0, 0, -4], "target": [0, 0, 0]})";
  const std::vector<std::pair<std::string, std::string>> mistakes = {
      {R"("shutter": {"open": 0.5})", "cameras[0].shutter: missing 'close'"},
      {R"("shutter": {"open": 0.5, "close": 0.5})", "cameras[0].shutter.close: must be after 'open' (0.5)"},
      {R"("shutter": {"close": 1.5})", "cameras[0].shutter.close"},
      {R"("shutter": {"close": 1, "samples": 0})", "cameras[0].shutter.samples"},
      {R"("shutter": {"close": 1, "scan": "sideways"})", "cameras[0].shutter.scan"},
      {R"("shutter": {"close": 1, "angle": 180})", "unknown key"},
      {R"("shutter": {"close": 1, "end": {"position": [0, 0, 1]}})",
       "cameras[0].shutter.end: missing 'rotation'"},
      {R"("shutter": {"close": 1, "end": {"look_at": {"eye": [0, 0, -4], "target": [0, 0, 0], "fov_deg": 30}}})",
       "the end camera keeps the camera's intrinsics"},
      {R"("shutter": {"close": 1, "end": {"look_at": {"eye": [0, 0, 0], "target": [0, 0, 0]}}})",
       "cameras[0].shutter.end.look_at.target: must differ from 'eye'"},
      {R"("shutter": {"close": 1, "end": {"position": [0, 0, 1], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, -1]]}})",
       "is a reflection"},
  };
  for (const auto& [shutter, phrase] : mistakes) {
    const std::string bad =
        replace_all(R"({"models": [{"path": "$PLY"}], "cameras": [{)" + camera + ", " + shutter + "}]}",
                    "$PLY", bundled_sh3().string());
    const std::string message =
        tilesplat::testing::error_of([&] { load_scene_description(write_text(dir / "bad.json", bad)); });
    EXPECT_NE(message.find(phrase), std::string::npos) << shutter << ": " << message;
  }
  const std::vector<std::pair<std::string, std::string>> motions = {
      {R"("motion": {"scale": [1, 2, 1]})", "models[0].motion.scale"},
      {R"("motion": {"z_up": true})", "unknown key"},
      {R"("motion": {"rotation_deg": [0, 1, 0], "quaternion": [1, 0, 0, 0]})", "not both"},
      {R"("motion": {"translation": [0, 0, 1e12]})", "models[0].motion.translation"},
      {R"("motion": [0, 0, 1])", "models[0].motion"},
  };
  for (const auto& [motion, phrase] : motions) {
    const std::string bad =
        replace_all(R"({"models": [{"path": "$PLY", )" + motion + "}]}", "$PLY", bundled_sh3().string());
    const std::string message =
        tilesplat::testing::error_of([&] { load_scene_description(write_text(dir / "bad.json", bad)); });
    EXPECT_NE(message.find(phrase), std::string::npos) << motion << ": " << message;
  }
}

TEST(SceneDescription, MalformedJsonGivesLineAndColumn) {
  const fs::path dir = temp_dir();
  auto message_of = [&](const std::string& text) {
    try {
      load_scene_description(write_text(dir / "broken.json", text));
    } catch (const SceneError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  const std::string trailing_comma = message_of("{\n  \"models\": [\n    {\"path\": \"a.ply\",}\n  ]\n}\n");
  EXPECT_EQ(trailing_comma.rfind((dir / "broken.json").string() + ": line 3, column 22: malformed JSON: ", 0), 0u)
      << trailing_comma;
  const std::string truncated = message_of("{\"models\": [\n");
  EXPECT_NE(truncated.find(": line 2, column 1: malformed JSON: "), std::string::npos) << truncated;
  // A literal too large for a double: nlohmann gives no position, the reader finds it.
  const std::string huge = message_of("{\"models\": [\n  {\"path\": \"a.ply\", \"scale\": 1e999}]}");
  EXPECT_NE(huge.find(": line 2, column 30: the number 1e999 is too large"), std::string::npos) << huge;
  const std::string missing = message_of("");
  EXPECT_NE(missing.find("malformed JSON"), std::string::npos) << missing;
  EXPECT_THROW(load_scene_description(dir / "absent.json"), SceneError);
}

TEST(SceneDescription, RelativePathsResolveAgainstTheSceneFile) {
  const fs::path dir = temp_dir() / "nested";
  fs::create_directories(dir / "models");
  fs::copy_file(bundled_sh3(), dir / "models" / "a.ply", fs::copy_options::overwrite_existing);
  fs::copy_file(bundled_sh3_cameras(), temp_dir() / "cams.json", fs::copy_options::overwrite_existing);
  const fs::path file =
      write_text(dir / "scene.json", R"({"models": [{"path": "models/a.ply"}], "cameras": "../cams.json"})");
  const SceneDescription d = load_scene_description(file);
  EXPECT_EQ(d.models[0].path, dir / "models" / "a.ply");
  EXPECT_EQ(d.cameras_file, temp_dir() / "cams.json");
  const GaussianScene scene = load_described_scene(d);
  EXPECT_EQ(scene.size(), load_scene(bundled_sh3()).size());
}

TEST(SceneDescription, ShDegreeEffectDropsTheBandsItNeverEvaluates) {
  const fs::path dir = temp_dir() / "sh_cap";
  fs::create_directories(dir);
  const std::string model = R"("models": [{"path": ")" + bundled_sh3().string() + R"("}])";
  const GaussianScene full = load_described_scene(load_scene_description(write_text(dir / "full.json", "{" + model + "}")));
  const GaussianScene capped = load_described_scene(
      load_scene_description(write_text(dir / "capped.json", "{" + model + R"(, "effects": {"sh_degree": 1}})")));
  ASSERT_EQ(full.sh_degree, 3);
  EXPECT_EQ(capped.sh_degree, 1);
  EXPECT_EQ(capped.sh.size(), full.size() * 4 * 3);  // 4 of 16 coefficients per splat held
  EXPECT_EQ(capped.sh, with_sh_degree(full, 1).sh);
  EXPECT_EQ(capped.positions, full.positions);
}

TEST(SceneDescription, LoadErrorsNameTheDescriptionAndTheModel) {
  const fs::path dir = temp_dir();
  std::string truncated;
  {
    std::ifstream in(bundled_sh3(), std::ios::binary);
    truncated.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  write_text(dir / "truncated.ply", truncated.substr(0, truncated.size() / 2));
  const fs::path file = write_text(dir / "scene.json", R"({"models": [{"path": ")" + bundled_sh3().string() +
                                                           R"("}, {"path": "truncated.ply"}]})");
  try {
    load_described_scene(load_scene_description(file));
    FAIL() << "no error";
  } catch (const SceneError& error) {
    const std::string message = error.what();
    EXPECT_EQ(message.rfind(file.string() + ": models[1]: ", 0), 0u) << message;
    EXPECT_NE(message.find("truncated.ply"), std::string::npos) << message;
  }
}

// ---------------------------------------------------------------------------------------------
// Transforms

TEST(Transform, IdentityIsBitIdentical) {
  for (const fs::path& path : {bundled_sh3(), bundled_playbot()}) {
    const GaussianScene scene = load_scene(path);
    expect_bit_identical(transform_scene(scene, ModelTransform{}), scene);
    // A rotation of exactly nothing leaves rotations, SH and normals alone too.
    ModelTransform translate_only;
    translate_only.translation = {0.5, -2, 3};
    const GaussianScene moved = transform_scene(scene, translate_only);
    EXPECT_TRUE(same_bits(moved.rotations, scene.rotations));
    EXPECT_TRUE(same_bits(moved.sh, scene.sh));
    EXPECT_TRUE(same_bits(moved.log_scales, scene.log_scales));
    EXPECT_EQ(moved.positions[1], float(double(scene.positions[1]) - 2));
  }
}

TEST(Transform, ShRotationIsExactForRandomCoefficientsRotationsAndDirections) {
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> uniform(-1, 1);
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    std::array<float, 48> coefficients{};
    for (float& c : coefficients) c = float(uniform(rng));
    const Matrix3 r = rotation_matrix(random_rotation(rng));
    std::array<float, 48> rotated = coefficients;
    ShRotation(r).apply(3, rotated.data());
    for (int sample = 0; sample < 100; ++sample) {
      const Vec3 d = random_direction(rng);
      const auto before = eval_sh(3, coefficients.data(), d);
      const auto after = eval_sh(3, rotated.data(), times(r, d));
      // Relative to the coefficients' size: the function itself may pass through zero.
      double scale = 0;
      for (float c : coefficients) scale = std::max(scale, double(std::abs(c)));
      for (size_t c = 0; c < 3; ++c) worst = std::max(worst, std::abs(after[c] - before[c]) / scale);
    }
  }
  std::printf("[ info ] SH rotation: worst |eval_sh(c', R d) - eval_sh(c, d)| / max|c| = %.3g\n", worst);
  EXPECT_LE(worst, 1e-5);
}

TEST(Transform, ShRotationBandsAreOrthogonalAndCompose) {
  std::mt19937_64 rng(7);
  const Matrix3 a = rotation_matrix(random_rotation(rng));
  const Matrix3 b = rotation_matrix(random_rotation(rng));
  const ShRotation ra(a), rb(b), rab(multiply(a, b)), identity(Matrix3{1, 0, 0, 0, 1, 0, 0, 0, 1});
  for (int l = 1; l <= 3; ++l) {
    const size_t n = size_t(2 * l + 1);
    const auto m = ra.band(l);
    ASSERT_EQ(m.size(), n * n);
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) {
        double dot = 0, composed = 0;
        for (size_t k = 0; k < n; ++k) {
          dot += m[i * n + k] * m[j * n + k];
          composed += m[i * n + k] * rb.band(l)[k * n + j];
        }
        EXPECT_NEAR(dot, i == j ? 1.0 : 0.0, 1e-12) << "band " << l;
        EXPECT_NEAR(composed, rab.band(l)[i * n + j], 1e-12) << "band " << l;
        EXPECT_NEAR(identity.band(l)[i * n + j], i == j ? 1.0 : 0.0, 1e-13) << "band " << l;
      }
  }
}

TEST(Transform, NonUniformScaleIsRejectedWithTheReason) {
  const GaussianScene scene = load_scene(bundled_sh3());
  ModelTransform stretched;
  stretched.scale = {1, 2, 1};
  try {
    transform_scene(scene, stretched);
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("non-uniform scale (1, 2, 1)"), std::string::npos) << message;
    EXPECT_NE(message.find("spherical harmonics"), std::string::npos) << message;
  }
  ModelTransform not_unit;
  not_unit.rotation = {1, 1, 0, 0};
  EXPECT_THROW(transform_scene(scene, not_unit), std::invalid_argument);
  ModelTransform negative;
  negative.scale = {-1, -1, -1};
  EXPECT_THROW(transform_scene(scene, negative), std::invalid_argument);
}

TEST(Transform, EulerAnglesAndZUpAreTheDocumentedRotations) {
  const Vec3 degrees = {25, -40, 70};
  const Matrix3 expected = euler_matrix_deg(degrees);
  const Matrix3 actual = rotation_matrix(quaternion_from_euler_xyz_deg(degrees));
  for (size_t i = 0; i < 9; ++i) EXPECT_NEAR(actual[i], expected[i], 1e-15);
  // z_up: (x, y, z) -> (x, -z, y): the capture's +Z up becomes the engine's -Y up.
  GaussianScene point;
  point.positions = {1, 2, 3};
  point.log_scales = {0, 0, 0};
  point.rotations = {1, 0, 0, 0};
  point.opacity_logits = {0};
  point.sh = {0, 0, 0};
  ModelTransform z_up;
  z_up.z_up = true;
  const GaussianScene moved = transform_scene(point, z_up);
  EXPECT_NEAR(moved.positions[0], 1, 1e-6);
  EXPECT_NEAR(moved.positions[1], -3, 1e-6);
  EXPECT_NEAR(moved.positions[2], 2, 1e-6);
}

struct InvarianceResult {
  double psnr_db = 0;                   // moved scene and camera against the original
  double psnr_without_sh_rotation = 0;  // the same with the SH left unrotated: what the rotation is worth
  double depth_ratio = 0;               // mean depth of the moved render over the original's
};

InvarianceResult reference_invariance(const GaussianScene& scene, const Camera& camera, const ModelTransform& t) {
  const RenderImage original = render_reference(scene, camera);
  const GaussianScene moved = transform_scene(scene, t);
  const Camera moved_camera = transform_camera(camera, t);
  const RenderImage image = render_reference(moved, moved_camera);
  GaussianScene unrotated_sh = moved;
  unrotated_sh.sh = scene.sh;
  InvarianceResult result;
  result.psnr_db = compare_images(image, original).psnr_db;
  result.psnr_without_sh_rotation = compare_images(render_reference(unrotated_sh, moved_camera), original).psnr_db;
  double sum = 0, sum_original = 0;
  for (size_t i = 0; i < image.depth.size(); ++i) {
    sum += image.depth[i];
    sum_original += original.depth[i];
  }
  result.depth_ratio = sum / sum_original;
  return result;
}

TEST(Transform, RigidMotionAndUniformScaleLeaveTheReferenceImageUnchanged) {
  ModelTransform t;
  t.translation = {0.7, -1.3, 2.1};
  t.rotation = quaternion_from_euler_xyz_deg({25, -40, 70});
  t.scale = {1.8, 1.8, 1.8};
  struct Case {
    const char* name;
    fs::path scene, cameras;
  };
  for (const Case& c : {Case{"playcanvas_test_64_sh3", bundled_sh3(), bundled_sh3_cameras()},
                        Case{"playbot_lod3_31000_sh2", bundled_playbot(), bundled_playbot_cameras()}}) {
    const GaussianScene scene = load_scene(c.scene);
    for (const size_t view : {size_t(0), size_t(3)}) {
      const InvarianceResult r = reference_invariance(scene, view_of(c.cameras, view), t);
      std::printf("[ info ] %s view %zu: moved scene and camera vs original %.2f dB; with SH unrotated %.2f dB; "
                  "depth ratio %.6f\n",
                  c.name, view, r.psnr_db, r.psnr_without_sh_rotation, r.depth_ratio);
      EXPECT_GE(r.psnr_db, kInvarianceMinPsnrDb) << c.name << " view " << view;
      // The SH rotation is what the bound measures: without it the view-dependent colour is wrong.
      EXPECT_LE(r.psnr_without_sh_rotation, r.psnr_db - 10) << c.name << " view " << view;
      EXPECT_NEAR(r.depth_ratio, 1.8, 1e-4) << c.name << " view " << view;
    }
  }
}

TEST(Transform, ZUpCaptureLoadedWithZUpRendersLikeTheOriginal) {
  const GaussianScene original = load_scene(bundled_playbot());
  // The capture as a Z-up tool would have written it: the inverse of z_up's rotation.
  ModelTransform to_z_up;
  const Quaternion q = z_up_rotation();
  to_z_up.rotation = {q[0], -q[1], -q[2], -q[3]};
  const GaussianScene z_up_capture = transform_scene(original, to_z_up);
  for (size_t i = 0; i < 10; ++i) EXPECT_NEAR(z_up_capture.positions[3 * i + 2], -original.positions[3 * i + 1], 1e-6);
  const fs::path dir = temp_dir();
  write_ply(dir / "z_up.ply", z_up_capture);
  const fs::path file = write_text(dir / "scene.json", R"({"models": [{"path": "z_up.ply", "z_up": true}]})");
  const GaussianScene loaded = load_described_scene(load_scene_description(file));

  for (const size_t view : {size_t(0), size_t(5)}) {
    const Camera camera = view_of(bundled_playbot_cameras(), view);
    const double psnr = compare_images(render_reference(loaded, camera), render_reference(original, camera)).psnr_db;
    std::printf("[ info ] z_up capture loaded with z_up vs original, view %zu: %.2f dB\n", view, psnr);
    EXPECT_GE(psnr, kInvarianceMinPsnrDb);
  }
}

TEST(Transform, MergePadsShDegrees) {
  const GaussianScene sh3 = load_scene(bundled_sh3());
  const GaussianScene sh2 = load_scene(bundled_playbot());
  const std::vector<GaussianScene> parts = {sh2, sh3};
  const GaussianScene merged = merge_scenes(parts);
  EXPECT_EQ(merged.sh_degree, 3);
  ASSERT_EQ(merged.size(), sh2.size() + sh3.size());
  ASSERT_EQ(merged.sh.size(), merged.size() * 16 * 3);
  for (size_t i = 0; i < sh2.size(); i += 997)
    for (size_t k = 0; k < 16; ++k)
      for (size_t c = 0; c < 3; ++c)
        EXPECT_EQ(merged.sh[(i * 16 + k) * 3 + c], k < 9 ? sh2.sh[(i * 9 + k) * 3 + c] : 0.0f);
  for (size_t i = 0; i < sh3.size(); ++i)
    for (size_t v = 0; v < 48; ++v) EXPECT_EQ(merged.sh[(sh2.size() + i) * 48 + v], sh3.sh[i * 48 + v]);
  EXPECT_EQ(merged.positions[3 * sh2.size()], sh3.positions[0]);
  EXPECT_EQ(merged.has_normals(), sh2.has_normals() || sh3.has_normals());

  // Zero coefficients add exact zeros: the padded scene renders bit-identically.
  const Camera camera = view_of(bundled_playbot_cameras(), 2);
  const RenderImage padded = render_reference(with_sh_degree(sh2, 3), camera);
  const RenderImage plain = render_reference(sh2, camera);
  EXPECT_EQ(padded.rgba, plain.rgba);
  EXPECT_EQ(with_sh_degree(sh3, 1).sh.size(), sh3.size() * 4 * 3);
}

TEST(Transform, ComposedDescriptionRendersLikeTheSceneMovedByHand) {
  const GaussianScene playbot = load_scene(bundled_playbot());
  const GaussianScene small = load_scene(bundled_sh3());
  const Bounds big_bounds = compute_bounds(playbot);
  const Bounds small_bounds = compute_bounds(small);

  // The SH3 scene, scaled to a third of the playbot, sits beside it; the playbot itself turns.
  const Vec3 degrees_a = {0, 35, 0};
  const Vec3 degrees_b = {-30, 60, 15};
  const double scale_b = big_bounds.radius / (3 * small_bounds.radius);
  const Matrix3 r_a = euler_matrix_deg(degrees_a);
  const Matrix3 r_b = euler_matrix_deg(degrees_b);
  const Vec3 t_a = {0.1, 0, -0.2};
  const Vec3 rotated_centre = times(r_b, {small_bounds.center[0], small_bounds.center[1], small_bounds.center[2]});
  Vec3 t_b{};
  for (size_t a = 0; a < 3; ++a)
    t_b[a] = big_bounds.center[a] + (a == 0 ? 0.8 * big_bounds.radius : 0) - scale_b * rotated_centre[a];

  const fs::path dir = temp_dir();
  const fs::path file = write_text(
      dir / "composed.json",
      R"({"models": [{"path": ")" + bundled_playbot().string() + R"(", "translation": )" + json_vector(t_a) +
          R"(, "rotation_deg": )" + json_vector(degrees_a) + R"(},
                     {"path": ")" + bundled_sh3().string() + R"(", "translation": )" + json_vector(t_b) +
          R"(, "rotation_deg": )" + json_vector(degrees_b) + R"(, "scale": )" + number(scale_b) + "}]}");
  LoadReport report;
  const GaussianScene described = load_described_scene(load_scene_description(file), {}, &report);
  EXPECT_EQ(report.gaussians_in_file, playbot.size() + small.size());
  EXPECT_EQ(described.sh_degree, 3);

  OrbitParams orbit;
  orbit.azimuth_deg = 40;
  for (const double azimuth : {40.0, 200.0}) {
    orbit.azimuth_deg = azimuth;
    const Camera camera = orbit_camera(described, kWidth, kHeight, orbit);
    GaussianScene by_hand;
    append_scene(by_hand, move_and_bake(playbot, r_a, 1.0, t_a, camera));
    append_scene(by_hand, move_and_bake(small, r_b, scale_b, t_b, camera));

    const double reference_psnr =
        compare_images(render_reference(described, camera), render_reference(by_hand, camera)).psnr_db;
    const double gpu_psnr = compare_images(render_gpu(described, camera), render_gpu(by_hand, camera)).psnr_db;
    std::printf("[ info ] composed description vs moved by hand, azimuth %.0f: reference %.2f dB, GPU %.2f dB\n",
                azimuth, reference_psnr, gpu_psnr);
    EXPECT_GE(reference_psnr, kInvarianceMinPsnrDb);
    EXPECT_GE(gpu_psnr, kGpuMinPsnrDb);
  }
}

}  // namespace
