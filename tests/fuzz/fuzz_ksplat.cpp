// libFuzzer harness for the GaussianSplats3D .ksplat reader. The checks are fuzz_checks.h's check_reader; see
// tests/fuzz/README.md.
#include <cstddef>
#include <cstdint>

#include "fuzz_checks.h"
#include "scene/scene_readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return tilesplat::fuzz::check_reader(data, size, "fuzz-input",
                                       [](auto bytes, auto name, const auto& options, auto* report) {
                                         return tilesplat::detail::read_ksplat(bytes, name, options, report);
                                       });
}
