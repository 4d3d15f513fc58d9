// Tests of the PLY loader, load_scene's dispatch, load reports and scene bounds.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "test_support.h"
#include "tilesplat/mapped_ply.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

// ---------------------------------------------------------------------------------------------
// A small PLY writer, independent of the loader, for hand-made files.

enum class Encoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

const char* format_name(Encoding encoding) {
  switch (encoding) {
    case Encoding::kAscii:
      return "ascii";
    case Encoding::kBinaryLittleEndian:
      return "binary_little_endian";
    case Encoding::kBinaryBigEndian:
      return "binary_big_endian";
  }
  return "";
}

constexpr std::array<Encoding, 3> kAllEncodings = {Encoding::kBinaryLittleEndian, Encoding::kBinaryBigEndian,
                                                   Encoding::kAscii};

struct TestProperty {
  std::string type;  // a PLY type name; the item type for a list
  std::string name;
  std::string list_count_type = {};  // non-empty for a list property
};

using Cell = std::vector<double>;  // one value, or the items of a list
struct TestElement {
  std::string name;
  std::vector<TestProperty> properties;
  std::vector<std::vector<Cell>> rows;
};

bool is_float_type(const std::string& type) {
  return type == "float" || type == "float32" || type == "double" || type == "float64";
}

template <typename T>
void append_bytes(std::string& out, T value, bool big_endian) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (big_endian) std::reverse(bytes, bytes + sizeof(T));
  out.append(bytes, sizeof(T));
}

void append_value(std::string& out, const std::string& type, double value, Encoding encoding) {
  if (encoding == Encoding::kAscii) {
    char buffer[64];
    const auto result = is_float_type(type)
                            ? std::to_chars(buffer, buffer + sizeof(buffer), value)
                            : std::to_chars(buffer, buffer + sizeof(buffer), static_cast<long long>(value));
    out.append(buffer, result.ptr);
    return;
  }
  const bool big = encoding == Encoding::kBinaryBigEndian;
  if (type == "char" || type == "int8") return append_bytes(out, static_cast<int8_t>(value), big);
  if (type == "uchar" || type == "uint8") return append_bytes(out, static_cast<uint8_t>(value), big);
  if (type == "short" || type == "int16") return append_bytes(out, static_cast<int16_t>(value), big);
  if (type == "ushort" || type == "uint16") return append_bytes(out, static_cast<uint16_t>(value), big);
  if (type == "int" || type == "int32") return append_bytes(out, static_cast<int32_t>(value), big);
  if (type == "uint" || type == "uint32") return append_bytes(out, static_cast<uint32_t>(value), big);
  if (type == "float" || type == "float32") return append_bytes(out, static_cast<float>(value), big);
  if (type == "double" || type == "float64") return append_bytes(out, value, big);
  ADD_FAILURE() << "test writer: unknown type " << type;
}

std::string encode_header(Encoding encoding, const std::vector<TestElement>& elements) {
  std::string header = "ply\nformat " + std::string(format_name(encoding)) +
                       " 1.0\ncomment written by test_ply_loader\nobj_info hand-made test scene\n";
  for (const TestElement& element : elements) {
    header += "element " + element.name + " " + std::to_string(element.rows.size()) + "\n";
    for (const TestProperty& property : element.properties) {
      if (property.list_count_type.empty()) {
        header += "property " + property.type + " " + property.name + "\n";
      } else {
        header +=
            "property list " + property.list_count_type + " " + property.type + " " + property.name + "\n";
      }
    }
  }
  return header + "end_header\n";
}

std::string encode_ply(Encoding encoding, const std::vector<TestElement>& elements) {
  std::string out = encode_header(encoding, elements);
  for (const TestElement& element : elements) {
    for (const std::vector<Cell>& row : element.rows) {
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const TestProperty& property = element.properties[p];
        const Cell& cell = row[p];
        if (!property.list_count_type.empty()) {
          if (encoding == Encoding::kAscii && p > 0) out += ' ';
          append_value(out, property.list_count_type, static_cast<double>(cell.size()), encoding);
          for (double item : cell) {
            if (encoding == Encoding::kAscii) out += ' ';
            append_value(out, property.type, item, encoding);
          }
          continue;
        }
        if (encoding == Encoding::kAscii && p > 0) out += ' ';
        append_value(out, property.type, cell.at(0), encoding);
      }
      if (encoding == Encoding::kAscii) out += '\n';
    }
  }
  return out;
}

std::filesystem::path write_file(const std::string& name, const std::string& bytes) {
  const std::filesystem::path path = testing::temp_dir() / name;
  // A fresh file rather than a truncated one: ext4 flushes a truncated-and-rewritten file on
  // close, which makes the thousands of rewrites below take seconds.
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  file.close();
  EXPECT_TRUE(file.good()) << "cannot write " << path;
  return path;
}

std::string replace_once(std::string text, std::string_view from, std::string_view to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test setup: '" << from << "' not found";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

size_t header_line_count(const std::string& ply) {
  const size_t end = ply.find("end_header\n");
  return static_cast<size_t>(std::count(ply.begin(), ply.begin() + static_cast<std::ptrdiff_t>(end), '\n')) +
         1;
}

// ---------------------------------------------------------------------------------------------
// A tiny scene with a distinct, exactly representable value in every slot.

constexpr size_t kTinyCount = 4;

int coefficients_of(int degree) {
  return (degree + 1) * (degree + 1);
}

float sh_value(size_t gaussian, size_t coefficient, size_t channel) {
  return static_cast<float>(1000 * gaussian + 10 * coefficient + channel) + 0.5f;
}

// Un-normalized on purpose: 2x identity, zero, a 5-norm quaternion and a general one.
std::array<double, 4> raw_rotation(size_t gaussian) {
  switch (gaussian % 4) {
    case 0:
      return {2, 0, 0, 0};
    case 1:
      return {0, 0, 0, 0};
    case 2:
      return {1, 2, 2, 4};
    default:
      return {2, -3, 6, 0};
  }
}

std::vector<std::string> trainer_property_names(int degree, bool normals) {
  std::vector<std::string> names = {"x", "y", "z"};
  if (normals) names.insert(names.end(), {"nx", "ny", "nz"});
  names.insert(names.end(), {"f_dc_0", "f_dc_1", "f_dc_2"});
  const int rest = 3 * (coefficients_of(degree) - 1);
  for (int r = 0; r < rest; ++r) names.push_back("f_rest_" + std::to_string(r));
  names.insert(names.end(), {"opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"});
  return names;
}

double tiny_value(size_t i, const std::string& name, int degree) {
  const double g = static_cast<double>(i);
  if (name == "x") return 1.5 + g;
  if (name == "y") return -2.25 * g;
  if (name == "z") return 0.125 + 3 * g;
  if (name == "nx") return 0.5 * g;
  if (name == "ny") return -0.75;
  if (name == "nz") return 4 + g;
  if (name == "opacity") return -1.5 + g;
  if (name == "confidence") return 7 + g;
  if (name.starts_with("f_dc_")) return sh_value(i, 0, static_cast<size_t>(std::stoi(name.substr(5))));
  if (name.starts_with("f_rest_")) {
    const size_t r = static_cast<size_t>(std::stoi(name.substr(7)));
    const size_t per_channel = static_cast<size_t>(coefficients_of(degree) - 1);
    return sh_value(i, r % per_channel + 1, r / per_channel);
  }
  if (name.starts_with("scale_")) return -3.0 + 0.5 * std::stoi(name.substr(6)) - 0.25 * g;
  if (name.starts_with("rot_")) return raw_rotation(i)[static_cast<size_t>(std::stoi(name.substr(4)))];
  ADD_FAILURE() << "no tiny value for " << name;
  return 0;
}

TestElement make_vertex_element(const std::vector<std::string>& names, size_t count, int degree) {
  TestElement vertex{"vertex", {}, {}};
  for (const std::string& name : names)
    vertex.properties.push_back({name == "confidence" ? "uchar" : "float", name});
  for (size_t i = 0; i < count; ++i) {
    std::vector<Cell> row;
    for (const std::string& name : names) row.push_back({tiny_value(i, name, degree)});
    vertex.rows.push_back(std::move(row));
  }
  return vertex;
}

// Shuffled properties, an ignored extra property, and extra elements before (with a list
// property) and after the vertex element.
std::vector<TestElement> tiny_scene_elements(int degree, bool normals = true) {
  std::vector<std::string> names = trainer_property_names(degree, normals);
  names.push_back("confidence");
  std::mt19937 random(1234u + static_cast<unsigned>(degree));
  std::shuffle(names.begin(), names.end(), random);

  TestElement faces{"face", {{"int", "vertex_indices", "uchar"}, {"ushort", "material"}}, {}};
  faces.rows = {{{0, 1, 2}, {7}}, {{}, {8}}, {{3, 2, 1, 0}, {9}}};
  TestElement camera{"camera", {{"float", "view_x"}, {"uchar", "flag"}, {"double", "focal"}}, {}};
  camera.rows = {{{1.25}, {1}, {500.5}}};
  return {faces, make_vertex_element(names, kTinyCount, degree), camera};
}

GaussianScene expected_tiny_scene(int degree, bool normals = true) {
  GaussianScene scene;
  scene.sh_degree = degree;
  const size_t k_count = static_cast<size_t>(coefficients_of(degree));
  for (size_t i = 0; i < kTinyCount; ++i) {
    for (const char* name : {"x", "y", "z"})
      scene.positions.push_back(static_cast<float>(tiny_value(i, name, degree)));
    if (normals)
      for (const char* name : {"nx", "ny", "nz"})
        scene.normals.push_back(static_cast<float>(tiny_value(i, name, degree)));
    for (const char* name : {"scale_0", "scale_1", "scale_2"})
      scene.log_scales.push_back(static_cast<float>(tiny_value(i, name, degree)));
    scene.opacity_logits.push_back(static_cast<float>(tiny_value(i, "opacity", degree)));
    for (size_t k = 0; k < k_count; ++k)
      for (size_t c = 0; c < 3; ++c) scene.sh.push_back(sh_value(i, k, c));
  }
  const std::array<std::array<float, 4>, 4> normalized = {{
      {1, 0, 0, 0},
      {1, 0, 0, 0},
      {0.2f, 0.4f, 0.4f, 0.8f},
      {static_cast<float>(2.0 / 7), static_cast<float>(-3.0 / 7), static_cast<float>(6.0 / 7), 0},
  }};  // |(2, -3, 6, 0)| = 7
  for (size_t i = 0; i < kTinyCount; ++i)
    scene.rotations.insert(scene.rotations.end(), normalized[i].begin(), normalized[i].end());
  return scene;
}

// How two scenes' rotations must agree: to a few float roundings (values normalized by hand against the
// reader's), or bit for bit (two readings of the same floats).
enum class Rotations { kNearly, kExactly };

void expect_same_scene(const GaussianScene& actual, const GaussianScene& expected, const std::string& label,
                       Rotations rotations = Rotations::kNearly) {
  SCOPED_TRACE(label);
  testing::expect_identical_scenes(actual, expected, rotations == Rotations::kExactly);
  if (rotations == Rotations::kExactly) return;
  ASSERT_EQ(actual.rotations.size(), expected.rotations.size());
  for (size_t i = 0; i < actual.rotations.size(); ++i)
    EXPECT_FLOAT_EQ(actual.rotations[i], expected.rotations[i]) << i;
}

void expect_unit_quaternions(const GaussianScene& scene) {
  size_t bad = 0;
  for (size_t i = 0; i < scene.size(); ++i) {
    const float* q = &scene.rotations[4 * i];
    const double norm =
        std::sqrt(double{q[0]} * q[0] + double{q[1]} * q[1] + double{q[2]} * q[2] + double{q[3]} * q[3]);
    if (std::abs(norm - 1.0) > 1e-5) ++bad;
  }
  EXPECT_EQ(bad, 0u) << "quaternions without unit norm";
}

void expect_sizes_consistent(const GaussianScene& scene) {
  const size_t n = scene.size();
  EXPECT_EQ(scene.positions.size(), 3 * n);
  EXPECT_EQ(scene.log_scales.size(), 3 * n);
  EXPECT_EQ(scene.rotations.size(), 4 * n);
  EXPECT_EQ(scene.sh.size(), 3 * static_cast<size_t>(scene.sh_coefficients()) * n);
  if (scene.has_normals()) {
    EXPECT_EQ(scene.normals.size(), 3 * n);
  }
}

// Reads `path` with `read` and expects a SceneError whose message starts with the path and holds every
// phrase.
template <typename Read>
void expect_read_error(const std::filesystem::path& path, std::initializer_list<std::string_view> phrases,
                       Read read) {
  std::string message;
  try {
    read();
    ADD_FAILURE() << "read without an error: " << path;
    return;
  } catch (const SceneError& error) {
    message = error.what();
  }
  EXPECT_TRUE(message.starts_with(path.string())) << message;
  for (std::string_view phrase : phrases) EXPECT_NE(message.find(phrase), std::string::npos) << message;
}

// Loads and expects a SceneError whose message starts with the path and holds every phrase.
void expect_load_error(const std::filesystem::path& path, std::initializer_list<std::string_view> phrases,
                       const LoadOptions& options = {}) {
  expect_read_error(path, phrases, [&] { load_ply(path, options); });
}

// ---------------------------------------------------------------------------------------------
// Real scenes bundled with the repository.

TEST(PlyLoader, LoadsBundledPlaybot) {
  LoadReport report;
  const GaussianScene scene = load_ply(testing::bundled_playbot(), {}, &report);
  EXPECT_EQ(scene.size(), 31000u);
  EXPECT_EQ(scene.sh_degree, 2);
  EXPECT_TRUE(scene.has_normals());
  expect_sizes_consistent(scene);
  expect_unit_quaternions(scene);
  EXPECT_EQ(report.format, "ply binary_little_endian");
  EXPECT_EQ(report.gaussians_in_file, 31000u);
  EXPECT_EQ(report.dropped, 0u);
  EXPECT_TRUE(report.ignored_properties.empty());
  EXPECT_EQ(report.summary(), "");
}

// A file of more than one block of rows (the reader decodes 64 MiB of rows at a time and lets go of each
// block's pages): every Gaussian lands in its slot across the blocks' seams, the non-finite ones dropped
// with their indices in the file, and the file read from memory (parse_ply, no pages let go of) agrees.
TEST(PlyLoader, AFileOfManyBlocksLoadsEveryRowInOrder) {
  constexpr size_t kCount = 1300000;  // 14 floats a row: 72.8 MB, two blocks and a part
  constexpr size_t kFloats = 14;
  std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(kCount) + "\n";
  for (const char* name : {"x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1",
                           "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
    ply += std::string("property float ") + name + "\n";
  ply += "end_header\n";
  const size_t header = ply.size();
  ply.resize(header + kCount * kFloats * sizeof(float));
  const auto is_dropped = [](size_t i) { return i % 100003 == 7; };  // a NaN opacity in these
  for (size_t i = 0; i < kCount; ++i) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float row[kFloats] = {float(i), 0,  1,  0.1f, 0.2f, 0.3f, is_dropped(i) ? nan : 0.5f,
                                -3,       -3, -3, 1,    0,    0,    0};
    std::memcpy(ply.data() + header + i * sizeof(row), row, sizeof(row));
  }
  const std::filesystem::path path = write_file("many_blocks.ply", ply);
  LoadReport report;
  const GaussianScene scene = load_ply(path, {}, &report);
  size_t dropped = 0;
  for (size_t i = 0; i < kCount; ++i) dropped += is_dropped(i) ? 1 : 0;
  ASSERT_EQ(scene.size(), kCount - dropped);
  EXPECT_EQ(report.dropped, dropped);
  ASSERT_EQ(report.dropped_by_property.size(), 1u);
  EXPECT_EQ(report.dropped_by_property[0].first_index, 7u);
  size_t slot = 0;
  for (size_t i = 0; i < kCount; ++i) {
    if (is_dropped(i)) continue;
    ASSERT_EQ(scene.positions[3 * slot], float(i)) << "slot " << slot;
    ASSERT_EQ(scene.opacity_logits[slot], 0.5f) << "slot " << slot;
    ++slot;
  }
  const GaussianScene in_memory =
      parse_ply(std::as_bytes(std::span(ply.data(), ply.size())), "many_blocks.ply");
  EXPECT_EQ(in_memory.positions, scene.positions);
  EXPECT_EQ(in_memory.sh, scene.sh);
  // Read part by part, the dropped rows of every block are skipped as load_ply skips them.
  const MappedPly mapped = MappedPly::open(path);
  ASSERT_EQ(mapped.size(), scene.size());
  const GaussianScene from_parts = mapped.load();
  EXPECT_EQ(from_parts.positions, scene.positions);
  EXPECT_EQ(from_parts.opacity_logits, scene.opacity_logits);
  std::filesystem::remove(path);
}

TEST(PlyLoader, LoadsBundledSh3Scene) {
  const GaussianScene scene = load_ply(testing::bundled_sh3());
  EXPECT_EQ(scene.size(), 64u);
  EXPECT_EQ(scene.sh_degree, 3);
  EXPECT_EQ(scene.sh_coefficients(), 16);
  expect_sizes_consistent(scene);
  expect_unit_quaternions(scene);
}

TEST(PlyLoader, LoadSceneDispatchesPlyCaseInsensitively) {
  const std::filesystem::path upper = testing::temp_dir() / "SH3_COPY.PLY";
  std::filesystem::copy_file(testing::bundled_sh3(), upper,
                             std::filesystem::copy_options::overwrite_existing);
  EXPECT_EQ(load_scene(upper).size(), 64u);
  EXPECT_EQ(load_scene(testing::bundled_sh3()).size(), 64u);
}

// ---------------------------------------------------------------------------------------------
// Hand-made files.

class TinyScene : public ::testing::TestWithParam<int> {};

TEST_P(TinyScene, IdenticalInEveryEncodingAndMatchesKnownValues) {
  const int degree = GetParam();
  const GaussianScene expected = expected_tiny_scene(degree);
  for (Encoding encoding : kAllEncodings) {
    const std::string label = format_name(encoding);
    const auto path = write_file("tiny_sh" + std::to_string(degree) + "_" + label + ".ply",
                                 encode_ply(encoding, tiny_scene_elements(degree)));
    LoadReport report;
    const GaussianScene scene = load_ply(path, {}, &report);
    expect_same_scene(scene, expected, label);
    EXPECT_EQ(report.format, "ply " + label);
    EXPECT_EQ(report.gaussians_in_file, kTinyCount);
    EXPECT_EQ(report.dropped, 0u);
    EXPECT_EQ(report.ignored_properties, std::vector<std::string>{"confidence"});
  }
}

TEST_P(TinyScene, ReordersChannelMajorRestToCoefficientMajor) {
  const int degree = GetParam();
  const auto path =
      write_file("tiny_rest.ply", encode_ply(Encoding::kBinaryLittleEndian, tiny_scene_elements(degree)));
  const GaussianScene scene = load_ply(path);
  const size_t k_count = static_cast<size_t>(coefficients_of(degree));
  ASSERT_EQ(scene.sh_degree, degree);
  ASSERT_EQ(scene.sh.size(), kTinyCount * k_count * 3);
  for (size_t i = 0; i < kTinyCount; ++i)
    for (size_t k = 0; k < k_count; ++k)
      for (size_t c = 0; c < 3; ++c)
        EXPECT_EQ(scene.sh[(i * k_count + k) * 3 + c], sh_value(i, k, c))
            << "i " << i << " k " << k << " c " << c;
  if (degree == 1) {
    // Spelled out once: f_rest_4 is channel 1 (green), coefficient 2 (4 = 1 * 3 + (2 - 1)).
    EXPECT_EQ(scene.sh[(0 * 4 + 2) * 3 + 1], sh_value(0, 2, 1));
  }
}

INSTANTIATE_TEST_SUITE_P(ShDegrees, TinyScene, ::testing::Values(0, 1, 2, 3),
                         [](const ::testing::TestParamInfo<int>& param) {
                           return "sh" + std::to_string(param.param);
                         });

TEST(PlyLoader, NormalizesQuaternionsAndZeroBecomesIdentity) {
  const auto path =
      write_file("rotations.ply", encode_ply(Encoding::kBinaryLittleEndian, tiny_scene_elements(1)));
  const GaussianScene scene = load_ply(path);
  ASSERT_EQ(scene.size(), kTinyCount);
  const auto rotation = [&](size_t i) {
    return std::array<float, 4>{scene.rotations[4 * i], scene.rotations[4 * i + 1],
                                scene.rotations[4 * i + 2], scene.rotations[4 * i + 3]};
  };
  EXPECT_EQ(rotation(0), (std::array<float, 4>{1, 0, 0, 0}));  // (2, 0, 0, 0)
  EXPECT_EQ(rotation(1), (std::array<float, 4>{1, 0, 0, 0}));  // zero -> identity
  EXPECT_FLOAT_EQ(rotation(2)[0], 0.2f);                       // (1, 2, 2, 4) / 5
  EXPECT_FLOAT_EQ(rotation(2)[1], 0.4f);
  EXPECT_FLOAT_EQ(rotation(2)[2], 0.4f);
  EXPECT_FLOAT_EQ(rotation(2)[3], 0.8f);
  expect_unit_quaternions(scene);
}

TEST(PlyLoader, TinyQuaternionsNormalizeInsteadOfBecomingIdentity) {
  TestElement vertex = make_vertex_element(trainer_property_names(0, false), 1, 0);
  const size_t rot_1 = 11;  // x y z, f_dc_0..2, opacity, scale_0..2, rot_0, rot_1
  ASSERT_EQ(vertex.properties[rot_1].name, "rot_1");
  vertex.rows[0][rot_1 - 1] = {0.0};
  vertex.rows[0][rot_1] = {1e-30};  // its square underflows float, not double
  const GaussianScene scene =
      load_ply(write_file("tiny_quat.ply", encode_ply(Encoding::kBinaryLittleEndian, {vertex})));
  EXPECT_EQ(scene.rotations, (std::vector<float>{0, 1, 0, 0}));
}

TEST(PlyLoader, ConvertsEveryScalarType) {
  TestElement vertex{"vertex",
                     {{"char", "x"},
                      {"uchar", "y"},
                      {"short", "z"},
                      {"ushort", "f_dc_0"},
                      {"int", "f_dc_1"},
                      {"uint", "f_dc_2"},
                      {"double", "opacity"},
                      {"int8", "scale_0"},
                      {"uint8", "scale_1"},
                      {"int16", "scale_2"},
                      {"uint16", "rot_0"},
                      {"int32", "rot_1"},
                      {"uint32", "rot_2"},
                      {"float64", "rot_3"},
                      {"float32", "confidence"},
                      {"float", "nx"},
                      {"float32", "ny"},
                      {"double", "nz"},
                      {"double", "huge"}},
                     {}};
  vertex.rows = {
      {{-5},
       {200},
       {-300},
       {60000},
       {-70000},
       {4000000000.0},
       {0.1},
       {-7},
       {255},
       {-32768},
       {3},
       {0},
       {4},
       {0},
       {2.5},
       {0.25},
       {-1},
       {0.5},
       {1e300}},
      {{127},
       {0},
       {32767},
       {0},
       {2147483647},
       {0},
       {-0.75},
       {-128},
       {0},
       {0},
       {0},
       {0},
       {0},
       {0},
       {0},
       {0},
       {0},
       {0},
       {-1e300}},
  };
  for (Encoding encoding : kAllEncodings) {
    SCOPED_TRACE(format_name(encoding));
    LoadReport report;
    const GaussianScene scene = load_ply(
        write_file(std::string("types_") + format_name(encoding) + ".ply", encode_ply(encoding, {vertex})),
        {}, &report);
    ASSERT_EQ(scene.size(), 2u);
    EXPECT_EQ(scene.sh_degree, 0);
    EXPECT_EQ(scene.positions, (std::vector<float>{-5, 200, -300, 127, 0, 32767}));
    EXPECT_EQ(scene.sh, (std::vector<float>{60000, -70000, 4000000000.0f, 0, 2147483647.0f, 0}));
    EXPECT_EQ(scene.opacity_logits, (std::vector<float>{0.1f, -0.75f}));
    EXPECT_EQ(scene.log_scales, (std::vector<float>{-7, 255, -32768, -128, 0, 0}));
    EXPECT_EQ(scene.normals, (std::vector<float>{0.25f, -1, 0.5f, 0, 0, 0}));
    ASSERT_EQ(scene.rotations.size(), 8u);
    EXPECT_FLOAT_EQ(scene.rotations[0], 0.6f);  // (3, 0, 4, 0) / 5
    EXPECT_FLOAT_EQ(scene.rotations[1], 0.0f);
    EXPECT_FLOAT_EQ(scene.rotations[2], 0.8f);
    EXPECT_FLOAT_EQ(scene.rotations[3], 0.0f);
    EXPECT_EQ((std::vector<float>(scene.rotations.begin() + 4, scene.rotations.end())),
              (std::vector<float>{1, 0, 0, 0}));
    // The ignored double (out of float range) is neither converted nor checked.
    EXPECT_EQ(report.ignored_properties, (std::vector<std::string>{"confidence", "huge"}));
    EXPECT_EQ(report.dropped, 0u);
  }
}

TEST(PlyLoader, DegreeZeroWithoutNormals) {
  const GaussianScene expected = expected_tiny_scene(0, false);
  for (Encoding encoding : kAllEncodings) {
    const auto path = write_file(std::string("sh0_") + format_name(encoding) + ".ply",
                                 encode_ply(encoding, tiny_scene_elements(0, false)));
    const GaussianScene scene = load_ply(path);
    EXPECT_FALSE(scene.has_normals());
    expect_same_scene(scene, expected, format_name(encoding));
  }
}

TEST(PlyLoader, AcceptsCrlfLinesAndEmptyVertexElement) {
  std::string ascii = encode_ply(Encoding::kAscii, tiny_scene_elements(1));
  std::string crlf;
  for (char c : ascii) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  expect_same_scene(load_ply(write_file("crlf.ply", crlf)), expected_tiny_scene(1), "crlf");

  TestElement empty = make_vertex_element(trainer_property_names(2, true), 0, 2);
  for (Encoding encoding : kAllEncodings) {
    LoadReport report;
    const GaussianScene scene = load_ply(
        write_file(std::string("empty_") + format_name(encoding) + ".ply", encode_ply(encoding, {empty})), {},
        &report);
    EXPECT_TRUE(scene.empty());
    EXPECT_EQ(scene.sh_degree, 2);
    EXPECT_EQ(report.gaussians_in_file, 0u);
  }
}

// ---------------------------------------------------------------------------------------------
// Non-finite values.

// 12 Gaussians, degree 1, trainer order plus a float 'confidence' that is ignored.
TestElement non_finite_vertex() {
  std::vector<std::string> names = trainer_property_names(1, true);
  names.push_back("confidence");
  TestElement vertex = make_vertex_element(names, 12, 1);
  vertex.properties.back().type = "float";
  const auto set = [&](size_t gaussian, const std::string& name, double value) {
    const auto it = std::find(names.begin(), names.end(), name);
    ASSERT_NE(it, names.end());
    vertex.rows[gaussian][static_cast<size_t>(it - names.begin())] = {value};
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  set(2, "scale_1", nan);
  set(5, "opacity", inf);
  set(7, "scale_1", nan);  // f_rest_3 comes first in header order
  set(7, "f_rest_3", -inf);
  set(8, "confidence", nan);  // ignored: not checked, Gaussian kept
  set(9, "scale_1", nan);
  set(10, "ny", nan);
  return vertex;
}

TEST(PlyLoader, DropsNonFiniteGaussiansAndReportsThem) {
  const std::vector<size_t> kept = {0, 1, 3, 4, 6, 8, 11};
  for (Encoding encoding : kAllEncodings) {
    SCOPED_TRACE(format_name(encoding));
    const auto path = write_file(std::string("non_finite_") + format_name(encoding) + ".ply",
                                 encode_ply(encoding, {non_finite_vertex()}));
    LoadReport report;
    const GaussianScene scene = load_ply(path, {}, &report);
    ASSERT_EQ(scene.size(), kept.size());
    expect_sizes_consistent(scene);
    for (size_t j = 0; j < kept.size(); ++j) {
      EXPECT_EQ(scene.positions[3 * j], static_cast<float>(tiny_value(kept[j], "x", 1)));
      EXPECT_EQ(scene.opacity_logits[j], static_cast<float>(tiny_value(kept[j], "opacity", 1)));
      EXPECT_EQ(scene.sh[(j * 4 + 3) * 3 + 2], sh_value(kept[j], 3, 2));
      EXPECT_EQ(scene.normals[3 * j + 2], static_cast<float>(tiny_value(kept[j], "nz", 1)));
    }
    EXPECT_EQ(report.gaussians_in_file, 12u);
    EXPECT_EQ(report.dropped, 5u);
    ASSERT_EQ(report.dropped_by_property.size(), 4u);
    const auto expect_entry = [&](size_t at, const char* property, size_t count, size_t first) {
      EXPECT_EQ(report.dropped_by_property[at].property, property);
      EXPECT_EQ(report.dropped_by_property[at].count, count) << property;
      EXPECT_EQ(report.dropped_by_property[at].first_index, first) << property;
    };
    expect_entry(0, "scale_1", 2, 2);
    expect_entry(1, "opacity", 1, 5);
    expect_entry(2, "f_rest_3", 1, 7);
    expect_entry(3, "ny", 1, 10);
    EXPECT_EQ(
        report.summary(),
        "dropped 5 of 12 Gaussians with non-finite values (scale_1: 2, first at 2; opacity: 1, first at 5; "
        "f_rest_3: 1, first at 7; ny: 1, first at 10)");
  }
}

TEST(PlyLoader, StrictModeRejectsTheFirstNonFiniteGaussian) {
  LoadOptions strict;
  strict.strict = true;
  for (Encoding encoding : kAllEncodings) {
    SCOPED_TRACE(format_name(encoding));
    const auto path = write_file(std::string("strict_") + format_name(encoding) + ".ply",
                                 encode_ply(encoding, {non_finite_vertex()}));
    expect_load_error(path, {"Gaussian 2 has a non-finite value in scale_1 (nan) (strict mode)"}, strict);
  }
  TestElement vertex = non_finite_vertex();
  vertex.rows.erase(vertex.rows.begin(), vertex.rows.begin() + 3);  // first bad is now opacity = inf
  expect_load_error(write_file("strict_inf.ply", encode_ply(Encoding::kBinaryLittleEndian, {vertex})),
                    {"Gaussian 2 has a non-finite value in opacity (inf)"}, strict);
}

TEST(LoadReport, SummaryIsOneLineAndEmptyWhenNothingDropped) {
  LoadReport report;
  report.gaussians_in_file = 1000;
  EXPECT_EQ(report.summary(), "");
  report.dropped = 3;
  report.dropped_by_property = {{"scale_1", 2, 17}, {"opacity", 1, 40}};
  EXPECT_EQ(report.summary(),
            "dropped 3 of 1000 Gaussians with non-finite values (scale_1: 2, first at 17; opacity: 1, first "
            "at 40)");
}

// ---------------------------------------------------------------------------------------------
// Malformed files: every one is a SceneError naming the file, never a crash.

// A plain LE file of 3 Gaussians, degree 0, no normals, no extras.
std::string minimal_ply(Encoding encoding = Encoding::kBinaryLittleEndian, size_t count = 3) {
  return encode_ply(encoding, {make_vertex_element(trainer_property_names(0, false), count, 0)});
}

TEST(PlyLoaderErrors, MissingFileAndDirectory) {
  expect_load_error(testing::temp_dir() / "does_not_exist.ply", {"cannot open", "no such file"});
  expect_load_error(testing::temp_dir(), {"cannot open", "directory"});
  try {
    load_scene(testing::temp_dir() / "missing.ply");
    ADD_FAILURE() << "no error";
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find("missing.ply: cannot open"), std::string::npos) << error.what();
  }
}

TEST(PlyLoaderErrors, NotAPly) {
  expect_load_error(write_file("empty.ply", ""), {"empty file"});
  expect_load_error(write_file("magic.ply", "plz\nformat ascii 1.0\n"), {"not a PLY file"});
  expect_load_error(write_file("magic2.ply", "ply format ascii 1.0\n"), {"not a PLY file"});
  expect_load_error(write_file("text.ply", "hello world"), {"not a PLY file"});
}

// The formats issue made the reader follow the content, not the extension: a PLY under any name
// loads, and bytes of no known format are refused with the formats that are.
TEST(PlyLoaderErrors, SceneFormatIsChosenByContent) {
  EXPECT_EQ(load_scene(write_file("scene.xyz", minimal_ply())).size(), 3u);
  EXPECT_EQ(load_scene(write_file("noextension", minimal_ply())).size(), 3u);
  testing::expect_scene_error(write_file("scene.xyz", "this is no scene file at all"),
                              {"unrecognized scene format", ".spz"});
}

TEST(PlyLoaderErrors, HeaderProblems) {
  const std::string good = minimal_ply();
  expect_load_error(
      write_file("format.ply", replace_once(good, "binary_little_endian", "binary_middle_endian")),
      {"unsupported format 'binary_middle_endian'"});
  expect_load_error(write_file("noformat.ply", replace_once(good, "format binary_little_endian 1.0\n", "")),
                    {"no 'format' line"});
  expect_load_error(write_file("version.ply", replace_once(good, " 1.0\n", " 2.0\n")), {"version"});
  expect_load_error(write_file("novertex.ply", replace_once(good, "element vertex", "element points")),
                    {"no 'element vertex'"});
  expect_load_error(write_file("noend.ply", replace_once(good, "end_header\n", "")), {"end_header"});
  const std::string header_only = good.substr(0, good.find("end_header"));
  expect_load_error(write_file("noend2.ply", header_only), {"not terminated by 'end_header'"});
  expect_load_error(write_file("keyword.ply", replace_once(good, "comment", "remark")),
                    {"header line 3", "unexpected header line"});
  expect_load_error(write_file("type.ply", replace_once(good, "property float y", "property half y")),
                    {"unknown property type 'half'"});
  expect_load_error(write_file("dup.ply", replace_once(good, "property float y\n", "property float x\n")),
                    {"duplicated property 'x'"});
  expect_load_error(write_file("count.ply", replace_once(good, "element vertex 3", "element vertex -3")),
                    {"invalid count '-3'"});
  expect_load_error(write_file("count2.ply", replace_once(good, "element vertex 3",
                                                          "element vertex 99999999999999999999999")),
                    {"invalid count"});
  expect_load_error(write_file("orphan.ply", replace_once(good, "element vertex 3\n", "")),
                    {"property before any element"});
  expect_load_error(
      write_file("listvertex.ply", replace_once(good, "property float y", "property list uchar float y")),
      {"list property 'y'"});
  expect_load_error(write_file("listcount.ply",
                               replace_once(good, "element vertex",
                                            "element face 0\nproperty list float int idx\nelement vertex")),
                    {"not an integer type"});
}

TEST(PlyLoaderErrors, MissingRequiredProperty) {
  const std::string good = minimal_ply();
  expect_load_error(write_file("noopacity.ply", replace_once(good, "property float opacity\n", "")),
                    {"missing required property 'opacity'"});
  expect_load_error(write_file("norot.ply", replace_once(good, "property float rot_3\n", "")),
                    {"missing required property 'rot_3'"});
  expect_load_error(
      write_file("nox.ply", replace_once(good, "property float x\n", "property float packed_position\n")),
      {"missing required property 'x'", "compressed PLY"});
}

TEST(PlyLoaderErrors, BadRestAndNormalProperties) {
  TestElement vertex = make_vertex_element(trainer_property_names(1, false), 2, 1);
  const std::string degree1 = encode_ply(Encoding::kBinaryLittleEndian, {vertex});
  expect_load_error(write_file("rest10.ply", replace_once(degree1, "property float opacity",
                                                          "property float f_rest_9\nproperty float opacity")),
                    {"f_rest", "(10)", "0, 9, 24 or 45"});
  expect_load_error(write_file("rest8.ply", replace_once(degree1, "property float f_rest_8\n", "")),
                    {"f_rest", "(8)"});
  expect_load_error(write_file("restgap.ply", replace_once(degree1, "property float f_rest_8\n",
                                                           "property float f_rest_12\n")),
                    {"f_rest", "not contiguous", "f_rest_12"});
  expect_load_error(write_file("restname.ply", replace_once(degree1, "property float f_rest_8\n",
                                                            "property float f_rest_08\n")),
                    {"f_rest_08"});
  expect_load_error(
      write_file("normals.ply", replace_once(minimal_ply(), "property float z\n",
                                             "property float z\nproperty float nx\nproperty float nz\n")),
      {"incomplete normals", "'ny'"});
}

TEST(PlyLoaderErrors, TruncatedBinaryData) {
  for (Encoding encoding : {Encoding::kBinaryLittleEndian, Encoding::kBinaryBigEndian}) {
    const std::string good = minimal_ply(encoding);
    const std::string cut = good.substr(0, good.size() - 10);
    expect_load_error(write_file("truncated.ply", cut),
                      {"truncated", "expected 3 vertices", "10 bytes missing", "ends in vertex 2"});
  }
  // Truncated inside an element with a list property before the vertex element.
  const std::string with_faces = encode_ply(Encoding::kBinaryLittleEndian, tiny_scene_elements(1));
  const size_t face_data = with_faces.find("end_header\n") + 11;
  expect_load_error(write_file("truncated_faces.ply", with_faces.substr(0, face_data + 5)),
                    {"truncated", "element 'face'"});
  // Truncated in the element after the vertex element.
  expect_load_error(write_file("truncated_camera.ply", with_faces.substr(0, with_faces.size() - 1)),
                    {"truncated", "element 'camera'"});
}

TEST(PlyLoaderErrors, TrailingBinaryData) {
  expect_load_error(
      write_file("trailing.ply", minimal_ply() + "junk"),
      {"4 bytes of trailing data after the declared elements; the vertex count in the header may be wrong"});
  // The header undercounts: a whole vertex of data is left over.
  std::string undercount = replace_once(minimal_ply(), "element vertex 3", "element vertex 2");
  expect_load_error(write_file("undercount.ply", undercount), {"56 bytes of trailing data"});
}

TEST(PlyLoaderErrors, ImpossibleVertexCountIsRefusedBeforeAllocating) {
  for (Encoding encoding : kAllEncodings) {
    SCOPED_TRACE(format_name(encoding));
    const std::string good = minimal_ply(encoding);
    expect_load_error(
        write_file("huge.ply", replace_once(good, "element vertex 3", "element vertex 1000000000000")),
        {"impossible vertex count 1000000000000"});
    expect_load_error(write_file("overflow.ply", replace_once(good, "element vertex 3",
                                                              "element vertex 18446744073709551615")),
                      {"impossible vertex count 18446744073709551615"});
  }
  // Huge counts of other elements are walked against the data, never allocated.
  const std::string good = minimal_ply();
  expect_load_error(
      write_file(
          "hugefaces.ply",
          replace_once(good, "element vertex",
                       "element face 18446744073709551615\nproperty list uchar int idx\nelement vertex")),
      {"truncated", "element 'face'"});
  expect_load_error(
      write_file("hugechunks.ply",
                 replace_once(good, "element vertex",
                              "element chunk 4611686018427387904\nproperty float a\nelement vertex")),
      {"element 'chunk'", "impossible"});
}

TEST(PlyLoaderErrors, AsciiDataProblems) {
  const std::string good = minimal_ply(Encoding::kAscii);
  const size_t first_data_line = header_line_count(good) + 1;
  const size_t data = good.find("end_header\n") + 11;
  const size_t second_line = good.find('\n', data) + 1;
  const size_t second_end = good.find('\n', second_line);
  const std::string line2 = good.substr(second_line, second_end - second_line);
  const std::string line_number = "line " + std::to_string(first_data_line + 1);

  std::string few = good;
  few.replace(second_line, line2.size(), line2.substr(0, line2.rfind(' ')));
  expect_load_error(write_file("few.ply", few), {line_number, "too few values, expected 14, found 13"});

  std::string many = good;
  many.replace(second_line, line2.size(), line2 + " 1");
  expect_load_error(write_file("many.ply", many), {line_number, "too many values"});

  std::string word = good;
  word.replace(second_line, line2.find(' '), "abc");
  expect_load_error(write_file("word.ply", word), {line_number, "'abc' is not a number"});

  std::string range = good;
  range.replace(second_line, line2.find(' '), "1e999");
  expect_load_error(write_file("range.ply", range), {line_number, "out of range"});

  expect_load_error(write_file("extra_line.ply", good + line2 + "\n"),
                    {"trailing data", "the vertex count in the header may be wrong"});
  expect_load_error(
      write_file("undercount_ascii.ply", replace_once(good, "element vertex 3", "element vertex 2")),
      {"trailing data", "line " + std::to_string(first_data_line + 2)});
  expect_load_error(
      write_file("overcount_ascii.ply", replace_once(good, "element vertex 3", "element vertex 4")),
      {"truncated", "expected 4 vertices", "ends after 3"});
  // Trailing blank lines are harmless.
  EXPECT_EQ(load_ply(write_file("blank_tail.ply", good + "\n  \n")).size(), 3u);
}

TEST(PlyLoaderErrors, EveryTruncationOfABinaryFileIsAnError) {
  const std::string good = encode_ply(Encoding::kBinaryLittleEndian, tiny_scene_elements(0));
  size_t errors = 0;
  for (size_t length = 0; length < good.size(); ++length) {
    try {
      load_ply(write_file("prefix.ply", good.substr(0, length)));
      ADD_FAILURE() << "prefix of " << length << " bytes loaded";
    } catch (const SceneError&) {
      ++errors;
    }
  }
  EXPECT_EQ(errors, good.size());
}

TEST(PlyLoaderErrors, CorruptedBytesNeverCrash) {
  // ASCII prefixes can be valid files (a number cut short is still a number): either outcome is
  // fine, anything but a SceneError is not.
  const std::string ascii = encode_ply(Encoding::kAscii, tiny_scene_elements(0));
  for (size_t length = 0; length < ascii.size(); length += 3) {
    try {
      load_ply(write_file("ascii_prefix.ply", ascii.substr(0, length)));
    } catch (const SceneError&) {
    }
  }
  const std::string binary = encode_ply(Encoding::kBinaryBigEndian, tiny_scene_elements(0));
  const size_t header_end = binary.find("end_header\n") + 11;
  for (size_t at = 0; at < header_end; ++at) {
    for (char replacement : {'\0', '9', '\n'}) {
      std::string corrupted = binary;
      corrupted[at] = replacement;
      try {
        const GaussianScene scene = load_ply(write_file("corrupted.ply", corrupted));
        expect_sizes_consistent(scene);
      } catch (const SceneError&) {
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Bounds.

TEST(SceneBounds, EmptySceneIsAllZeros) {
  const Bounds bounds = compute_bounds(GaussianScene{});
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(bounds.min[a], 0.0);
    EXPECT_EQ(bounds.max[a], 0.0);
    EXPECT_EQ(bounds.center[a], 0.0);
  }
  EXPECT_EQ(bounds.radius, 0.0);
}

TEST(SceneBounds, MedianCenterAndRobustRadiusIgnoreFloaters) {
  GaussianScene scene;
  // A 5x5x5 grid over [-1, 1]^3 around (10, 20, 30), plus 2 far floaters on one side.
  for (int ix = 0; ix < 5; ++ix)
    for (int iy = 0; iy < 5; ++iy)
      for (int iz = 0; iz < 5; ++iz) {
        scene.positions.insert(scene.positions.end(), {10 + 0.5f * static_cast<float>(ix - 2),
                                                       20 + 0.5f * static_cast<float>(iy - 2),
                                                       30 + 0.5f * static_cast<float>(iz - 2)});
        scene.opacity_logits.push_back(0);
      }
  for (float far : {1000.0f, 5000.0f}) {
    scene.positions.insert(scene.positions.end(), {far, -far, far});
    scene.opacity_logits.push_back(0);
  }
  const Bounds bounds = compute_bounds(scene);
  EXPECT_EQ(bounds.center[0], 10.0);
  EXPECT_EQ(bounds.center[1], 20.0);
  EXPECT_EQ(bounds.center[2], 30.0);
  // 127 distances, nearest-rank 95th percentile = the 121st smallest: above it are only the 2
  // floaters and some of the 8 corners at sqrt(3).
  EXPECT_NEAR(bounds.radius, std::sqrt(3.0), 1e-6);
  EXPECT_EQ(bounds.min[0], 9.0);
  EXPECT_EQ(bounds.max[0], 5000.0);
  EXPECT_EQ(bounds.min[1], -5000.0);
  EXPECT_EQ(bounds.max[1], 21.0);

  GaussianScene single;
  single.positions = {1, 2, 3};
  single.opacity_logits = {0};
  const Bounds one = compute_bounds(single);
  EXPECT_EQ(one.center[1], 2.0);
  EXPECT_EQ(one.radius, 0.0);
  EXPECT_EQ(one.min[2], 3.0);

  GaussianScene pair;
  pair.positions = {0, 0, 0, 2, 4, 6};
  pair.opacity_logits = {0, 0};
  const Bounds two = compute_bounds(pair);
  EXPECT_EQ(two.center[0], 1.0);  // even count: mean of the middle two
  EXPECT_EQ(two.center[2], 3.0);
}

TEST(SceneBounds, BundledPlaybotRadiusIsBelowItsBoxDiagonal) {
  const Bounds bounds = compute_bounds(load_ply(testing::bundled_playbot()));
  double diagonal = 0;
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(bounds.min[a], bounds.center[a]);
    EXPECT_LE(bounds.center[a], bounds.max[a]);
    diagonal += (bounds.max[a] - bounds.min[a]) * (bounds.max[a] - bounds.min[a]);
  }
  EXPECT_GT(bounds.radius, 0.0);
  EXPECT_LT(bounds.radius, std::sqrt(diagonal));
}

// ---------------------------------------------------------------------------------------------
// The shared real scenes (optional).

// "guitar_90854_sh0.ply" -> {90854, 0}; nothing for other names (e.g. NAME.compressed.ply).
std::optional<std::pair<size_t, int>> count_and_degree_from_name(const std::string& name) {
  constexpr std::string_view kSuffix = ".ply";
  if (!name.ends_with(kSuffix)) return std::nullopt;
  const std::string_view stem = std::string_view(name).substr(0, name.size() - kSuffix.size());
  const size_t sh = stem.rfind("_sh");
  if (sh == std::string_view::npos || stem.size() != sh + 4 || stem[sh + 3] < '0' || stem[sh + 3] > '3')
    return std::nullopt;
  const size_t underscore = stem.rfind('_', sh - 1);
  if (underscore == std::string_view::npos || sh == 0) return std::nullopt;
  const std::string_view digits = stem.substr(underscore + 1, sh - underscore - 1);
  size_t count = 0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), count);
  if (digits.empty() || error != std::errc() || end != digits.data() + digits.size()) return std::nullopt;
  return std::pair<size_t, int>{count, stem[sh + 3] - '0'};
}

TEST(PlyLoaderSharedScenes, FileNamePatternParses) {
  EXPECT_EQ(count_and_degree_from_name("guitar_90854_sh0.ply"), (std::pair<size_t, int>{90854, 0}));
  EXPECT_EQ(count_and_degree_from_name("playbot_lod0_500000_sh2.ply"), (std::pair<size_t, int>{500000, 2}));
  EXPECT_FALSE(count_and_degree_from_name("guitar_90854.compressed.ply"));
  EXPECT_FALSE(count_and_degree_from_name("plant_113648.splat"));
}

TEST(PlyLoaderSharedScenes, EveryScenePlyLoadsWithItsCount) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  // NAME_COUNT_shN.ply; compressed PLYs (NAME.compressed.ply) are another format.
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(testing::shared_scenes()))
    if (entry.path().extension() == ".ply") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  size_t loaded = 0;
  for (const std::filesystem::path& path : files) {
    const std::string name = path.filename().string();
    const auto expected = count_and_degree_from_name(name);
    if (!expected) continue;
    SCOPED_TRACE(name);
    const auto [expected_count, expected_degree] = *expected;
    LoadReport report;
    const auto start = std::chrono::steady_clock::now();
    const GaussianScene scene = load_ply(path, {}, &report);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::cout << "[ load     ] " << name << ": " << scene.size() << " Gaussians in " << ms << " ms\n";
    EXPECT_EQ(report.gaussians_in_file, expected_count);
    EXPECT_EQ(scene.size(), expected_count) << report.summary();
    EXPECT_EQ(scene.sh_degree, expected_degree);
    expect_sizes_consistent(scene);
    expect_unit_quaternions(scene);
    ++loaded;
  }
  EXPECT_GT(loaded, 0u) << "no NAME_COUNT_shN.ply in " << testing::shared_scenes();
}

// A PlayCanvas compressed PLY is read by load_ply too (tests/test_scene_formats.cpp checks its values).
TEST(PlyLoaderSharedScenes, CompressedPlyIsRead) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const auto path = testing::shared_scenes() / "playcanvas_test_64.compressed.ply";
  if (!std::filesystem::exists(path)) TILESPLAT_SKIP_OR_FAIL(path << " not found");
  LoadReport report;
  const GaussianScene scene = load_ply(path, {}, &report);
  EXPECT_EQ(report.format, "compressed ply");
  EXPECT_EQ(scene.size(), 64u);
  EXPECT_EQ(scene.sh_degree, 3);
}

// ---------------------------------------------------------------------------------------------
// MappedPly: a binary PLY read part by part holds load_ply's Gaussians, bit for bit.

void expect_same_bounds(const Bounds& actual, const Bounds& expected) {
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(actual.min[a], expected.min[a]);
    EXPECT_EQ(actual.max[a], expected.max[a]);
    EXPECT_EQ(actual.center[a], expected.center[a]);
  }
  EXPECT_EQ(actual.radius, expected.radius);
}

void expect_mapped_is_loaded(const std::filesystem::path& path, const LoadOptions& options = {}) {
  LoadReport loaded_report, mapped_report;
  const GaussianScene loaded = load_ply(path, options, &loaded_report);
  const MappedPly mapped = MappedPly::open(path, options, &mapped_report);
  EXPECT_EQ(mapped.size(), loaded.size()) << path;
  EXPECT_EQ(mapped.sh_degree(), loaded.sh_degree) << path;
  EXPECT_EQ(mapped.has_normals(), loaded.has_normals()) << path;
  expect_same_bounds(mapped.bounds(), compute_bounds(loaded));
  expect_same_scene(mapped.load(), loaded, path.string(),
                    Rotations::kExactly);  // both normalize the same floats
  EXPECT_EQ(mapped_report.summary(), loaded_report.summary());
  EXPECT_EQ(mapped_report.format, loaded_report.format);
  EXPECT_EQ(mapped_report.gaussians_in_file, loaded_report.gaussians_in_file);
  EXPECT_EQ(mapped_report.ignored_properties, loaded_report.ignored_properties);
}

TEST(MappedPly, HoldsTheGaussiansLoadPlyReads) {
  expect_mapped_is_loaded(testing::bundled_playbot());
  expect_mapped_is_loaded(testing::bundled_sh3());
  for (Encoding encoding : {Encoding::kBinaryLittleEndian, Encoding::kBinaryBigEndian})
    for (int degree = 0; degree <= 3; ++degree) {
      SCOPED_TRACE(std::string(format_name(encoding)) + " degree " + std::to_string(degree));
      // Other elements (one with a list property) before and after the vertices, shuffled properties.
      expect_mapped_is_loaded(
          write_file("mapped_tiny.ply", encode_ply(encoding, tiny_scene_elements(degree))));
    }
  // No vertices: an empty scene.
  const std::filesystem::path empty =
      write_file("mapped_empty.ply", minimal_ply(Encoding::kBinaryLittleEndian, 0));
  EXPECT_EQ(MappedPly::open(empty).size(), 0u);
  EXPECT_EQ(MappedPly::open(empty).load().size(), 0u);
}

TEST(MappedPly, DropsNonFiniteGaussiansAsLoadPlyDoes) {
  LoadOptions strict;
  strict.strict = true;
  for (Encoding encoding : {Encoding::kBinaryLittleEndian, Encoding::kBinaryBigEndian}) {
    SCOPED_TRACE(format_name(encoding));
    const auto path = write_file("mapped_non_finite.ply", encode_ply(encoding, {non_finite_vertex()}));
    expect_mapped_is_loaded(path);
    LoadReport report;
    EXPECT_EQ(MappedPly::open(path, {}, &report).size(), 7u);
    EXPECT_EQ(report.dropped, 5u);
    try {
      MappedPly::open(path, strict);
      ADD_FAILURE() << "strict: opened";
    } catch (const SceneError& error) {
      EXPECT_NE(
          std::string(error.what()).find("Gaussian 2 has a non-finite value in scale_1 (nan) (strict mode)"),
          std::string::npos)
          << error.what();
    }
  }
}

// Opens and expects a SceneError whose message starts with the path and holds every phrase.
void expect_mapped_error(const std::filesystem::path& path, std::initializer_list<std::string_view> phrases) {
  expect_read_error(path, phrases, [&] { MappedPly::open(path); });
}

TEST(MappedPlyErrors, WhatCannotBeReadInPartsIsRefusedNamingTheFile) {
  expect_mapped_error(testing::temp_dir() / "does_not_exist.ply", {"cannot open", "no such file"});
  expect_mapped_error(write_file("mapped_ascii.ply", minimal_ply(Encoding::kAscii)),
                      {"an ASCII PLY cannot be read part by part"});
  expect_mapped_error(write_file("mapped_not.ply", "not a ply\n"), {"not a PLY file"});
  const std::string good = minimal_ply();
  expect_mapped_error(write_file("mapped_truncated.ply", good.substr(0, good.size() - 5)),
                      {"truncated binary data"});
  expect_mapped_error(write_file("mapped_trailing.ply", good + "xyz"), {"trailing data"});
  // Every prefix of a binary file is an error, never a crash.
  const std::string tiny = encode_ply(Encoding::kBinaryLittleEndian, tiny_scene_elements(1));
  for (size_t length = 0; length < tiny.size(); length += 7) {
    try {
      MappedPly::open(write_file("mapped_prefix.ply", tiny.substr(0, length)));
      ADD_FAILURE() << "prefix of " << length << " bytes opened";
    } catch (const SceneError&) {
    }
  }
}

TEST(MappedPlySharedScenes, ACompressedPlyIsRefused) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const auto path = testing::shared_scenes() / "playcanvas_test_64.compressed.ply";
  if (!std::filesystem::exists(path)) TILESPLAT_SKIP_OR_FAIL(path << " not found");
  expect_mapped_error(path, {"a compressed PLY (PlayCanvas) cannot be read part by part"});
  expect_mapped_is_loaded(testing::shared_scenes() / "guitar_90854_sh0.ply");
}

}  // namespace
}  // namespace tilesplat
