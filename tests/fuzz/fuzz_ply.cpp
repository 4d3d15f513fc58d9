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

#include "tilesplat/scene.h"

namespace {

[[noreturn]] void invariant_failed(const char* what) {
  std::fprintf(stderr, "fuzz_ply: invariant violated: %s\n", what);
  std::abort();
}

#define FUZZ_CHECK(condition) \
  do {                        \
    if (!(condition)) invariant_failed(#condition); \
  } while (0)

bool all_finite(const std::vector<float>& values) {
  for (const float value : values)
    if (!std::isfinite(value)) return false;
  return true;
}

void check_scene(const tilesplat::GaussianScene& scene, const tilesplat::LoadReport& report) {
  const size_t n = scene.size();
  FUZZ_CHECK(scene.sh_degree >= 0 && scene.sh_degree <= 3);
  FUZZ_CHECK(scene.positions.size() == 3 * n);
  FUZZ_CHECK(scene.log_scales.size() == 3 * n);
  FUZZ_CHECK(scene.rotations.size() == 4 * n);
  FUZZ_CHECK(scene.sh.size() == 3 * static_cast<size_t>(scene.sh_coefficients()) * n);
  FUZZ_CHECK(scene.normals.empty() || scene.normals.size() == 3 * n);
  FUZZ_CHECK(n + report.dropped == report.gaussians_in_file);
  size_t dropped = 0;
  for (const tilesplat::DroppedProperty& entry : report.dropped_by_property) dropped += entry.count;
  FUZZ_CHECK(dropped == report.dropped);
  FUZZ_CHECK(report.dropped == 0 || !report.summary().empty());
  FUZZ_CHECK(all_finite(scene.positions) && all_finite(scene.log_scales) && all_finite(scene.rotations) &&
             all_finite(scene.opacity_logits) && all_finite(scene.sh) && all_finite(scene.normals));
  for (size_t i = 0; i < n; ++i) {
    const float* q = scene.rotations.data() + 4 * i;
    const double norm = std::sqrt(static_cast<double>(q[0]) * q[0] + static_cast<double>(q[1]) * q[1] +
                                  static_cast<double>(q[2]) * q[2] + static_cast<double>(q[3]) * q[3]);
    FUZZ_CHECK(std::fabs(norm - 1.0) < 1e-5);
  }
  const tilesplat::Bounds bounds = tilesplat::compute_bounds(scene);
  FUZZ_CHECK(!(bounds.radius < 0));
}

}  // namespace

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
