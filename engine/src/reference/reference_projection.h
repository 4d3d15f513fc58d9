// What render_reference shares with project_gaussian: the projection of one Gaussian with the lights
// prepared once per frame, and the checks of the inputs it projects.
#pragma once

#include <cstddef>

#include "camera/camera_models.h"
#include "lighting.h"
#include "tilesplat/reference.h"

namespace tilesplat::reference {

// project_gaussian, the camera's limits (camera_models::model_limits) and the lights (prepare_lighting,
// lighting.h) already prepared once for the frame. `seam_copy` 1: the equirectangular camera's second
// copy of the splat (camera_models::seam_copies).
ProjectedGaussian project(const GaussianScene& scene, size_t i, const Camera& camera,
                          const camera_models::ModelLimits& limits, Antialiasing antialiasing,
                          const PreparedLighting& lighting, double near_plane, uint32_t seam_copy = 0);
// Throws std::invalid_argument for a near plane that is not finite and positive (as the GPU's plan does).
// Throws std::invalid_argument when the scene has normals but not 3 per Gaussian.
void check_normals(const GaussianScene& scene);

}  // namespace tilesplat::reference
