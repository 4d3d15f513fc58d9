// RenderSettings::host, as both renderers (the GPU's and the float64 reference) read it.
#pragma once

#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/render_settings.h"

namespace tilesplat {

// Throws std::invalid_argument ("host depth: ...") for a compositor or mode that does not honour
// it, a convention that is not one, a threshold outside (0, 1], or a depth image of the wrong size or
// with a NaN.
void validate_host_depth(const RenderSettings& settings, const Camera& camera);

// The host's depth image as the view depths both renderers compare splats with: float, +inf where
// the host's value lies at or beyond infinity. Empty for no depth image.
std::vector<float> host_view_depths(const HostDepth& host);

// RenderImage::host_depth at `pixel`, from the view depth at which the splats' alpha reached the
// threshold there (0: never): that depth in the host's convention, else the host's own depth (its
// far value without a depth image).
float host_depth_out(const HostDepth& host, double surface_z, size_t pixel);

}  // namespace tilesplat
