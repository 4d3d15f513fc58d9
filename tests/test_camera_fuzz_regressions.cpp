// Replays the camera fuzzer's regression inputs (tests/fuzz/regressions/cameras/) through the fuzzer's
// own harness, tests/fuzz/fuzz_cameras.cpp, linked into this test: the same reader choice by the first
// byte and the same invariants (a camera the renderer accepts, or a SceneError naming the file), so that
// the gcc sanitizer build of CI replays them too, not only tests/fuzz/run.sh's clang build. A broken
// invariant aborts the process, which fails the test.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>

#include "test_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

TEST(CameraFuzzRegressions, EveryInputPassesTheFuzzersInvariants) {
  tilesplat::testing::replay_fuzz_regressions("cameras", 10, LLVMFuzzerTestOneInput);
}

}  // namespace
