/// @file
/// The float64 CPU reference renderer: the math of docs/rendering-math.md, tiles and all.
/// It is the ground truth the GPU pipeline and every approximation are measured against.
#pragma once

#include <array>
#include <cstdint>

#include "tilesplat/camera.h"
#include "tilesplat/export.h"
#include "tilesplat/image.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/scene.h"

namespace tilesplat {

/// Per-Gaussian screen-space result of the projection step, in float64.
struct ProjectedGaussian {
  bool visible = false;         ///< passed every cull and touches at least one tile
  double depth = 0;             ///< view-space z
  double mean[2] = {0, 0};      ///< projected mean in pixels (x, y)
  double cov2d[3] = {0, 0, 0};  ///< a b c of the dilated 2D covariance [[a b] [b c]]
  double conic[3] = {0, 0, 0};  ///< inverse of cov2d: A B C
  double opacity = 0;           ///< sigmoid(logit)
  double color[3] = {0, 0, 0};  ///< max(SH + 0.5, 0), times the light factor when lit (tilesplat::Lighting)
  int radius = 0;               ///< pixels
  int tile_min[2] = {0, 0};     ///< first tile (x, y) of the tile rectangle
  int tile_max[2] = {0, 0};     ///< one past the last tile (x, y): the maximum is exclusive
};

/// Width and height of a screen tile in pixels: the unit of binning and sorting.
constexpr int kTileSize = 16;

/// Projects Gaussian i of the scene with the reference math, lit when `lighting` has lights, culled
/// at or before `near_plane` (RenderSettings::near_plane). Throws std::invalid_argument for invalid
/// lights (validate).
TILESPLAT_API ProjectedGaussian project_gaussian(const GaussianScene& scene, size_t i, const Camera& camera,
                                                 Antialiasing antialiasing = Antialiasing::kClassic,
                                                 const Lighting& lighting = {},
                                                 double near_plane = kDefaultNearPlane);

/// Evaluates real spherical harmonics up to `degree` for the (normalized) direction dir.
/// coeffs: K * 3 values, coefficient-major RGB innermost. Returns the raw sum (no +0.5, no clamp).
TILESPLAT_API std::array<double, 3> eval_sh(int degree, const float* coeffs,
                                            const std::array<double, 3>& dir);

/// 3D covariance R S S^T R^T (row-major 3x3) from log scales and a w x y z quaternion.
TILESPLAT_API std::array<double, 9> covariance3d(const float log_scale[3], const float quat_wxyz[4]);

/// Renders the whole image in float64: projection, per-tile lists ordered by (depth, index),
/// front-to-back blending with the reference cut-offs. Uses all CPU cores. With
/// AccuracyModes::resort_window set, each pixel blends in the order the GPU's re-sorting composite
/// blends (the same window, in float64).
TILESPLAT_API RenderImage render_reference(const GaussianScene& scene, const Camera& camera,
                                           const RenderSettings& settings = {});

struct SceneInstances;  // tilesplat/scene_description.h

/// A scene file's placed copies in float64: their merged scene (merge_instances); where copies move under
/// an open shutter (settings.shutter: close > open), the linear mean of the frames at the shutter's times,
/// each of the copies where they are then from the camera then, as Renderer::render(instances, ...)
/// makes it (docs/effects.md, "Moving models").
TILESPLAT_API RenderImage render_reference(const SceneInstances& scene, const Camera& camera,
                                           const RenderSettings& settings = {});

/// The order in which each pixel of render_reference blends its splats.
enum class ReferenceOrder {
  kSettings,  ///< as the settings say: the tile's centre-depth list, or the re-sorting mode's window
  kRayDepth,  ///< every splat the pixel's tile lists, by the depth of its density maximum along the
              ///< pixel's ray: the exact order that the re-sorting modes approximate (pinhole only)
};

/// render_reference in the given order (ReferenceOrder::kRayDepth ignores the settings' re-sorting
/// modes). Throws std::invalid_argument for kRayDepth with a camera model other than the pinhole.
TILESPLAT_API RenderImage render_reference(const GaussianScene& scene, const Camera& camera,
                                           const RenderSettings& settings, ReferenceOrder order);

}  // namespace tilesplat
