// write_ply (tilesplat/scene.h): the trainer's PLY that every viewer reads, read back to the bit (the
// quaternions normalized again) and rendering the same frame; its refusals leave no file.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "test_support.h"
#include "tilesplat/image.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

namespace fs = std::filesystem;

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

TEST(WritePly, ATrainedSceneReadsBackToTheBitAndRendersTheSameFrame) {
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const fs::path path = testing::temp_dir() / "written_playbot.ply";
  write_ply(scene, path);
  const GaussianScene back = load_scene(path);
  ASSERT_EQ(back.size(), scene.size());
  EXPECT_EQ(back.sh_degree, scene.sh_degree);
  EXPECT_TRUE(same_bits(back.positions, scene.positions));
  EXPECT_TRUE(same_bits(back.log_scales, scene.log_scales));
  EXPECT_TRUE(same_bits(back.opacity_logits, scene.opacity_logits));
  EXPECT_TRUE(same_bits(back.sh, scene.sh));
  EXPECT_TRUE(same_bits(back.normals, scene.normals));
  // The quaternions are written as the scene holds them and normalized again on load, which moves some by
  // a float step (normalization is not a fixed point in float).
  for (size_t k = 0; k < scene.rotations.size(); ++k)
    EXPECT_NEAR(back.rotations[k], scene.rotations[k], 2e-7f) << k;
  Renderer& renderer = testing::validated_renderer();
  const Camera camera = orbit_camera(scene, 160, 90);
  const RenderImage before = renderer.render(scene, camera);
  const RenderImage after = renderer.render(back, camera);
  EXPECT_GT(compare_images(before, after).psnr_db, 100.0);
  fs::remove(path);
}

TEST(WritePly, EveryValueOfAnyDegreeAndNormalsIsWrittenAsItIs) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-3.0f, 3.0f);
  for (int degree = 0; degree <= 3; ++degree) {
    GaussianScene scene;
    scene.sh_degree = degree;
    const size_t n = 37, k = size_t((degree + 1) * (degree + 1));
    for (size_t i = 0; i < 3 * n; ++i) {
      scene.positions.push_back(unit(rng));
      scene.log_scales.push_back(unit(rng));
      scene.normals.push_back(unit(rng));
    }
    for (size_t i = 0; i < 4 * n; ++i) scene.rotations.push_back(unit(rng));
    for (size_t i = 0; i < n; ++i) scene.opacity_logits.push_back(unit(rng));
    for (size_t i = 0; i < n * k * 3; ++i) scene.sh.push_back(unit(rng));
    const fs::path path = testing::temp_dir() / ("written_sh" + std::to_string(degree) + ".ply");
    write_ply(scene, path);
    const GaussianScene back = load_ply(path);
    EXPECT_EQ(back.sh_degree, degree);
    EXPECT_TRUE(same_bits(back.positions, scene.positions)) << degree;
    EXPECT_TRUE(same_bits(back.log_scales, scene.log_scales)) << degree;
    EXPECT_TRUE(same_bits(back.normals, scene.normals)) << degree;
    EXPECT_TRUE(same_bits(back.opacity_logits, scene.opacity_logits)) << degree;
    EXPECT_TRUE(same_bits(back.sh, scene.sh)) << degree;  // f_rest's channel-major order undone
    // The stored quaternions come back normalized, as every reader gives them.
    for (size_t i = 0; i < n; ++i) {
      const float* q = &scene.rotations[4 * i];
      const double norm =
          std::sqrt(double(q[0]) * q[0] + double(q[1]) * q[1] + double(q[2]) * q[2] + double(q[3]) * q[3]);
      for (size_t c = 0; c < 4; ++c) EXPECT_NEAR(back.rotations[4 * i + c], q[c] / norm, 1e-7) << i;
    }
    fs::remove(path);
  }
}

TEST(WritePly, RefusesWhatItCannotWriteLeavingNoFile) {
  GaussianScene scene = load_scene(testing::bundled_sh3());
  const fs::path missing = testing::temp_dir() / "no_such_directory" / "scene.ply";
  const std::string message = testing::error_of([&] { write_ply(scene, missing); });
  EXPECT_NE(message.find("no_such_directory"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(missing));
  scene.log_scales.pop_back();
  const fs::path path = testing::temp_dir() / "inconsistent.ply";
  EXPECT_THROW(write_ply(scene, path), std::invalid_argument);
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
}  // namespace tilesplat
