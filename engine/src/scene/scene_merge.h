// Merging scenes one at a time into a scene sized for all of them (merge_scenes, and a scene file's
// models: each transformed copy appended and dropped before the next is made).
#pragma once

#include <cstddef>

#include "tilesplat/scene.h"

namespace tilesplat::detail {

// `out` empty, with room for `total` Gaussians of SH degree `sh_degree` (and normals).
void reserve_merged(GaussianScene& out, size_t total, int sh_degree, bool with_normals);
// Appends `scene`, its SH padded with zeros or cut to out.sh_degree, its normals (zeros where it has
// none) when `with_normals`.
void append_merged(GaussianScene& out, const GaussianScene& scene, bool with_normals);

}  // namespace tilesplat::detail
