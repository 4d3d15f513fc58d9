// Invariants every scene reader's output must hold, shared by the libFuzzer harnesses.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/scene.h"

namespace tilesplat::fuzz {

[[noreturn]] inline void invariant_failed(const char* what) {
  std::fprintf(stderr, "fuzz: invariant violated: %s\n", what);
  std::abort();
}

#define FUZZ_CHECK(condition)                                          \
  do {                                                                 \
    if (!(condition)) ::tilesplat::fuzz::invariant_failed(#condition); \
  } while (0)

// A 64x48 pinhole camera `distance` units back from the origin, looking down +z.
inline tilesplat::Camera camera_looking_at_origin(double distance) {
  tilesplat::Camera camera;
  camera.width = 64;
  camera.height = 48;
  camera.fx = camera.fy = 50;
  camera.cx = 32;
  camera.cy = 24;
  camera.position = {0, 0, -distance};
  return camera;
}

inline bool all_finite(const std::vector<float>& values) {
  for (const float value : values)
    if (!std::isfinite(value)) return false;
  return true;
}

// Two readings of one file hold the same Gaussians, bit for bit.
inline void check_same_gaussians(const tilesplat::GaussianScene& a, const tilesplat::GaussianScene& b) {
  const auto same = [](const std::vector<float>& x, const std::vector<float>& y) {
    return x.size() == y.size() &&
           (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0);
  };
  FUZZ_CHECK(a.sh_degree == b.sh_degree);
  FUZZ_CHECK(same(a.positions, b.positions));
  FUZZ_CHECK(same(a.log_scales, b.log_scales));
  FUZZ_CHECK(same(a.rotations, b.rotations));
  FUZZ_CHECK(same(a.opacity_logits, b.opacity_logits));
  FUZZ_CHECK(same(a.sh, b.sh));
  FUZZ_CHECK(same(a.normals, b.normals));
}

// Gaussians `indices` of `scene`, in that order, as a scene of their own (what a part holds).
inline tilesplat::GaussianScene gaussians_at(const tilesplat::GaussianScene& scene,
                                             std::span<const uint32_t> indices) {
  tilesplat::GaussianScene part;
  part.sh_degree = scene.sh_degree;
  const size_t sh = 3 * static_cast<size_t>(scene.sh_coefficients());
  const auto copy = [](const std::vector<float>& from, std::vector<float>& to, size_t i, size_t per) {
    to.insert(to.end(), from.begin() + std::ptrdiff_t(i * per), from.begin() + std::ptrdiff_t((i + 1) * per));
  };
  for (const uint32_t i : indices) {
    copy(scene.positions, part.positions, i, 3);
    copy(scene.log_scales, part.log_scales, i, 3);
    copy(scene.rotations, part.rotations, i, 4);
    copy(scene.opacity_logits, part.opacity_logits, i, 1);
    copy(scene.sh, part.sh, i, sh);
    if (scene.has_normals()) copy(scene.normals, part.normals, i, 3);
  }
  return part;
}

// A loaded scene: consistent array sizes, finite values, unit quaternions, report counts that add up.
inline void check_scene(const tilesplat::GaussianScene& scene, const tilesplat::LoadReport& report) {
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

// The whole check of one fuzz input through a reader, `read(bytes, name, options, report)`: it must
// load a well-formed scene or throw a SceneError that names the file, and strict mode must fail
// exactly when the default mode drops a Gaussian, and otherwise load the same.
template <typename Read>
int check_reader(const uint8_t* data, size_t size, const char* name, Read read) {
  const auto bytes = std::as_bytes(std::span(data, size));
  bool loaded = false;
  tilesplat::GaussianScene scene;
  tilesplat::LoadReport report;
  try {
    scene = read(bytes, name, tilesplat::LoadOptions{}, &report);
    loaded = true;
  } catch (const tilesplat::SceneError& error) {
    FUZZ_CHECK(std::string(error.what()).starts_with(std::string(name) + ": "));
  }
  if (loaded) check_scene(scene, report);

  tilesplat::LoadOptions strict;
  strict.strict = true;
  try {
    const tilesplat::GaussianScene strict_scene =
        read(bytes, name, strict, static_cast<tilesplat::LoadReport*>(nullptr));
    FUZZ_CHECK(loaded && report.dropped == 0);
    FUZZ_CHECK(strict_scene.size() == scene.size() && strict_scene.positions == scene.positions &&
               strict_scene.sh == scene.sh && strict_scene.rotations == scene.rotations);
  } catch (const tilesplat::SceneError&) {
    FUZZ_CHECK(!loaded || report.dropped > 0);
  }
  return 0;
}

}  // namespace tilesplat::fuzz
