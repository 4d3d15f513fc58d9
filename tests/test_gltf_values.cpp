// The glTF reader's values on files this test writes from the KHR_gaussian_splatting and glTF 2.0
// specifications: normalized integer attributes (int8 and int16 rotations, uint8 and uint16 opacities),
// an interleaved bufferView with byteStride, the same scene as .glb, as .gltf with a base64 data: URI
// and as .gltf with an external .bin, and node transforms (TRS under a parent matrix) that move,
// rotate and scale the Gaussians and rotate their degree-1 SH. Every expected value is computed here
// from the formulas, not by the library: glTF's axes turned 180 degrees about z into the trainer's,
// quaternions and SH through rotation matrices.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "process_support.h"
#include "test_math.h"
#include "test_support.h"
#include "tilesplat/scene.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using tilesplat::testing::math::Matrix3;
using tilesplat::testing::math::multiply;
using Vector3 = tilesplat::testing::math::Vec3;
constexpr auto transform = tilesplat::testing::math::times;
constexpr auto rotation_of = tilesplat::testing::math::quaternion_matrix;

constexpr size_t kCount = 3;
// The file's values, glTF axes (y up). Rotations as x y z w.
constexpr double kPositions[kCount][3] = {{0.25, -0.5, 1.0}, {-1.5, 0.75, 2.0}, {0.0, 0.125, -0.625}};
constexpr double kScales[kCount][3] = {{0.05, 0.1, 0.2}, {0.3, 0.02, 0.07}, {0.01, 0.01, 0.04}};
constexpr int16_t kRotationsI16[kCount][4] = {
    {0, 0, 0, 32767}, {16384, -8192, 4096, 30000}, {-32768, 0, 0, 0}};
constexpr int8_t kRotationsI8[kCount][4] = {{0, 0, 0, 127}, {64, -32, 16, 117}, {-128, 0, 0, 0}};
constexpr uint8_t kOpacitiesU8[kCount] = {128, 200, 13};
constexpr uint16_t kOpacitiesU16[kCount] = {32768, 51400, 3341};
constexpr double kShDc[kCount][3] = {{0.5, -0.25, 1.0}, {-1.0, 0.0, 0.75}, {2.0, 1.5, -0.5}};
constexpr double kSh1[kCount][3][3] = {  // [gaussian][coefficient 0..2][rgb]
    {{0.1, 0.2, 0.3}, {-0.4, 0.5, -0.6}, {0.7, -0.8, 0.9}},
    {{0.05, 0.0, -0.05}, {0.25, 0.35, 0.45}, {-0.15, 0.6, 0.2}},
    {{-0.3, 0.3, 0.0}, {0.0, -0.2, 0.1}, {0.4, 0.0, -0.4}}};

template <typename T>
void append(std::vector<uint8_t>& bytes, T value) {
  const size_t at = bytes.size();
  bytes.resize(at + sizeof(T));
  std::memcpy(bytes.data() + at, &value, sizeof(T));
}
void align4(std::vector<uint8_t>& bytes) {
  while (bytes.size() % 4) bytes.push_back(0);
}

struct Encoding {
  bool rotation_i8 = false;  // int8 normalized, else int16 normalized
  bool opacity_u16 = false;  // uint16 normalized, else uint8 normalized
};

// The buffer and the glTF JSON (its buffers[0] without a uri: the caller says where the bytes go).
std::pair<json, std::vector<uint8_t>> make_gltf(const Encoding& encoding, const json& nodes) {
  std::vector<uint8_t> bin;
  json views = json::array(), accessors = json::array();
  auto add_view = [&](size_t offset, size_t length, std::optional<size_t> stride) {
    json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", length}};
    if (stride) view["byteStride"] = *stride;
    views.push_back(view);
    return views.size() - 1;
  };
  auto add_accessor = [&](size_t view, size_t offset, int component_type, const char* type, bool normalized) {
    json accessor = {{"bufferView", view},
                     {"byteOffset", offset},
                     {"componentType", component_type},
                     {"count", kCount},
                     {"type", type}};
    if (normalized) accessor["normalized"] = true;
    accessors.push_back(accessor);
    return accessors.size() - 1;
  };
  // POSITION and SCALE interleaved: 24 bytes an element.
  const size_t interleaved = bin.size();
  for (size_t e = 0; e < kCount; ++e) {
    for (double v : kPositions[e]) append(bin, float(v));
    for (double v : kScales[e]) append(bin, float(v));
  }
  const size_t interleaved_view = add_view(interleaved, bin.size() - interleaved, 24);
  json attributes = {
      {"POSITION", add_accessor(interleaved_view, 0, 5126, "VEC3", false)},
      {"KHR_gaussian_splatting:SCALE", add_accessor(interleaved_view, 12, 5126, "VEC3", false)}};
  const size_t rotations = bin.size();
  for (size_t e = 0; e < kCount; ++e)
    for (size_t c = 0; c < 4; ++c)
      encoding.rotation_i8 ? append(bin, kRotationsI8[e][c]) : append(bin, kRotationsI16[e][c]);
  attributes["KHR_gaussian_splatting:ROTATION"] =
      add_accessor(add_view(rotations, bin.size() - rotations, std::nullopt), 0,
                   encoding.rotation_i8 ? 5120 : 5122, "VEC4", true);
  align4(bin);
  const size_t opacities = bin.size();
  for (size_t e = 0; e < kCount; ++e)
    encoding.opacity_u16 ? append(bin, kOpacitiesU16[e]) : append(bin, kOpacitiesU8[e]);
  attributes["KHR_gaussian_splatting:OPACITY"] =
      add_accessor(add_view(opacities, bin.size() - opacities, std::nullopt), 0,
                   encoding.opacity_u16 ? 5123 : 5121, "SCALAR", true);
  align4(bin);
  auto add_sh = [&](const std::string& semantic, auto&& value_of) {
    const size_t start = bin.size();
    for (size_t e = 0; e < kCount; ++e)
      for (size_t c = 0; c < 3; ++c) append(bin, float(value_of(e, c)));
    attributes[semantic] =
        add_accessor(add_view(start, bin.size() - start, std::nullopt), 0, 5126, "VEC3", false);
  };
  add_sh("KHR_gaussian_splatting:SH_DEGREE_0_COEF_0", [](size_t e, size_t c) { return kShDc[e][c]; });
  for (size_t n = 0; n < 3; ++n)
    add_sh("KHR_gaussian_splatting:SH_DEGREE_1_COEF_" + std::to_string(n),
           [n](size_t e, size_t c) { return kSh1[e][n][c]; });

  json gltf = {{"asset", {{"version", "2.0"}}},
               {"extensionsUsed", {"KHR_gaussian_splatting"}},
               {"buffers", {{{"byteLength", bin.size()}}}},
               {"bufferViews", views},
               {"accessors", accessors},
               {"meshes",
                {{{"primitives",
                   {{{"mode", 0},
                     {"attributes", attributes},
                     {"extensions", {{"KHR_gaussian_splatting", {{"kernel", "ellipse"}}}}}}}}}}},
               {"nodes", nodes},
               {"scenes", {{{"nodes", {0}}}}},
               {"scene", 0}};
  return {gltf, bin};
}

void write_glb(const fs::path& path, const json& gltf, const std::vector<uint8_t>& bin) {
  std::ofstream(path, std::ios::binary) << tilesplat::testing::glb_bytes(gltf.dump(), std::string(bin.begin(), bin.end()));
}

std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string text;
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t n = uint32_t(bytes[i]) << 16 | uint32_t(bytes[i + 1]) << 8 | bytes[i + 2];
    for (int shift : {18, 12, 6, 0}) text += kAlphabet[(n >> shift) & 63];
  }
  if (i + 1 == bytes.size()) {
    const uint32_t n = uint32_t(bytes[i]) << 16;
    text += kAlphabet[(n >> 18) & 63];
    text += kAlphabet[(n >> 12) & 63];
    text += "==";
  } else if (i + 2 == bytes.size()) {
    const uint32_t n = uint32_t(bytes[i]) << 16 | uint32_t(bytes[i + 1]) << 8;
    for (int shift : {18, 12, 6}) text += kAlphabet[(n >> shift) & 63];
    text += '=';
  }
  return text;
}

// glTF (y up) to the trainer's frame: 180 degrees about z.
constexpr Matrix3 kFlip = {-1, 0, 0, 0, -1, 0, 0, 0, 1};

// The node transform the expected values apply: world = rotation * scale, then translation.
struct Placement {
  Matrix3 rotation = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  double scale = 1;
  Vector3 translation = {0, 0, 0};
};

double normalized_rotation(const Encoding& encoding, size_t e, size_t c) {
  return encoding.rotation_i8 ? std::max(kRotationsI8[e][c] / 127.0, -1.0)
                              : std::max(kRotationsI16[e][c] / 32767.0, -1.0);
}

void expect_scene(const tilesplat::GaussianScene& scene, const Encoding& encoding,
                  const Placement& placement) {
  ASSERT_EQ(scene.size(), kCount);
  ASSERT_EQ(scene.sh_degree, 1);
  const Matrix3 to_engine = multiply(kFlip, placement.rotation);
  for (size_t e = 0; e < kCount; ++e) {
    SCOPED_TRACE("Gaussian " + std::to_string(e));
    Vector3 p = transform(placement.rotation, {kPositions[e][0], kPositions[e][1], kPositions[e][2]});
    for (size_t a = 0; a < 3; ++a) p[a] = placement.scale * p[a] + placement.translation[a];
    p = transform(kFlip, p);
    for (size_t a = 0; a < 3; ++a) {
      EXPECT_NEAR(scene.positions[3 * e + a], p[a], 1e-6) << "position " << a;
      EXPECT_NEAR(scene.log_scales[3 * e + a], std::log(float(kScales[e][a]) * placement.scale), 1e-6) << a;
    }
    // Rotations as matrices (a quaternion's sign is free): the file's, then the node's, then the flip.
    const double x = normalized_rotation(encoding, e, 0), y = normalized_rotation(encoding, e, 1),
                 z = normalized_rotation(encoding, e, 2), w = normalized_rotation(encoding, e, 3);
    const Matrix3 expected = multiply(to_engine, rotation_of(w, x, y, z));
    const float* q = scene.rotations.data() + 4 * e;
    const Matrix3 actual = rotation_of(q[0], q[1], q[2], q[3]);
    for (size_t k = 0; k < 9; ++k) EXPECT_NEAR(actual[k], expected[k], 1e-6) << "rotation " << k;
    const double opacity = encoding.opacity_u16 ? kOpacitiesU16[e] / 65535.0 : kOpacitiesU8[e] / 255.0;
    EXPECT_NEAR(scene.opacity_logits[e], std::log(opacity / (1 - opacity)), 1e-5);
    // SH: the DC term as it is; degree 1 is C1 (v . d) with v = (-sh3, -sh1, sh2), so it turns as v' = R v.
    const size_t stride = 3 * 4;
    for (size_t c = 0; c < 3; ++c) {
      EXPECT_NEAR(scene.sh[stride * e + c], kShDc[e][c], 1e-7) << "DC " << c;
      const Vector3 v = transform(to_engine, {-kSh1[e][2][c], -kSh1[e][0][c], kSh1[e][1][c]});
      EXPECT_NEAR(scene.sh[stride * e + 3 + c], -v[1], 1e-6) << "SH 1 colour " << c;
      EXPECT_NEAR(scene.sh[stride * e + 6 + c], v[2], 1e-6) << "SH 2 colour " << c;
      EXPECT_NEAR(scene.sh[stride * e + 9 + c], -v[0], 1e-6) << "SH 3 colour " << c;
    }
  }
}

fs::path out_dir() {
  return tilesplat::testing::fresh_output_dir();
}

TEST(GltfValues, NormalizedIntegersAndAnInterleavedStrideReadAsTheSpecSays) {
  const fs::path out = out_dir();
  for (const Encoding encoding : {Encoding{false, false}, Encoding{true, true}}) {
    SCOPED_TRACE(encoding.rotation_i8 ? "int8 rotations, uint16 opacities"
                                      : "int16 rotations, uint8 opacities");
    const auto [gltf, bin] = make_gltf(encoding, json::array({json{{"mesh", 0}}}));
    write_glb(out / "plain.glb", gltf, bin);
    expect_scene(tilesplat::load_scene(out / "plain.glb"), encoding, {});
  }
}

TEST(GltfValues, GltfWithDataUriAndWithExternalBufferReadAsTheGlb) {
  const fs::path out = out_dir();
  const Encoding encoding;
  auto [gltf, bin] = make_gltf(encoding, json::array({json{{"mesh", 0}}}));
  write_glb(out / "scene.glb", gltf, bin);
  EXPECT_EQ(base64({'M', 'a', 'n'}), "TWFu");  // RFC 4648's examples, so that the encoder is right
  EXPECT_EQ(base64({'M', 'a'}), "TWE=");
  EXPECT_EQ(base64({'M'}), "TQ==");

  json embedded = gltf;
  embedded["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64(bin);
  std::ofstream(out / "embedded.gltf") << embedded.dump(2);
  json external = gltf;
  external["buffers"][0]["uri"] = "scene%20data.bin";  // a space, percent-encoded as URIs have it
  std::ofstream(out / "scene data.bin", std::ios::binary)
      .write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size()));
  std::ofstream(out / "external.gltf") << external.dump(2);

  const tilesplat::GaussianScene glb = tilesplat::load_scene(out / "scene.glb");
  expect_scene(glb, encoding, {});
  for (const char* name : {"embedded.gltf", "external.gltf"}) {
    SCOPED_TRACE(name);
    tilesplat::LoadReport report;
    const tilesplat::GaussianScene scene = tilesplat::load_scene(out / name, {}, &report);
    EXPECT_EQ(report.format, "gltf");
    EXPECT_EQ(scene.positions, glb.positions);
    EXPECT_EQ(scene.log_scales, glb.log_scales);
    EXPECT_EQ(scene.rotations, glb.rotations);
    EXPECT_EQ(scene.opacity_logits, glb.opacity_logits);
    EXPECT_EQ(scene.sh, glb.sh);
  }
  // Without its .bin the external one names the file it misses.
  fs::remove(out / "scene data.bin");
  EXPECT_NE(tilesplat::testing::error_of([&] {
              tilesplat::load_scene(out / "external.gltf");
            }).find("scene data.bin"),
            std::string::npos);
}

TEST(GltfValues, NodeTransformsMoveRotateScaleAndTurnTheSh) {
  const fs::path out = out_dir();
  const Encoding encoding;
  // A parent node with a matrix (a translation) and a child with TRS: rotation 50 degrees about the
  // axis (1, 2, 2) / 3, uniform scale 2, translation (0.5, -1, 3).
  const double angle = 50.0 * 3.14159265358979323846 / 180.0;
  const double s = std::sin(angle / 2), c = std::cos(angle / 2);
  const std::array<double, 4> q = {s / 3, 2 * s / 3, 2 * s / 3, c};  // x y z w
  json parent_matrix = json::array({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -0.25, 0.5, 0.125, 1});
  json nodes = json::array(
      {json{{"matrix", parent_matrix}, {"children", {1}}}, json{{"mesh", 0},
                                                                {"rotation", {q[0], q[1], q[2], q[3]}},
                                                                {"scale", {2, 2, 2}},
                                                                {"translation", {0.5, -1, 3}}}});
  const auto [gltf, bin] = make_gltf(encoding, nodes);
  write_glb(out / "placed.glb", gltf, bin);
  Placement placement;
  placement.rotation = rotation_of(q[3], q[0], q[1], q[2]);
  placement.scale = 2;
  placement.translation = {0.5 - 0.25, -1 + 0.5, 3 + 0.125};
  expect_scene(tilesplat::load_scene(out / "placed.glb"), encoding, placement);
}

}  // namespace
