// libFuzzer harness for the PLY reader (parse_ply, the in-memory core of load_ply).
//
// Every input must either load or throw SceneError: any other exception, a sanitizer report, a
// timeout or an allocation over -rss_limit_mb is a finding. A scene that loads must also be
// well-formed (consistent array sizes, finite values, unit quaternions), and the strict mode must
// agree with the default one. See tests/fuzz/README.md.
#include <cstddef>
#include <cstdint>

#include "fuzz_checks.h"
#include "tilesplat/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return tilesplat::fuzz::check_reader(data, size, "fuzz-input.ply",
                                       [](auto bytes, auto name, const auto& options, auto* report) {
                                         return tilesplat::parse_ply(bytes, name, options, report);
                                       });
}
