// The float64 reference's projection of one Gaussian (reference_projection.cpp) for the pinhole camera,
// in forward-mode dual numbers: what the composite reads of the splat (its 2D mean, conic, opacity, view
// depth and colour) with their derivatives with respect to the Gaussian's own parameters. The backward
// (reference_backward.cpp) carries each splat's screen-space gradient to the scene through these.
#pragma once

#include <array>
#include <cstddef>

#include "camera/camera_models.h"
#include "reference/dual.h"
#include "tilesplat/camera.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/scene.h"

namespace tilesplat::reference {

// The Gaussian's parameters that the projection differentiates with respect to, in this order.
enum GaussianInput : size_t {
  kMeanX,
  kMeanY,
  kMeanZ,  // GaussianScene::positions
  kLogScaleX,
  kLogScaleY,
  kLogScaleZ,  // GaussianScene::log_scales
  kQuatW,
  kQuatX,
  kQuatY,
  kQuatZ,         // GaussianScene::rotations (before normalization)
  kOpacityLogit,  // GaussianScene::opacity_logits
  kGaussianInputs
};
using GaussianDual = Dual<kGaussianInputs>;

// What the composite reads of one projected splat, each with its derivatives. The colour is linear in
// the SH coefficients: d colour[c] / d coefficient (k, c) = sh_basis[k] where the colour is not clamped
// at 0 (colour_clamped[c] false), else 0.
struct DifferentiableSplat {
  GaussianDual mean[2];   // pixels
  GaussianDual conic[3];  // A B C of the inverse dilated 2D covariance
  GaussianDual opacity;   // after the antialiased modes' compensation
  GaussianDual depth;     // view-space z
  GaussianDual colour[3];
  std::array<double, 16> sh_basis{};
  bool colour_clamped[3] = {false, false, false};
};

// Gaussian i of the scene, seen by a pinhole camera (camera_models::drawn_model(camera) == kPinhole)
// with the reference's culls already passed (ProjectedGaussian::visible): its values equal
// project_gaussian's.
DifferentiableSplat project_differentiable(const GaussianScene& scene, size_t i, const Camera& camera,
                                           const camera_models::ModelLimits& limits,
                                           Antialiasing antialiasing);

}  // namespace tilesplat::reference
