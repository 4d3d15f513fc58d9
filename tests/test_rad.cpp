// Spark 2's .rad (engine/src/scene/rad_file.cpp, tilesplat/lod_tree.h). The files in tests/data/rad are Spark's
// own encoder's (build-lod, tests/data/rad/make_rad.sh) for playcanvas_test_64_sh3.ply: a quality and a quick
// LOD tree, SH clamped to degree 1, SH as a codebook, and the chunk in a .radc file beside the header. Each
// leaf is checked against its source as the encoder quantizes it, each file's level 0 rendered against the
// float64 reference of its Gaussians and against the source; every level and every budgeted cut must be a
// cut of the tree as Spark's rules make it. A file built here from the layout in rad.rs covers the encodings
// build-lod does not choose, a file without a tree, and damaged trees.
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "process_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/lod_tree.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_in_parts.h"

namespace tilesplat {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kRadDir = fs::path(TILESPLAT_SOURCE_DIR) / "tests" / "data" / "rad";
constexpr double kShC0 = 0.28209479177387814;
constexpr double kPi = 3.14159265358979323846;

fs::path write_file(const std::string& name, const std::string& bytes) {
  return testing::write_temp_file("rad", name, bytes);
}

double sigmoid(double x) { return 1 / (1 + std::exp(-x)); }

// The header's JSON (RAD0, length, text).
json header_of(const fs::path& path) {
  const std::string bytes = testing::read_file(path);
  uint32_t length = 0;
  std::memcpy(&length, bytes.data() + 4, 4);
  return json::parse(bytes.substr(8, length));
}

// Rotation angle between two unit quaternions (w x y z), either sign.
double angle_between(const float* a, const float* b) {
  double dot = 0;
  for (int k = 0; k < 4; ++k) dot += double(a[k]) * b[k];
  return 2 * std::acos(std::min(1.0, std::fabs(dot)));
}

struct RadCase {
  const char* file;
  int sh_degree;
  bool sh_codebook;  // SH from a clustered codebook: only the geometry is checked per leaf
};
const RadCase kCases[] = {{"playcanvas_test_64_sh3-lod.rad", 3, false},
                          {"playcanvas_test_64_sh3_quick-lod.rad", 3, false},
                          {"playcanvas_test_64_sh3_sh1-lod.rad", 1, false},
                          {"playcanvas_test_64_sh3_clustered-lod.rad", 3, true},
                          {"playcanvas_test_64_sh3_chunked-lod.rad", 3, false}};

class RadFiles : public ::testing::TestWithParam<RadCase> {};

// build-lod's encodings: positions as float32 bytes (exact), opacity float16 (a LOD tree's may pass 1), colour
// 8 bits over the header's [rgbMin, rgbMax] (clamped), log scale 8 bits over [lnScaleMin, lnScaleMax] (254
// steps), rotation as an 8-bit octahedral axis and an 8-bit angle, SH 8 bits over [-shNMax, shNMax]. Before
// that the LOD builder holds colour, log scale and opacity as float16 (its Gsplat), which may move a value
// across a step's middle: each bound is half a step plus float16's rounding of the value. The rotation's:
// half the angle's step (pi / 255) plus the octahedral axis's (measured worst 0.0222 rad).
TEST_P(RadFiles, EachLeafIsItsSourceAsTheEncoderQuantizesIt) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const RadCase c = GetParam();
  const fs::path path = kRadDir / c.file;
  LoadReport report;
  const GaussianScene scene = load_scene(path, {}, &report);
  const GaussianScene source = load_scene(testing::shared_scenes() / "playcanvas_test_64_sh3.ply");
  EXPECT_TRUE(report.format.starts_with("rad (1 chunk; LOD tree of ")) << report.format;
  EXPECT_NE(report.format.find("its 64 leaves read; center f32_lebytes, alpha "), std::string::npos) << report.format;
  EXPECT_EQ(report.version, "1");
  ASSERT_EQ(scene.size(), source.size());
  ASSERT_EQ(scene.sh_degree, c.sh_degree);
  const json encoding = header_of(path)["splatEncoding"];
  const double rgb_min = encoding["rgbMin"], rgb_max = encoding["rgbMax"];
  const double ln_min = encoding["lnScaleMin"], ln_max = encoding["lnScaleMax"];
  const double sh_max[4] = {0, encoding["sh1Max"], encoding["sh2Max"], encoding["sh3Max"]};
  const size_t coefficients = size_t(scene.sh_coefficients());
  std::vector<bool> matched(source.size(), false);
  for (size_t i = 0; i < scene.size(); ++i) {
    SCOPED_TRACE("leaf " + std::to_string(i));
    // The encoder reorders the splats; positions are exact, so each leaf finds its source by them.
    size_t s = 0;
    while (s < source.size() && !std::equal(scene.positions.begin() + std::ptrdiff_t(3 * i),
                                            scene.positions.begin() + std::ptrdiff_t(3 * i + 3),
                                            source.positions.begin() + std::ptrdiff_t(3 * s)))
      ++s;
    ASSERT_LT(s, source.size()) << "no source Gaussian at this position";
    EXPECT_FALSE(matched[s]);
    matched[s] = true;
    constexpr double kHalf = 1.0 / 2048;  // float16's relative rounding
    for (size_t a = 0; a < 3; ++a) {
      const double log_scale = std::clamp(double(source.log_scales[3 * s + a]), ln_min, ln_max);
      EXPECT_NEAR(scene.log_scales[3 * i + a], log_scale,
                  (ln_max - ln_min) / 254 / 2 + std::fabs(log_scale) * kHalf + 1e-5);
    }
    EXPECT_NEAR(sigmoid(scene.opacity_logits[i]), sigmoid(source.opacity_logits[s]), kHalf);
    EXPECT_LE(angle_between(&scene.rotations[4 * i], &source.rotations[4 * s]), 0.025);
    for (size_t ch = 0; ch < 3; ++ch) {
      const double colour = std::clamp(0.5 + kShC0 * source.sh[3 * 16 * s + ch], rgb_min, rgb_max);
      EXPECT_NEAR(0.5 + kShC0 * scene.sh[3 * coefficients * i + ch], colour,
                  (rgb_max - rgb_min) / 255 / 2 + std::fabs(colour) * kHalf + 1e-6);
    }
    if (c.sh_codebook) continue;
    for (size_t k = 1; k < coefficients; ++k) {
      const int band = k < 4 ? 1 : k < 9 ? 2 : 3;
      for (size_t ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(scene.sh[3 * (coefficients * i + k) + ch],
                    std::clamp(double(source.sh[3 * (16 * s + k) + ch]), -sh_max[band], sh_max[band]),
                    sh_max[band] / 127 / 2 + 1e-6)
            << "SH " << k << " channel " << ch;
    }
  }
}

TEST_P(RadFiles, LevelZeroRendersAsItsReferenceAndNearItsSource) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const RadCase c = GetParam();
  const GaussianScene scene = load_scene(kRadDir / c.file);
  const GaussianScene source = load_scene(testing::shared_scenes() / "playcanvas_test_64_sh3.ply");
  const Camera camera = resize_camera(
      load_cameras_json(testing::shared_scenes() / "cameras" / "playcanvas_test_64_sh3.json")[0].camera, 240, 135);
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  const RenderImage image = renderer.render(camera);
  testing::expect_matches_reference(image, render_reference(scene, camera, RenderSettings{}), 2e-5, c.file);
  // The source at the SH degree the file keeps: its first (degree + 1)^2 coefficients.
  const GaussianScene truncated = testing::with_sh_degree(source, c.sh_degree);
  renderer.set_scene(truncated);
  const ImageDifference d = compare_images(image, renderer.render(camera));
  std::printf("[ measure  ] %s, %zu bytes: level 0 %.1f dB against the source PLY (max abs %.2e)\n", c.file,
              size_t(fs::file_size(kRadDir / c.file)), d.psnr_db, d.max_abs);
  // Measured 42.7 to 45.4 dB: 8-bit colour (clamped to the file's range), log scale, SH and rotation axis.
  EXPECT_GE(d.psnr_db, 40.0);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// Read part by part (SceneInParts: each part decodes the chunks its leaves lie in): its Gaussians are the
// whole read's, bit for bit, and a frame rendered in parts under a memory budget is the whole frame.
TEST_P(RadFiles, ReadPartByPartIsTheWholeRead) {
  const fs::path path = kRadDir / GetParam().file;
  const GaussianScene whole = load_scene(path);
  // The header's count sizes every splat, a tree's inner nodes too: at least the leaves' arrays.
  EXPECT_GE(SceneInParts::whole_scene_bytes(path),
            whole.size() * (11 + 3 * uint64_t(whole.sh_coefficients())) * sizeof(float));
  testing::expect_read_in_parts_as_whole(
      path, resize_camera(load_cameras_json(testing::bundled_sh3_cameras())[0].camera, 64, 48));
}

// Every leaf has exactly one node of `cut` on its way to the root (itself included).
void expect_cut(const SplatLodTree& tree, const std::vector<uint32_t>& cut, const std::string& what) {
  std::vector<int> covered(tree.nodes(), 0);
  std::vector<bool> in_cut(tree.nodes(), false);
  for (uint32_t node : cut) in_cut[node] = true;
  // Down from the root: how many cut nodes each node has above it or is.
  std::vector<std::pair<uint32_t, int>> stack = {{0, 0}};
  size_t leaves = 0;
  while (!stack.empty()) {
    const auto [node, above] = stack.back();
    stack.pop_back();
    const int here = above + (in_cut[node] ? 1 : 0);
    if (tree.child_count(node) == 0) {
      ++leaves;
      EXPECT_EQ(here, 1) << what << ": leaf " << node;
    }
    for (uint32_t k = 0; k < tree.child_count(node); ++k) stack.push_back({tree.child_start(node) + k, here});
  }
  EXPECT_EQ(leaves, 64u) << what;
  EXPECT_TRUE(std::is_sorted(cut.begin(), cut.end())) << what;
}

TEST_P(RadFiles, EachLevelIsACutFromTheLeavesToTheRoot) {
  const RadCase c = GetParam();
  const SplatLodTree tree = SplatLodTree::open(kRadDir / c.file);
  ASSERT_GT(tree.levels(), 2);
  const std::vector<uint32_t> leaves = tree.level_nodes(0);
  EXPECT_EQ(leaves.size(), 64u);
  EXPECT_EQ(tree.level_nodes(tree.levels() - 1), std::vector<uint32_t>{0});  // the root alone
  size_t previous = leaves.size();
  for (int level = 0; level < tree.levels(); ++level) {
    const std::vector<uint32_t> cut = tree.level_nodes(level);
    expect_cut(tree, cut, "level " + std::to_string(level));
    EXPECT_LE(cut.size(), previous) << "level " << level;  // coarser, never finer
    previous = cut.size();
    // Spark's rule: a drawn inner node is within the level's size; a refined one was not.
    const double threshold = tree.node_size(0) / std::pow(1.25, tree.levels() - 1 - level);
    for (uint32_t node : cut)
      if (tree.child_count(node) > 0) {
        EXPECT_LE(tree.node_size(node), threshold) << level;
      }
  }
  // Level 0 is what load_scene reads; any level loads.
  const GaussianScene whole = load_scene(kRadDir / c.file);
  EXPECT_EQ(tree.load_level(0).positions, whole.positions);
  EXPECT_EQ(tree.load_level(tree.levels() / 2).size(), tree.level_nodes(tree.levels() / 2).size());
  EXPECT_THROW(tree.level_nodes(tree.levels()), std::out_of_range);
  const std::vector<uint32_t> past_the_end = {uint32_t(tree.nodes())};
  EXPECT_THROW(tree.load(past_the_end), std::out_of_range);
}

TEST_P(RadFiles, ABudgetRefinesTheNodesThatCoverMostUntilTheNextWouldNotFit) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const RadCase c = GetParam();
  const SplatLodTree tree = SplatLodTree::open(kRadDir / c.file);
  const Camera camera =
      load_cameras_json(testing::shared_scenes() / "cameras" / "playcanvas_test_64_sh3.json")[0].camera;
  const auto pixel_scale = [&](uint32_t node) {
    const std::vector<uint32_t> nodes = {node};
    const GaussianScene one = tree.load(nodes);
    double d2 = 0;
    for (size_t a = 0; a < 3; ++a) d2 += std::pow(double(one.positions[a]) - camera.position[a], 2);
    return tree.node_size(node) / std::sqrt(d2);
  };
  size_t previous = 0;
  for (uint64_t budget : {0, 1, 2, 5, 10, 20, 40, 63, 64, 1000}) {
    SCOPED_TRACE("budget " + std::to_string(budget));
    const LodTreeCut cut = tree.select(camera, budget);
    EXPECT_EQ(cut.over_budget, budget == 0);
    expect_cut(tree, cut.nodes, "budget " + std::to_string(budget));
    EXPECT_LE(cut.nodes.size(), std::max<uint64_t>(budget, 1));
    EXPECT_GE(cut.nodes.size(), previous);  // more budget, never a coarser cut
    previous = cut.nodes.size();
    if (budget >= 64) {
      EXPECT_EQ(cut.nodes, tree.level_nodes(0));
    }
    // The refinement stopped at the inner node covering most of the view: its children would not fit.
    uint32_t largest = 0;
    double largest_scale = -1;
    for (uint32_t node : cut.nodes)
      if (tree.child_count(node) > 0 && pixel_scale(node) > largest_scale) largest = node, largest_scale = pixel_scale(node);
    if (largest_scale >= 0) {
      EXPECT_GT(cut.nodes.size() - 1 + tree.child_count(largest), budget) << "node " << largest;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(BuildLod, RadFiles, ::testing::ValuesIn(kCases), [](const auto& param_info) {
  std::string name = param_info.param.file;
  name = name.substr(0, name.find('.'));
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
});

// ---- Files built from rad.rs's layout --------------------------------------------------------------------

std::string raw_deflate(const std::string& bytes) {
  z_stream stream{};
  EXPECT_EQ(deflateInit2(&stream, 6, Z_DEFLATED, -MAX_WBITS, 8, Z_DEFAULT_STRATEGY), Z_OK);
  std::string out(deflateBound(&stream, bytes.size()), '\0');
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  stream.avail_in = uInt(bytes.size());
  stream.next_out = reinterpret_cast<Bytef*>(out.data());
  stream.avail_out = uInt(out.size());
  EXPECT_EQ(deflate(&stream, Z_FINISH), Z_STREAM_END);
  out.resize(out.size() - stream.avail_out);
  deflateEnd(&stream);
  return out;
}

template <typename T>
void append(std::string& bytes, T value) {
  bytes.append(reinterpret_cast<const char*>(&value), sizeof(T));
}
void pad8(std::string& bytes) {
  while (bytes.size() % 8) bytes += '\0';
}

// One chunk of properties (name, encoding, bytes as stored, extra JSON), compressed or not.
struct BuiltProperty {
  std::string name, encoding, bytes;
  json extra = json::object();
  bool gz = false;
};
std::string chunk_bytes(size_t base, size_t count, int max_sh, bool lod_tree, const std::vector<BuiltProperty>& properties) {
  std::string payload;
  json meta = {{"version", 1}, {"base", base}, {"count", count}, {"maxSh", max_sh}, {"properties", json::array()}};
  if (lod_tree) meta["lodTree"] = true;
  for (const BuiltProperty& p : properties) {
    const std::string stored = p.gz ? raw_deflate(p.bytes) : p.bytes;
    json entry = {{"offset", payload.size()}, {"bytes", stored.size()}, {"property", p.name}, {"encoding", p.encoding}};
    if (p.gz) entry["compression"] = "gz";
    if (p.extra.is_object()) entry.update(p.extra);
    meta["properties"].push_back(entry);
    payload += stored;
    pad8(payload);
  }
  meta["payloadBytes"] = payload.size();
  const std::string text = meta.dump();
  std::string chunk = "RADC";
  append(chunk, uint32_t(text.size()));
  chunk += text;
  pad8(chunk);
  append(chunk, uint64_t(payload.size()));
  return chunk + payload;
}
// A RAD0 header over `chunks` (each of `chunk_size` splats but the last), the chunks after it.
std::string rad_bytes(size_t count, int max_sh, bool lod_tree, const std::vector<std::string>& chunks,
                      size_t chunk_size = 65536) {
  json ranges = json::array();
  std::string bytes;
  for (const std::string& chunk : chunks) {
    ranges.push_back({{"offset", bytes.size()}, {"bytes", chunk.size()}});
    bytes += chunk;
  }
  json meta = {{"version", 1},          {"type", "gsplat"},        {"count", count}, {"maxSh", max_sh},
               {"chunkSize", chunk_size}, {"allChunkBytes", bytes.size()}, {"chunks", ranges}};
  if (lod_tree) meta["lodTree"] = true;
  const std::string text = meta.dump();
  std::string out = "RAD0";
  append(out, uint32_t(text.size()));
  out += text;
  pad8(out);
  return out + bytes;
}

uint16_t half_of(float v) {  // exact for the values used here (small dyadic fractions)
  uint32_t bits = 0;
  std::memcpy(&bits, &v, 4);
  if (v == 0) return 0;
  const uint32_t sign = bits >> 31, exponent = (bits >> 23) & 0xff, mantissa = bits & 0x7fffff;
  return uint16_t(sign << 15 | (exponent - 127 + 15) << 10 | mantissa >> 13);
}

// Two splats, every encoding build-lod leaves out: center f16 planes of bytes, alpha r8, rgb f32, scales
// ln_f16, orientation f16 (x y z, w derived), sh1 s8_delta; no LOD tree. Each value is the formula's.
TEST(Rad, AFileBuiltFromTheLayoutDecodesEachEncodingAsRadRsDoes) {
  const float centers[2][3] = {{0.5f, -1.25f, 2.0f}, {3.0f, 0.125f, -0.75f}};
  std::string center;  // f16_lebytes: byte b of every value, planar by component
  for (int b = 0; b < 2; ++b)
    for (int d = 0; d < 3; ++d)
      for (int i = 0; i < 2; ++i) center += char((half_of(centers[i][d]) >> (8 * b)) & 0xff);
  const std::string alpha = {char(51), char(255)};  // r8 over [0, 1]: 0.2 and 1
  std::string rgb;                                   // f32, planar
  const float colours[2][3] = {{0.25f, 0.5f, 0.75f}, {1.5f, -0.25f, 0.0f}};
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < 2; ++i) append(rgb, colours[i][d]);
  std::string scales;  // ln_f16: log scales as halves
  const float log_scales[2][3] = {{-2.0f, -3.0f, -4.5f}, {0.0f, -1.0f, -0.5f}};
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < 2; ++i) append(scales, half_of(log_scales[i][d]));
  std::string orientation;  // f16 x y z; w = sqrt(1 - |xyz|^2)
  const float xyz[2][3] = {{0.5f, 0.5f, 0.5f}, {0.0f, 0.0f, 0.0f}};
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < 2; ++i) append(orientation, half_of(xyz[i][d]));
  std::string sh1;  // s8_delta over max 2: per component the running sum of bytes, as int8 / 127 * 2
  const int8_t sh1_values[2][9] = {{127, -127, 0, 64, -64, 1, 2, 3, 4}, {-127, 127, 0, 0, 10, -10, 5, 5, 5}};
  for (int d = 0; d < 9; ++d) {
    uint8_t last = 0;
    for (int i = 0; i < 2; ++i) {
      const uint8_t value = uint8_t(sh1_values[i][d]);
      sh1 += char(uint8_t(value - last));
      last = value;
    }
  }
  const std::string chunk = chunk_bytes(
      0, 2, 1, false,
      {{"center", "f16_lebytes", center, {}, true},
       {"alpha", "r8", alpha, {{"min", 0.0}, {"max", 1.0}}, false},
       {"rgb", "f32", rgb, {}, true},
       {"scales", "ln_f16", scales, {}, false},
       {"orientation", "f16", orientation, {}, true},
       {"sh1", "s8_delta", sh1, {{"min", -2.0}, {"max", 2.0}}, true}});
  const fs::path path = write_file("built.rad", rad_bytes(2, 1, false, {chunk}));
  LoadReport report;
  const GaussianScene scene = load_scene(path, {}, &report);
  EXPECT_EQ(report.format,
            "rad (1 chunk; center f16_lebytes, alpha r8, rgb f32, scales ln_f16, orientation f16, sh1 s8_delta)");
  ASSERT_EQ(scene.size(), 2u);
  ASSERT_EQ(scene.sh_degree, 1);
  for (int i = 0; i < 2; ++i) {
    SCOPED_TRACE(i);
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(scene.positions[3 * i + d], centers[i][d]);
      EXPECT_NEAR(scene.log_scales[3 * i + d], log_scales[i][d], 1e-6);
      EXPECT_NEAR(scene.sh[12 * i + d], (colours[i][d] - 0.5) / kShC0, 1e-5);
    }
    for (int k = 0; k < 3; ++k)
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(scene.sh[12 * i + 3 + 3 * k + ch], sh1_values[i][3 * k + ch] / 127.0 * 2, 1e-6);
    const double w = std::sqrt(std::max(0.0, 1 - 3 * double(xyz[i][0]) * xyz[i][0]));
    EXPECT_NEAR(scene.rotations[4 * i], w, 1e-6);
    EXPECT_NEAR(scene.rotations[4 * i + 1], xyz[i][0], 1e-6);
  }
  EXPECT_NEAR(sigmoid(scene.opacity_logits[0]), 0.2, 1e-6);
  EXPECT_NEAR(sigmoid(scene.opacity_logits[1]), 1.0, 1e-5);  // clamped to 1 - 1e-6 as every 8-bit opacity
  EXPECT_THROW(SplatLodTree::open(path), SceneError);        // no tree to cut
}

// A LOD tree of the given children (node 0 the root), its properties as float32 planes and its children as u16
// / u32 planes, in chunks of `chunk_size` nodes.
std::string tree_file(std::vector<uint16_t> counts, std::vector<uint32_t> starts, size_t chunk_size = 65536) {
  const size_t n = counts.size();
  std::vector<std::string> chunks;
  for (size_t base = 0; base < n; base += chunk_size) {
    const size_t m = std::min(chunk_size, n - base);
    std::string center, alpha, rgb, scales, orientation, child_count, child_start;
    for (size_t d = 0; d < 3; ++d)
      for (size_t i = base; i < base + m; ++i) append(center, float(3 * i + d));
    for (size_t i = base; i < base + m; ++i) append(alpha, float(i == 0 ? 1.5f : 0.5f));  // the root's is wider
    for (size_t i = 0; i < 3 * m; ++i) append(rgb, 0.5f);
    for (size_t i = 0; i < 3 * m; ++i) append(scales, 0.25f);
    for (size_t i = 0; i < 3 * m; ++i) append(orientation, 0.0f);
    for (size_t i = base; i < base + m; ++i) append(child_count, counts[i]);
    for (size_t i = base; i < base + m; ++i) append(child_start, starts[i]);
    chunks.push_back(chunk_bytes(base, m, 0, true,
                                 {{"center", "f32", center}, {"alpha", "f32", alpha}, {"rgb", "f32", rgb},
                                  {"scales", "f32", scales}, {"orientation", "f32", orientation},
                                  {"child_count", "u16", child_count}, {"child_start", "u32", child_start, {}, true}}));
  }
  return rad_bytes(n, 0, true, chunks, chunk_size);
}

TEST(Rad, ATreeBuiltFromTheLayoutCutsAndWidensItsInnerNodes) {
  const fs::path path = write_file("tree.rad", tree_file({2, 0, 0}, {1, 0, 0}));
  EXPECT_TRUE(is_lod_tree(path));
  const SplatLodTree tree = SplatLodTree::open(path);
  EXPECT_EQ(tree.nodes(), 3u);
  EXPECT_EQ(tree.level_nodes(0), (std::vector<uint32_t>{1, 2}));
  EXPECT_EQ(tree.level_nodes(tree.levels() - 1), std::vector<uint32_t>{0});
  // The root: alpha 1.5 is Spark's wider kernel, a = 4 x 1.5 - 3 = 3: drawn at opacity 1 with its scales
  // widened by exp((a^2 - 1) / e)^(1/3), and sized 2 x 0.25 x (1 + 0.7 (a - 1)) by the cut rule.
  const std::vector<uint32_t> root_node = {0};
  const GaussianScene root = tree.load(root_node);
  EXPECT_NEAR(sigmoid(root.opacity_logits[0]), 1.0, 1e-5);
  EXPECT_NEAR(root.log_scales[0], std::log(0.25) + (9.0 - 1.0) / std::exp(1.0) / 3, 1e-5);
  EXPECT_NEAR(tree.node_size(0), 2 * 0.25 * (1 + 0.7 * 2), 1e-6);
  EXPECT_NEAR(tree.node_size(1), 0.5, 1e-6);
  EXPECT_EQ(load_scene(path).size(), 2u);  // the leaves
  EXPECT_FALSE(is_lod_tree(kRadDir / "make_rad.sh"));
}

// A tree in chunks of two nodes, read part by part (a chunk at a time): the same report as the whole read (the
// file's splats and chunks, not its first chunk's) and the same leaves.
TEST(Rad, ATreeInSeveralChunksReadsPartByPartAsWhole) {
  const fs::path path = write_file("chunked_tree.rad", tree_file({2, 0, 2, 0, 0}, {1, 0, 3, 0, 0}, 2));
  LoadReport whole_report, parts_report;
  const GaussianScene whole = load_scene(path, {}, &whole_report);
  EXPECT_EQ(whole_report.format,
            "rad (3 chunks; LOD tree of 5 splats, its 3 leaves read; center f32, alpha f32, rgb f32, scales f32, "
            "orientation f32, child_count u16, child_start u32)");
  const SceneInParts in_parts = SceneInParts::open(path, {}, &parts_report);
  EXPECT_EQ(parts_report.format, whole_report.format);
  EXPECT_EQ(parts_report.gaussians_in_file, whole_report.gaussians_in_file);
  const GaussianScene loaded = in_parts.load();
  EXPECT_EQ(loaded.positions, whole.positions);
  EXPECT_EQ(loaded.log_scales, whole.log_scales);
  EXPECT_EQ(loaded.rotations, whole.rotations);
  EXPECT_EQ(loaded.opacity_logits, whole.opacity_logits);
  EXPECT_EQ(loaded.sh, whole.sh);
  // The leaves, nodes 1, 3 and 4: their centres are 3 i, 3 i + 1, 3 i + 2.
  EXPECT_EQ(whole.positions, (std::vector<float>{3, 4, 5, 9, 10, 11, 12, 13, 14}));
}

TEST(Rad, DamagedFilesAreRefusedNamingTheFileAndThePart) {
  // Trees that are no trees.
  testing::expect_scene_error(write_file("two_parents.rad", tree_file({2, 1, 0}, {1, 2, 0})),
                              {"two_parents.rad", "splat 2 has two parents"});
  testing::expect_scene_error(write_file("child_past_end.rad", tree_file({3, 0, 0}, {1, 0, 0})),
                              {"splat 0's children (3 from 1) are past the file's 3 splats"});
  testing::expect_scene_error(write_file("root_as_child.rad", tree_file({2, 1, 0}, {1, 0, 0})),
                              {"splat 0 has two parents"});
  // Spark's own file, damaged.
  const std::string good = testing::read_file(kRadDir / "playcanvas_test_64_sh3-lod.rad");
  testing::expect_scene_error(write_file("truncated.rad", good.substr(0, good.size() - 100)),
                              {"truncated.rad", "chunk 0", "runs past the end of the file"});
  testing::expect_scene_error(write_file("header_only.rad", good.substr(0, 40)),
                              {"header_only.rad", "header: its JSON", "runs past the end"});
  std::string zeroed_payload = good;
  std::fill(zeroed_payload.end() - 3000, zeroed_payload.end(), '\0');
  testing::expect_scene_error(write_file("zeroed_payload.rad", zeroed_payload), {"zeroed_payload.rad", "chunk 0 property"});
  std::string version = good;
  version.replace(version.find("\"version\": 1"), 12, "\"version\": 7");
  testing::expect_scene_error(write_file("version.rad", version), {"unsupported RAD version 7"});
  std::string count = good;
  count.replace(count.find("\"count\": 90"), 11, "\"count\": 91");
  testing::expect_scene_error(write_file("count.rad", count), {"chunk 0 holds splats 0 to 90", "0 to 91"});
  // A chunk file that is not beside the header.
  const fs::path lone = write_file("lonely/playcanvas_test_64_sh3_chunked-lod.rad",
                                   testing::read_file(kRadDir / "playcanvas_test_64_sh3_chunked-lod.rad"));
  testing::expect_scene_error(lone, {"playcanvas_test_64_sh3_chunked-lod-0.radc"});
  // Every byte flipped in turn (every 7th): each file loads or is refused with a SceneError, never worse.
  size_t refused = 0;
  for (size_t at = 0; at < good.size(); at += 7) {
    std::string flipped = good;
    flipped[at] = char(flipped[at] ^ 0x41);
    try {
      EXPECT_LE(load_scene(write_file("flipped.rad", flipped)).size(), 90u);
    } catch (const SceneError& error) {
      EXPECT_NE(std::string(error.what()).find("flipped.rad"), std::string::npos) << error.what();
      ++refused;
    }
  }
  EXPECT_GT(refused, 100u);
}

// tilesplat-render draws a level (--lod) or the cut a camera calls for under a budget (--splat-budget): the
// library's cut for the camera the EXR records, rendered, is the file's image.
TEST(RadCli, RendersALevelOrABudgetedCutAndTellsWhatItDrew) {
  const fs::path rad = kRadDir / "playcanvas_test_64_sh3-lod.rad";
  const fs::path out = testing::fresh_output_dir();
  const auto render = [&](const std::vector<std::string>& extra, const std::string& name) {
    std::vector<std::string> args = {rad.string(), "--cameras", testing::bundled_sh3_cameras().string(),
                                     "--width", "160", "-o", (out / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return testing::run_process("", TILESPLAT_RENDER_EXE, args);
  };
  const SplatLodTree tree = SplatLodTree::open(rad);
  const auto plain = render({}, "plain.exr");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const auto level0 = render({"--lod", "0"}, "level0.exr");
  ASSERT_EQ(level0.exit_code, 0) << level0.err;
  EXPECT_NE(level0.err.find("LOD tree of 90 splats (64 leaves, " + std::to_string(tree.levels()) +
                            " levels, SH3), level 0: 64 Gaussians"),
            std::string::npos)
      << level0.err;
  EXPECT_EQ(read_exr(out / "level0.exr").rgba, read_exr(out / "plain.exr").rgba);  // load_scene reads level 0
  const auto all = render({"--splat-budget", "1000"}, "all.exr");
  ASSERT_EQ(all.exit_code, 0) << all.err;
  EXPECT_EQ(read_exr(out / "all.exr").rgba, read_exr(out / "level0.exr").rgba);

  const auto some = render({"--splat-budget", "20", "--stats"}, "some.exr");
  ASSERT_EQ(some.exit_code, 0) << some.err;
  const std::optional<Camera> camera = read_exr_camera(out / "some.exr");
  ASSERT_TRUE(camera);
  const LodTreeCut cut = tree.select(*camera, 20);
  EXPECT_NE(some.out.find("lod tree splats                    " + std::to_string(cut.nodes.size())), std::string::npos)
      << some.out;
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(tree.load(cut.nodes));
  EXPECT_GE(compare_images(read_exr(out / "some.exr"), renderer.render(*camera)).psnr_db, 100.0);
  const auto level = render({"--lod", std::to_string(tree.levels() - 2)}, "coarse.exr");
  ASSERT_EQ(level.exit_code, 0) << level.err;
  // Coarser than the leaves: the image differs from level 0's, but it is the same scene.
  const double coarse_psnr = compare_images(read_exr(out / "coarse.exr"), read_exr(out / "level0.exr")).psnr_db;
  EXPECT_LT(coarse_psnr, 60.0);
  EXPECT_GT(coarse_psnr, 10.0);

  const auto no_level = render({"--lod", std::to_string(tree.levels())}, "no_level.exr");
  EXPECT_NE(no_level.exit_code, 0);
  EXPECT_NE(no_level.err.find("has " + std::to_string(tree.levels()) + " levels"), std::string::npos) << no_level.err;
  EXPECT_FALSE(fs::exists(out / "no_level.exr"));
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// tilesplat-bench --lod-curve on a tree: level 0, the levels that about halve it, then each budget; a budget
// past the leaves is level 0's image, and each budgeted row draws the library's cut for its view.
TEST(RadCli, BenchDrawsTheCurveOfLevelsAndBudgets) {
  const fs::path rad = kRadDir / "playcanvas_test_64_sh3-lod.rad";
  const fs::path out = testing::fresh_output_dir();
  const auto run = testing::run_process(
      "", TILESPLAT_BENCH_EXE,
      {rad.string(), "--cameras", testing::bundled_sh3_cameras().string(), "--views", "0", "--width", "160",
       "--lod-curve", "20,1000", "--warmup", "0", "--repeat", "1", "--csv", (out / "lod.csv").string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const SplatLodTree tree = SplatLodTree::open(rad);
  std::string table;  // the text table with its columns' runs of blanks as one
  for (const char c : run.out)
    if (c != ' ' || table.empty() || table.back() != ' ') table += c;
  EXPECT_NE(table.find("\nlevel 0 64 "), std::string::npos) << run.out;
  EXPECT_NE(table.find("\nlevel " + std::to_string(tree.levels() - 1) + " 1 "), std::string::npos) << run.out;
  const Camera view = resize_camera(load_cameras_json(testing::bundled_sh3_cameras())[0].camera, 160, 90);
  EXPECT_NE(table.find("\nbudget 20 " + std::to_string(tree.select(view, 20).nodes.size()) + " "), std::string::npos)
      << run.out;
  const std::string csv = testing::read_file(out / "lod.csv");
  // The last row, the budget of 1,000: all 64 leaves, level 0's image (PSNR inf).
  const std::string last = csv.substr(csv.rfind("\n", csv.size() - 2) + 1);
  EXPECT_NE(last.find(",1000,64.0,"), std::string::npos) << csv;
  EXPECT_NE(last.find(",inf,"), std::string::npos) << csv;
}

}  // namespace
}  // namespace tilesplat
