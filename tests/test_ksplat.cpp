// GaussianSplats3D's .ksplat (engine/src/scene/ksplat_reader.cpp) against the PLY it was written from. The
// files in tests/data/ksplat are the viewer's own generator's output (tests/data/ksplat/make_ksplat.mjs: npm
// @mkkellogg/gaussian-splats-3d 0.4.7 under node) for playcanvas_test_64_sh3.ply at compression levels 0, 1
// and 2, SH degree 0 and 2. Each Gaussian is checked against its source as the generator quantizes it
// (computed here on its own), each file rendered against the source's image and its own float64
// reference; damaged files are refused naming the file and the broken part.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "process_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_in_parts.h"

namespace tilesplat {
namespace {

namespace fs = std::filesystem;

const fs::path kKsplatDir = fs::path(TILESPLAT_SOURCE_DIR) / "tests" / "data" / "ksplat";
constexpr double kShC0 = 0.28209479177387814;

fs::path ksplat_file(int level, int sh_degree) {
  return kKsplatDir / ("playcanvas_test_64_sh3_l" + std::to_string(level) + "_sh" + std::to_string(sh_degree) +
                       ".ksplat");
}

fs::path write_file(const std::string& name, const std::string& bytes) {
  return testing::write_temp_file("ksplat", name, bytes);
}

double sigmoid(double x) { return 1 / (1 + std::exp(-x)); }

// What the generator stores of a DC coefficient or an opacity: floor(255 v) clamped to a byte, read back
// as byte / 255 (GaussianSplats3D's INRIAV1PlyParser).
double byte_of(double v) { return std::clamp(std::floor(v * 255), 0.0, 255.0) / 255; }

// The source Gaussian nearest to `position`: the generator reorders the Gaussians by bucket.
size_t nearest(const GaussianScene& scene, const float* position) {
  size_t best = 0;
  double best_d = INFINITY;
  for (size_t i = 0; i < scene.size(); ++i) {
    double d = 0;
    for (size_t a = 0; a < 3; ++a) d += std::pow(double(scene.positions[3 * i + a]) - position[a], 2);
    if (d < best_d) best_d = d, best = i;
  }
  return best;
}

// How far each attribute of a level may be from its source: level 0 stores float32 (the rounding of the
// normalized quaternion), levels 1 and 2 float16 (11 bits) and positions in steps of
// block / 2 / 32767 (5 / 65534, half a step 3.8e-5) about their bucket's centre; level 2 SH floored to
// 255 steps of the file's range.
struct LevelTolerance {
  double position, rotation, sh_rest;
};
LevelTolerance tolerance_of(int level, double sh_range) {
  if (level == 0) return {0, 1e-6, 0};
  return {4e-5, 1e-3, level == 1 ? 2e-3 : sh_range / 255 + 1e-6};
}

class KsplatFiles : public ::testing::TestWithParam<std::array<int, 2>> {};

TEST_P(KsplatFiles, EachGaussianIsItsSourceAsTheGeneratorQuantizesIt) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const auto [level, sh_degree] = GetParam();
  const GaussianScene source = load_scene(testing::shared_scenes() / "playcanvas_test_64_sh3.ply");
  LoadReport report;
  const GaussianScene scene = load_scene(ksplat_file(level, sh_degree), {}, &report);
  EXPECT_EQ(report.format.find("ksplat level " + std::to_string(level)), 0u) << report.format;
  EXPECT_EQ(report.version, "0.1");
  ASSERT_EQ(scene.size(), source.size());
  ASSERT_EQ(scene.sh_degree, sh_degree);
  // Level 2's 8-bit SH span the range in the file's header (the generator's minimum and maximum of the
  // source's SH beyond DC), floored to 255 steps: a value outside it is clamped.
  const std::string bytes = testing::read_file(ksplat_file(level, sh_degree));
  float sh_min = 0, sh_max = 0;
  std::memcpy(&sh_min, bytes.data() + 36, 4);
  std::memcpy(&sh_max, bytes.data() + 40, 4);
  const LevelTolerance tolerance = tolerance_of(level, double(sh_max) - double(sh_min));
  std::vector<bool> matched(source.size(), false);
  double worst_position = 0, worst_sh = 0;
  for (size_t i = 0; i < scene.size(); ++i) {
    const size_t s = nearest(source, &scene.positions[3 * i]);
    EXPECT_FALSE(matched[s]) << "source Gaussian " << s << " matched twice";
    matched[s] = true;
    for (size_t a = 0; a < 3; ++a) {
      const double dp = std::abs(double(scene.positions[3 * i + a]) - source.positions[3 * s + a]);
      worst_position = std::max(worst_position, dp);
      EXPECT_LE(dp, tolerance.position) << "Gaussian " << i << " position " << a;
      if (level == 0) {
        EXPECT_NEAR(scene.log_scales[3 * i + a], source.log_scales[3 * s + a],
                    1e-6 * std::max(1.0, std::abs(double(source.log_scales[3 * s + a]))))
            << "Gaussian " << i << " log scale " << a;
      } else {  // float16 of the linear scale: 11 bits, or steps of 2^-24 below 2^-14 (subnormal)
        const double linear = std::exp(double(source.log_scales[3 * s + a]));
        EXPECT_NEAR(std::exp(double(scene.log_scales[3 * i + a])), linear, std::max(linear * 1e-3, 0x1p-24))
            << "Gaussian " << i << " scale " << a;
      }
    }
    for (size_t a = 0; a < 4; ++a)
      EXPECT_NEAR(scene.rotations[4 * i + a], source.rotations[4 * s + a], tolerance.rotation)
          << "Gaussian " << i << " rotation " << a;
    EXPECT_NEAR(sigmoid(scene.opacity_logits[i]), byte_of(sigmoid(source.opacity_logits[s])), 2e-6)
        << "Gaussian " << i;
    for (size_t c = 0; c < 3; ++c)
      EXPECT_NEAR(scene.sh[i * size_t(scene.sh_coefficients()) * 3 + c],
                  (byte_of(0.5 + kShC0 * source.sh[s * 16 * 3 + c]) - 0.5) / kShC0, 1e-5)
          << "Gaussian " << i << " DC " << c;
    for (int k = 1; k < scene.sh_coefficients(); ++k)
      for (size_t c = 0; c < 3; ++c) {
        double expected = source.sh[(s * 16 + size_t(k)) * 3 + c];
        if (level == 2) expected = std::clamp(expected, double(sh_min), double(sh_max));
        const double d =
            std::abs(double(scene.sh[(i * size_t(scene.sh_coefficients()) + size_t(k)) * 3 + c]) - expected);
        worst_sh = std::max(worst_sh, d);
        EXPECT_LE(d, tolerance.sh_rest) << "Gaussian " << i << " SH " << k << " channel " << c;
      }
  }
  std::printf("[ measure  ] ksplat level %d, SH %d: worst position %.2e, worst SH beyond DC %.2e\n", level,
              sh_degree, worst_position, worst_sh);
}

// Rendered on the GPU: against the float64 reference of the file's own Gaussians (the reader and the
// renderer), and against the source PLY's image (what the format keeps of the scene).
TEST_P(KsplatFiles, RendersAsItsReferenceAndNearItsSource) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const auto [level, sh_degree] = GetParam();
  const GaussianScene scene = load_scene(ksplat_file(level, sh_degree));
  const GaussianScene source = load_scene(testing::shared_scenes() / "playcanvas_test_64_sh3.ply");
  const Camera camera = resize_camera(
      load_cameras_json(testing::shared_scenes() / "cameras" / "playcanvas_test_64_sh3.json")[0].camera, 240, 135);
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(scene);
  const RenderImage image = renderer.render(camera);
  testing::expect_matches_reference(image, render_reference(scene, camera, RenderSettings{}), 2e-5,
                                    "ksplat level " + std::to_string(level));
  // The source at the SH degree the file keeps: its first (degree + 1)^2 coefficients.
  const GaussianScene truncated = testing::with_sh_degree(source, sh_degree);
  renderer.set_scene(truncated);
  const ImageDifference d = compare_images(image, renderer.render(camera));
  std::printf("[ measure  ] ksplat level %d, SH %d, %zu bytes: %.1f dB against the source PLY (max abs %.2e)\n",
              level, sh_degree, size_t(fs::file_size(ksplat_file(level, sh_degree))), d.psnr_db, d.max_abs);
  // The format's own loss: 8-bit colour and opacity at every level (floored, 1/255 at most), float16 and
  // 16-bit positions above level 0, 8-bit SH at level 2.
  EXPECT_GE(d.psnr_db, 40.0);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// Read part by part (SceneInParts: each part's splats decoded from the mapped file): its Gaussians are the
// whole read's, bit for bit (no NaN in these files, so == is bitwise here), and a frame rendered in parts
// under a budget is the whole frame.
TEST_P(KsplatFiles, ReadPartByPartIsTheWholeRead) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const auto [level, sh_degree] = GetParam();
  const fs::path path = ksplat_file(level, sh_degree);
  const GaussianScene whole = load_scene(path);
  EXPECT_EQ(SceneInParts::whole_scene_bytes(path),
            whole.size() * (11 + 3 * uint64_t(whole.sh_coefficients())) * sizeof(float));
  testing::expect_read_in_parts_as_whole(
      path, resize_camera(
                load_cameras_json(testing::shared_scenes() / "cameras" / "playcanvas_test_64_sh3.json")[0].camera,
                64, 48));
}

INSTANTIATE_TEST_SUITE_P(Levels, KsplatFiles,
                         ::testing::Values(std::array<int, 2>{0, 0}, std::array<int, 2>{0, 2},
                                           std::array<int, 2>{1, 0}, std::array<int, 2>{1, 2},
                                           std::array<int, 2>{2, 0}, std::array<int, 2>{2, 2}),
                         [](const auto& param_info) {
                           return "Level" + std::to_string(param_info.param[0]) + "Sh" +
                                  std::to_string(param_info.param[1]);
                         });

void put_u32(std::string& bytes, size_t at, uint32_t value) { std::memcpy(bytes.data() + at, &value, 4); }
void put_u16(std::string& bytes, size_t at, uint16_t value) { std::memcpy(bytes.data() + at, &value, 2); }

TEST(Ksplat, DamagedFilesAreRefusedNamingThePart) {
  const std::string good = testing::read_file(ksplat_file(1, 2));
  ASSERT_GT(good.size(), 5120u);
  testing::expect_scene_error(write_file("header.ksplat", good.substr(0, 1000)), {"less than its 4096-byte header"});
  testing::expect_scene_error(write_file("sections.ksplat", good.substr(0, 4500)), {"section headers"});
  testing::expect_scene_error(write_file("splats.ksplat", good.substr(0, good.size() - 7)), {"section 0", "truncated"});
  std::string version = good;
  version[1] = 0;
  testing::expect_scene_error(write_file("version.ksplat", version), {"version 0.0"});
  std::string level = good;
  put_u16(level, 20, 3);
  testing::expect_scene_error(write_file("level.ksplat", level), {"compression level 3"});
  std::string degree = good;
  put_u16(degree, 4096 + 40, 3);
  testing::expect_scene_error(write_file("degree.ksplat", degree), {"section 0", "SH degree 3"});
  std::string buckets = good;
  put_u32(buckets, 4096 + 32, 1000);  // full buckets
  testing::expect_scene_error(write_file("buckets.ksplat", buckets), {"section 0", "buckets"});
  std::string count = good;
  put_u32(count, 12, 65);
  testing::expect_scene_error(write_file("count.ksplat", count), {"declares 65 splats"});
  std::string block = good;
  put_u32(block, 4096 + 16, 0);
  testing::expect_scene_error(write_file("block.ksplat", block), {"block size"});
  // A zeroed file has no version: not a ksplat by its content, and refused as one by its extension.
  testing::expect_scene_error(write_file("zeros.ksplat", std::string(good.size(), '\0')), {"version 0.0"});
  testing::expect_scene_error(write_file("zeros.bin", std::string(good.size(), '\0')), {"unrecognized scene format"});
}

// Any single flipped byte gives a scene or one SceneError, never a crash (the fuzzer goes further).
TEST(Ksplat, FlippedBytesLoadOrFailCleanly) {
  const std::string good = testing::read_file(ksplat_file(2, 2));
  size_t loaded = 0, refused = 0;
  for (size_t at = 0; at < good.size(); at += 37) {
    std::string flipped = good;
    flipped[at] = char(~flipped[at]);
    try {
      const GaussianScene scene = load_scene(write_file("flipped.ksplat", flipped));
      EXPECT_LE(scene.size(), 64u);
      ++loaded;
    } catch (const SceneError& error) {
      EXPECT_NE(std::string(error.what()).find("flipped.ksplat"), std::string::npos) << error.what();
      ++refused;
    }
  }
  EXPECT_GT(loaded, 0u);
  EXPECT_GT(refused, 0u);
}

// Read part by part, a .ksplat is told by its header like the rest: a JSON that is no SOG meta.json (a glTF)
// is still refused as a format read whole, not taken for a .ksplat.
TEST(Ksplat, PartByPartTakesOnlyAKsplatForOne) {
  const fs::path gltf = write_file("scene.gltf", R"({"asset": {"version": "2.0"}})");
  try {
    SceneInParts::open(gltf);
    ADD_FAILURE() << "a glTF opened part by part";
  } catch (const SceneError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("only these are read part by part"), std::string::npos) << message;
    EXPECT_EQ(message.find("not a whole .ksplat"), std::string::npos) << message;
  }
  EXPECT_EQ(SceneInParts::open(ksplat_file(0, 0)).size(), 64u);
}

TEST(Ksplat, ChosenByContentWhateverTheName) {
  const std::string good = testing::read_file(ksplat_file(0, 0));
  LoadReport report;
  const GaussianScene scene = load_scene(write_file("renamed.bin", good), {}, &report);
  EXPECT_EQ(scene.size(), 64u);
  EXPECT_EQ(report.format, "ksplat level 0 (float32)");
}

}  // namespace
}  // namespace tilesplat
