// Placing and merging scenes one Gaussian or one scene at a time: merge_scenes, a scene file's instances
// (each transformed copy appended and dropped before the next is made), and the parts of a scene of
// instances (frame/scene_parts.h), which place only the Gaussians a part draws.
#pragma once

#include <array>
#include <cstddef>

#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"

namespace tilesplat::detail {

// Where transform_scene puts a Gaussian's position, one at a time (transform_scene places every position
// through it): p' = s R p + t in double, rounded once to float. Throws std::invalid_argument when the
// placed position overflows float, naming the Gaussian.
class PositionPlacement {
 public:
  explicit PositionPlacement(const ModelTransform& transform);  // a valid transform (validate)
  std::array<float, 3> place(const float* position, size_t gaussian) const;

 private:
  std::array<double, 9> rotation_;  // row-major
  bool rotates_;
  double scale_;
  std::array<double, 3> translation_;
};

// `out` empty, with room for `total` Gaussians of SH degree `sh_degree` (and normals).
void reserve_merged(GaussianScene& out, size_t total, int sh_degree, bool with_normals);
// Appends `scene` (or its Gaussians [first, first + count)), its SH padded with zeros or cut to
// out.sh_degree, its normals (zeros where it has none) when `with_normals`.
void append_merged(GaussianScene& out, const GaussianScene& scene, bool with_normals);
void append_merged(GaussianScene& out, const GaussianScene& scene, bool with_normals, size_t first,
                   size_t count);

}  // namespace tilesplat::detail
