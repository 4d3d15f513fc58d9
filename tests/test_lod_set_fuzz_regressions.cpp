// Replays the LOD set fuzzer's regression inputs (tests/fuzz/regressions/lod_set/) through the fuzzer's own
// harness, tests/fuzz/fuzz_lod_set.cpp, linked into this test: the same index beside the same chunk file
// and the same invariants (levels that add up and load, a budget that holds, or a SceneError naming the
// file), so that the gcc sanitizer build of CI replays them too, not only tests/fuzz/run.sh's clang build. A
// broken invariant aborts the process, which fails the test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

namespace fs = std::filesystem;

TEST(LodSetFuzzRegressions, EveryInputPassesTheFuzzersInvariants) {
  const fs::path dir = fs::path(TILESPLAT_SOURCE_DIR) / "tests" / "fuzz" / "regressions" / "lod_set";
  std::vector<fs::path> inputs;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file()) inputs.push_back(entry.path());
  std::sort(inputs.begin(), inputs.end());
  ASSERT_GE(inputs.size(), 10u) << "the LOD set regressions in " << dir << " are missing";
  for (const fs::path& input : inputs) {
    SCOPED_TRACE(input.filename().string());
    std::ifstream file(input, std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(file)),
                                     std::istreambuf_iterator<char>());
    ASSERT_FALSE(bytes.empty());
    EXPECT_EQ(LLVMFuzzerTestOneInput(bytes.data(), bytes.size()), 0);
  }
}

}  // namespace
