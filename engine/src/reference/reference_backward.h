// The float64 reference's frame in float64 all the way out, for what checks its backward against finite
// differences: render_reference rounds its outputs to float, which would drown a small step's change.
#pragma once

#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/scene.h"

namespace tilesplat::reference {

// The outputs FrameGradients has gradients for, per pixel of the whole image, unrounded.
struct FrameF64 {
  std::vector<double> rgb;                // 3 per pixel, with the background
  std::vector<double> alpha;              // 1 - T
  std::vector<double> expected_depth;     // sum w z / sum w, 0 where nothing blended
  std::vector<double> accumulated_depth;  // sum w z
};
// The frame reference_backward differentiates (check_differentiable's frames only): render_reference's,
// unrounded.
FrameF64 render_f64(const GaussianScene& scene, const Camera& camera, const RenderSettings& settings);

}  // namespace tilesplat::reference
