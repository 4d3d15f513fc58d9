// Replays the LOD set fuzzer's regression inputs (tests/fuzz/regressions/lod_set/) through the fuzzer's own
// harness, tests/fuzz/fuzz_lod_set.cpp, linked into this test: the same index beside the same chunk file
// and the same invariants (levels that add up and load, a budget that holds, or a SceneError naming the
// file), so that the gcc sanitizer build of CI replays them too, not only tests/fuzz/run.sh's clang build. A
// broken invariant aborts the process, which fails the test.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>

#include "test_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

TEST(LodSetFuzzRegressions, EveryInputPassesTheFuzzersInvariants) {
  tilesplat::testing::replay_fuzz_regressions("lod_set", 10, LLVMFuzzerTestOneInput);
}

}  // namespace
