// glTF with an SPZ stream in a bufferView (engine/src/scene/gltf_reader.cpp), as the three Khronos drafts
// place it: KHR_gaussian_splatting_compression_spz_2 and its earlier name inside KHR_gaussian_splatting, and
// the first draft's KHR_spz_compression on the primitive. tests/data/gltf_spz holds one file of each, built
// from the drafts' text by make_spz_glb.py around the shared scenes' .spz files (no tool of the drafts' authors
// writes them here). Each must read as the .spz it wraps, land where the source PLY is (the drafts pack in
// glTF's axes), move with its node like accessor Gaussians, and refuse a stream that disagrees with the
// primitive or is damaged, naming the extension and the bufferView.
#include <gtest/gtest.h>

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
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kDir = fs::path(TILESPLAT_SOURCE_DIR) / "tests" / "data" / "gltf_spz";

struct Fixture {
  const char* glb;
  const char* spz;  // in the shared scenes' formats/
  const char* format;
};
constexpr Fixture kFixtures[] = {
    {"playcanvas_test_64_sh3.v3.spz_2.glb", "playcanvas_test_64_sh3.v3.spz",
     "glb (SPZ v3 in KHR_gaussian_splatting_compression_spz_2)"},
    {"playcanvas_test_64_sh3.v4.spz.glb", "playcanvas_test_64_sh3.v4.spz",
     "glb (SPZ v4 in KHR_gaussian_splatting_compression_spz)"},
    {"playcanvas_test_64_sh3.v3.khr_spz_compression.glb", "playcanvas_test_64_sh3.v3.spz",
     "glb (SPZ v3 in KHR_spz_compression)"}};

// A .glb's JSON and binary chunks (the fixtures have exactly those two).
struct Glb {
  json gltf;
  std::string bin;
};
Glb split(const std::string& bytes) {
  const auto u32 = [&](size_t at) {
    uint32_t v = 0;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  const size_t json_length = u32(12);
  const size_t bin_length = u32(20 + json_length);
  return {json::parse(bytes.substr(20, json_length)), bytes.substr(28 + json_length, bin_length)};
}

fs::path write(const std::string& name, const Glb& glb) {
  return testing::write_temp_file("gltf_spz", name, testing::glb_bytes(glb.gltf.dump(), glb.bin));
}

Glb spz_2_fixture() { return split(testing::read_file(kDir / kFixtures[0].glb)); }

TEST(GltfSpz, EachDraftReadsAsTheSpzStreamItHolds) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  for (const Fixture& fixture : kFixtures) {
    SCOPED_TRACE(fixture.glb);
    LoadReport report;
    const GaussianScene scene = load_scene(kDir / fixture.glb, {}, &report);
    const GaussianScene spz = load_scene(testing::shared_scenes() / "formats" / fixture.spz);
    EXPECT_EQ(report.format, fixture.format);
    EXPECT_EQ(report.version, "2.0");
    ASSERT_EQ(scene.size(), 64u);
    EXPECT_EQ(scene.sh_degree, 3);
    // glTF's axes and back are exact sign changes; a quaternion may come back negated (the same rotation).
    EXPECT_EQ(scene.positions, spz.positions);
    EXPECT_EQ(scene.log_scales, spz.log_scales);
    EXPECT_EQ(scene.opacity_logits, spz.opacity_logits);
    EXPECT_EQ(scene.sh, spz.sh);
    for (size_t i = 0; i < scene.size(); ++i) {
      const float* q = scene.rotations.data() + 4 * i;
      const float* s = spz.rotations.data() + 4 * i;
      const bool same = std::equal(q, q + 4, s);
      const bool negated = q[0] == -s[0] && q[1] == -s[1] && q[2] == -s[2] && q[3] == -s[3];
      EXPECT_TRUE(same || negated) << "Gaussian " << i;
    }
  }
}

// The drafts pack the stream from glTF's axes (SPZ's LUF option): read so, it lands on the source PLY, to
// SPZ's position step (12 fractional bits: half a step is 1.2e-4).
TEST(GltfSpz, TheStreamLandsWhereItsSourcePlyIs) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const GaussianScene source = load_scene(testing::shared_scenes() / "playcanvas_test_64_sh3.ply");
  const GaussianScene scene = load_scene(kDir / kFixtures[0].glb);
  ASSERT_EQ(scene.size(), source.size());
  float worst = 0;
  for (size_t k = 0; k < scene.positions.size(); ++k)
    worst = std::max(worst, std::fabs(scene.positions[k] - source.positions[k]));
  EXPECT_LE(worst, 0.5f / 4096 + 1e-6f);
}

TEST(GltfSpz, ANodeMovesTheStreamsGaussiansAsItMovesAccessorOnes) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  Glb glb = spz_2_fixture();
  glb.gltf["nodes"][0]["translation"] = {1.0, 2.0, 3.0};
  glb.gltf["nodes"][0]["scale"] = {2.0, 2.0, 2.0};
  const GaussianScene moved = load_scene(write("moved.glb", glb));
  const GaussianScene still = load_scene(kDir / kFixtures[0].glb);
  ASSERT_EQ(moved.size(), still.size());
  // In glTF's axes p' = 2 p + t; the engine's are glTF's turned 180 degrees about z: x and y of t flip.
  const double t[3] = {-1.0, -2.0, 3.0};
  for (size_t i = 0; i < still.size(); ++i)
    for (size_t a = 0; a < 3; ++a) {
      EXPECT_NEAR(moved.positions[3 * i + a], 2.0 * still.positions[3 * i + a] + t[a], 1e-5) << i << " " << a;
      EXPECT_NEAR(moved.log_scales[3 * i + a], still.log_scales[3 * i + a] + std::log(2.0), 1e-5);
    }
}

TEST(GltfSpz, APrimitiveThatDisagreesWithItsStreamIsRefused) {
  Glb glb = spz_2_fixture();
  const size_t position = glb.gltf["meshes"][0]["primitives"][0]["attributes"]["POSITION"];
  glb.gltf["accessors"][position]["count"] = 63;
  testing::expect_scene_error(write("count.glb", glb),
                              {"count.glb", "POSITION accessor says 63 Gaussians; the SPZ stream holds 64"});

  Glb first_draft = split(testing::read_file(kDir / kFixtures[2].glb));
  first_draft.gltf["meshes"][0]["primitives"][0]["extensions"]["KHR_spz_compression"]["numPoints"] = 65;
  testing::expect_scene_error(write("num_points.glb", first_draft),
                              {"KHR_spz_compression.numPoints says 65 Gaussians; the SPZ stream holds 64"});
}

TEST(GltfSpz, ADamagedStreamOrViewIsRefusedNamingTheExtensionAndTheView) {
  const Glb good = spz_2_fixture();
  const std::string extension = "KHR_gaussian_splatting_compression_spz_2";
  auto spz_of = [&](Glb& glb) -> json& {
    return glb.gltf["meshes"][0]["primitives"][0]["extensions"]["KHR_gaussian_splatting"]["extensions"][extension];
  };

  Glb truncated = good;  // the view ends half way through the stream
  truncated.gltf["bufferViews"][0]["byteLength"] = good.bin.size() / 2;
  testing::expect_scene_error(write("truncated.glb", truncated),
                              {"truncated.glb: " + extension + " stream in bufferView 0: "});

  Glb outside = good;  // the view runs past its buffer
  outside.gltf["bufferViews"][0]["byteOffset"] = 8;
  testing::expect_scene_error(write("outside.glb", outside),
                              {"outside.glb", "bufferView 0 of " + extension + " lies outside its buffer"});

  Glb no_view = good;
  spz_of(no_view)["bufferView"] = 5;
  testing::expect_scene_error(write("no_view.glb", no_view), {"index 5 is outside bufferViews (1)"});

  Glb not_an_index = good;
  spz_of(not_an_index)["bufferView"] = "0";
  testing::expect_scene_error(write("not_an_index.glb", not_an_index), {extension + ".bufferView is not an index"});

  Glb zeroed = good;  // the stream's bytes zeroed: no SPZ at all
  std::fill(zeroed.bin.begin(), zeroed.bin.end(), '\0');
  testing::expect_scene_error(write("zeroed.glb", zeroed), {"zeroed.glb: " + extension + " stream in bufferView 0: "});

  Glb unknown = good;  // a required extension this reader cannot decode is still refused
  unknown.gltf["extensionsRequired"].push_back("KHR_gaussian_splatting_compression_lgsc");
  testing::expect_scene_error(write("unknown.glb", unknown), {"KHR_gaussian_splatting_compression_lgsc"});
}

// Every byte of the stream flipped in turn (every 5th, to stay quick): each file loads or is refused with a
// SceneError naming it, never anything else.
TEST(GltfSpz, FlippedStreamBytesLoadOrAreRefused) {
  const Glb good = spz_2_fixture();
  size_t refused = 0, loaded = 0;
  for (size_t at = 0; at < good.bin.size(); at += 5) {
    Glb flipped = good;
    flipped.bin[at] = static_cast<char>(flipped.bin[at] ^ 0x5a);
    const fs::path path = write("flipped.glb", flipped);
    try {
      const GaussianScene scene = load_scene(path);
      EXPECT_LE(scene.size(), 64u);
      ++loaded;
    } catch (const SceneError& error) {
      EXPECT_NE(std::string(error.what()).find("flipped.glb"), std::string::npos) << error.what();
      ++refused;
    }
  }
  EXPECT_GT(refused, 0u);  // the gzip header and trailer at least
  EXPECT_GT(loaded + refused, 100u);
}

}  // namespace
}  // namespace tilesplat
