// Replays the regression inputs of the format fuzzers (tests/fuzz/regressions/<reader>/, all but
// ply, which test_ply_fuzz_regressions.cpp replays) through load_scene in the normal build: every
// one must load a well-formed scene or throw a SceneError that names the file, never crash, under
// the gcc sanitizer build of CI as well as the clang fuzzers.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

namespace fs = std::filesystem;

class SceneFuzzRegressions : public ::testing::TestWithParam<std::string> {};

TEST_P(SceneFuzzRegressions, EveryInputLoadsOrNamesItsProblem) {
  const fs::path dir = fs::path(TILESPLAT_SOURCE_DIR) / "tests" / "fuzz" / "regressions" / GetParam();
  std::vector<fs::path> inputs;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file()) inputs.push_back(entry.path());
  std::sort(inputs.begin(), inputs.end());
  ASSERT_FALSE(inputs.empty()) << "no regression inputs in " << dir;
  for (const fs::path& input : inputs) {
    SCOPED_TRACE(input.filename().string());
    try {
      LoadReport report;
      const GaussianScene scene = load_scene(input, {}, &report);
      const size_t n = scene.size();
      EXPECT_EQ(scene.positions.size(), 3 * n);
      EXPECT_EQ(scene.rotations.size(), 4 * n);
      EXPECT_EQ(scene.sh.size(), 3 * static_cast<size_t>(scene.sh_coefficients()) * n);
      EXPECT_EQ(n + report.dropped, report.gaussians_in_file);
    } catch (const SceneError& error) {
      EXPECT_TRUE(std::string(error.what()).starts_with(input.string() + ": ")) << error.what();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Readers, SceneFuzzRegressions,
                         ::testing::Values("splat", "ksplat", "spz", "sog", "compressed_ply", "gltf"));

}  // namespace
}  // namespace tilesplat
