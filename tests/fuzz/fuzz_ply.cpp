// libFuzzer harness for the PLY reader (parse_ply, the in-memory core of load_ply).
//
// Every input must either load or throw SceneError: any other exception, a sanitizer report, a
// timeout or an allocation over -rss_limit_mb is a finding. A scene that loads must also be
// well-formed (consistent array sizes, finite values, unit quaternions), and the strict mode must
// agree with the default one. See tests/fuzz/README.md.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>
#include <vector>

#include "fuzz_checks.h"
#include "tilesplat/scene.h"

using tilesplat::fuzz::check_scene;


extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto bytes = std::as_bytes(std::span(data, size));
  constexpr const char* kName = "fuzz-input.ply";

  bool loaded = false;
  tilesplat::GaussianScene scene;
  tilesplat::LoadReport report;
  try {
    scene = tilesplat::parse_ply(bytes, kName, {}, &report);
    loaded = true;
  } catch (const tilesplat::SceneError& error) {
    // The message must name the file.
    FUZZ_CHECK(std::string(error.what()).starts_with(std::string(kName) + ": "));
  }
  if (loaded) check_scene(scene, report);

  // Strict mode fails exactly when the default mode drops something, and otherwise loads the same.
  tilesplat::LoadOptions strict;
  strict.strict = true;
  try {
    const tilesplat::GaussianScene strict_scene = tilesplat::parse_ply(bytes, kName, strict);
    FUZZ_CHECK(loaded && report.dropped == 0);
    FUZZ_CHECK(strict_scene.size() == scene.size() && strict_scene.positions == scene.positions &&
               strict_scene.sh == scene.sh && strict_scene.rotations == scene.rotations);
  } catch (const tilesplat::SceneError&) {
    FUZZ_CHECK(!loaded || report.dropped > 0);
  }
  return 0;
}
