// Replays the PLY fuzzer's regression inputs (tests/fuzz/regressions/ply) through the reader in the
// normal build: every one must load or throw a SceneError that names the file, never crash. The
// libFuzzer harness itself (tests/fuzz, clang only) checks more; this keeps the inputs guarded where
// clang is not installed, and under the gcc sanitizer build of CI.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "test_support.h"
#include "tilesplat/mapped_ply.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

std::filesystem::path regression_dir() {
  return std::filesystem::path(TILESPLAT_SOURCE_DIR) / "tests" / "fuzz" / "regressions" / "ply";
}

std::vector<std::filesystem::path> regression_inputs() {
  std::vector<std::filesystem::path> files;
  if (std::filesystem::is_directory(regression_dir()))
    for (const auto& entry : std::filesystem::directory_iterator(regression_dir()))
      if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::string read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void expect_well_formed(const GaussianScene& scene) {
  const size_t n = scene.size();
  EXPECT_EQ(scene.positions.size(), 3 * n);
  EXPECT_EQ(scene.log_scales.size(), 3 * n);
  EXPECT_EQ(scene.rotations.size(), 4 * n);
  EXPECT_EQ(scene.sh.size(), 3 * static_cast<size_t>(scene.sh_coefficients()) * n);
  EXPECT_TRUE(scene.normals.empty() || scene.normals.size() == 3 * n);
}

// The outcome of one read: the scene's size, or the error message.
struct Outcome {
  std::optional<size_t> loaded;
  std::string error;
  bool operator==(const Outcome&) const = default;
};

template <typename Read>
Outcome outcome_of(const std::string& name, Read read) {
  Outcome outcome;
  try {
    const GaussianScene scene = read();
    expect_well_formed(scene);
    outcome.loaded = scene.size();
  } catch (const SceneError& error) {
    outcome.error = error.what();
    EXPECT_EQ(outcome.error.rfind(name + ": ", 0), 0u) << "the error does not name the file: " << outcome.error;
  } catch (const std::exception& error) {
    ADD_FAILURE() << "an exception other than SceneError: " << error.what();
  }
  return outcome;
}

TEST(PlyFuzzRegressions, EveryInputLoadsOrThrowsSceneError) {
  const std::vector<std::filesystem::path> files = regression_inputs();
  ASSERT_FALSE(files.empty()) << "no regression inputs in " << regression_dir();
  for (const std::filesystem::path& file : files) {
    SCOPED_TRACE(file.filename().string());
    const std::string bytes = read_bytes(file);
    const auto data = std::as_bytes(std::span(bytes.data(), bytes.size()));
    for (const bool strict : {false, true}) {
      LoadOptions options;
      options.strict = strict;
      const std::string name = file.string();
      // From memory and from the file: the same outcome, to the message.
      const Outcome from_memory = outcome_of(name, [&] { return parse_ply(data, name, options); });
      const Outcome from_file = outcome_of(name, [&] { return load_ply(file, options); });
      EXPECT_EQ(from_memory, from_file) << (strict ? "strict: " : "") << from_memory.error << " vs "
                                        << from_file.error;
    }
  }
}

// Read part by part (MappedPly), every input is refused with a SceneError naming the file (an ASCII or a
// compressed PLY among them), or holds the Gaussians load_ply reads, bit for bit.
TEST(PlyFuzzRegressions, EveryInputReadPartByPartIsRefusedOrTheLoadedScene) {
  const std::vector<std::filesystem::path> files = regression_inputs();
  ASSERT_FALSE(files.empty()) << "no regression inputs in " << regression_dir();
  size_t read_in_parts = 0;
  for (const std::filesystem::path& file : files) {
    SCOPED_TRACE(file.filename().string());
    const std::string name = file.string();
    std::optional<GaussianScene> parts;
    outcome_of(name, [&] {  // a SceneError must name the file
      parts = MappedPly::open(file).load();
      return *parts;
    });
    if (!parts) continue;
    ++read_in_parts;
    const GaussianScene loaded = load_ply(file);
    EXPECT_EQ(parts->sh_degree, loaded.sh_degree);
    EXPECT_EQ(parts->positions, loaded.positions);
    EXPECT_EQ(parts->log_scales, loaded.log_scales);
    EXPECT_EQ(parts->rotations, loaded.rotations);
    EXPECT_EQ(parts->opacity_logits, loaded.opacity_logits);
    EXPECT_EQ(parts->sh, loaded.sh);
    EXPECT_EQ(parts->normals, loaded.normals);
  }
  EXPECT_GT(read_in_parts, 0u) << "no regression input is a binary PLY that reads";
}

TEST(PlyFuzzRegressions, ParsePlyFromMemoryMatchesLoadPly) {
  const std::filesystem::path path = testing::bundled_sh3();
  const std::string bytes = read_bytes(path);
  LoadReport from_memory_report;
  const GaussianScene from_memory =
      parse_ply(std::as_bytes(std::span(bytes.data(), bytes.size())), "in-memory.ply", {}, &from_memory_report);
  const GaussianScene from_file = load_ply(path);
  EXPECT_EQ(from_memory.sh_degree, from_file.sh_degree);
  EXPECT_EQ(from_memory.positions, from_file.positions);
  EXPECT_EQ(from_memory.sh, from_file.sh);
  EXPECT_EQ(from_memory.rotations, from_file.rotations);
  EXPECT_EQ(from_memory_report.format, "ply binary_little_endian");

  try {
    parse_ply({}, "in-memory.ply");
    ADD_FAILURE() << "an empty buffer loaded";
  } catch (const SceneError& error) {
    EXPECT_STREQ(error.what(), "in-memory.ply: empty file, not a PLY file");
  }
}

}  // namespace
}  // namespace tilesplat
