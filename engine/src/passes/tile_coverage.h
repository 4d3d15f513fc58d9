// Host side of compute/tile_coverage.glsl.
#pragma once

namespace tilesplat {

// 1 / the alpha cut-off, rounded to float once, on the host. The projection, the key emission and the
// composite each derive a splat's coverage ellipse from this value (255 exactly for the reference's
// 1/255), so they cannot disagree about which tiles and pixels a splat reaches.
inline float coverage_alpha_inv(float alpha_cutoff) { return float(1.0 / double(alpha_cutoff)); }

}  // namespace tilesplat
