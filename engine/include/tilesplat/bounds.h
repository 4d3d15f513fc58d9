/// @file
/// Where a scene is, as cameras frame it (compute_bounds in tilesplat/scene.h measures it).
#pragma once

namespace tilesplat {

/// Where a scene is, for framing cameras: its box and a robust centre and radius, in world units.
struct Bounds {
  double min[3] = {0, 0, 0};     ///< smallest x, y, z of the means
  double max[3] = {0, 0, 0};     ///< largest x, y, z of the means
  double center[3] = {0, 0, 0};  ///< robust centre (the median of the means per axis)
  double radius = 0;             ///< robust radius around center (covers most Gaussians, ignores outliers)
};

}  // namespace tilesplat
