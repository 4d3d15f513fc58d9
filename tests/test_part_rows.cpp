// A scene read part by part (SceneInParts) gives each part the Gaussians load_scene reads, bit for bit:
// the gathers the renderer's parts make (frame/scene_parts.h PartSource), ascending and scattered through
// the file, from a binary PLY's mapped rows, an SPZ's packed bytes and a SOG's texels.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "frame/scene_parts.h"
#include "test_support.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_in_parts.h"

namespace tilesplat {
namespace {

// The Gaussians `indices` of `scene`, in that order.
GaussianScene pick(const GaussianScene& scene, const std::vector<uint32_t>& indices) {
  GaussianScene picked;
  picked.sh_degree = scene.sh_degree;
  const size_t sh = 3 * size_t(scene.sh_coefficients());
  for (uint32_t i : indices) {
    picked.positions.insert(picked.positions.end(), &scene.positions[3 * i], &scene.positions[3 * i + 3]);
    picked.log_scales.insert(picked.log_scales.end(), &scene.log_scales[3 * i], &scene.log_scales[3 * i + 3]);
    picked.rotations.insert(picked.rotations.end(), &scene.rotations[4 * i], &scene.rotations[4 * i + 4]);
    picked.opacity_logits.push_back(scene.opacity_logits[i]);
    picked.sh.insert(picked.sh.end(), &scene.sh[sh * i], &scene.sh[sh * (i + 1)]);
    if (scene.has_normals())
      picked.normals.insert(picked.normals.end(), &scene.normals[3 * i], &scene.normals[3 * i + 3]);
  }
  return picked;
}

void expect_parts_are_loaded(const std::filesystem::path& path) {
  SCOPED_TRACE(path.filename().string());
  const GaussianScene loaded = load_scene(path);
  const SceneInParts in_parts = SceneInParts::open(path);
  const PartSource source(in_parts);
  ASSERT_EQ(source.size(), loaded.size());
  EXPECT_EQ(source.sh_degree(), loaded.sh_degree);
  for (size_t i = 0; i < loaded.size(); i += 97) {
    const std::array<float, 3> position = source.position(i);
    EXPECT_EQ(std::vector<float>(position.begin(), position.end()),
              std::vector<float>(&loaded.positions[3 * i], &loaded.positions[3 * i + 3]))
        << "Gaussian " << i;
  }
  std::vector<uint32_t> every_seventh, first_and_last{0, uint32_t(loaded.size() - 1)}, none;
  for (uint32_t i = 3; i < loaded.size(); i += 7) every_seventh.push_back(i);
  for (const std::vector<uint32_t>& indices : {every_seventh, first_and_last, none}) {
    SCOPED_TRACE(std::to_string(indices.size()) + " Gaussians");
    testing::expect_identical_scenes(source.gather(indices), pick(loaded, indices));
  }
}

TEST(PartRows, EachPartIsTheLoadedScenesGaussians) {
  expect_parts_are_loaded(testing::bundled_playbot());
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const std::filesystem::path formats = testing::shared_scenes() / "formats";
  for (const std::string file : {"playbot_lod6_1873_sh2.v4.spz", "playbot_lod6_1873_sh2.v3.spz",
                                 "playcanvas_test_64_sh3.v4.spz", "playcanvas_test_64_sh3.v3.spz"})
    expect_parts_are_loaded(formats / file);
  expect_parts_are_loaded(testing::shared_scenes() / "biker_152746.spz");
  for (const std::string file : {"playbot_lod6_1873_sh2.sog", "playcanvas_test_64_sh3.sog",
                                 "playbot_lod6_1873_sh2_sog_unbundled/meta.json"})
    expect_parts_are_loaded(formats / file);
}

}  // namespace
}  // namespace tilesplat
