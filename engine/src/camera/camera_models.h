// The camera models' math (tilesplat::CameraModel) in float64, written once on the host: the reference
// projects every splat centre with it, and the GPU's projection (compute/projection.comp,
// project_centre) mirrors it operation for operation with the limits the host derives here.
#pragma once

#include <array>
#include <cstdint>

#include "tilesplat/camera.h"
#include "tilesplat/render_settings.h"

namespace tilesplat::camera_models {

// Where a model stops drawing and where its Jacobian is evaluated at most: derived once per camera,
// given to the GPU in CameraParams::clip.
struct ModelLimits {
  // Pinhole and OpenCV: the Jacobian is evaluated at (x / z, y / z) clamped to these, 1.3 times the
  // image's extent in undistorted coordinates (the trainer's rule, which keeps splats far outside the
  // frame from getting absurd footprints).
  double clamp_x = 0;
  double clamp_y = 0;
  // OpenCV: the undistorted radius sqrt((x/z)^2 + (y/z)^2) from which the radial distortion folds back
  // (d(r radial(r)) / dr <= 0); fisheye: the angle from the axis from which theta_d stops growing, at
  // most pi. Centres at or beyond it are not drawn. Infinite where nothing folds.
  double reach = 0;
};
// Those of `camera`, remembered for the last camera (its model, coefficients, intrinsics and size) asked
// about on the calling thread; the reference lives until the next call on that thread.
const ModelLimits& model_limits(const Camera& camera);

// A splat centre t (camera space) through the camera's model.
struct CentreProjection {
  bool visible = false;                // false: culled (behind the near plane, beyond the reach, ...)
  std::array<double, 2> pixel{};       // where the centre lands
  std::array<double, 3> jacobian_u{};  // d pixel.x / d t
  std::array<double, 3> jacobian_v{};  // d pixel.y / d t
  double depth = 0;                    // what splats sort by and depth images hold: z, or the distance
};
// The model a camera is drawn with: its own, except that an OpenCV camera whose coefficients are all 0 is
// the pinhole (and drawn by the pinhole's code, so that it renders the pinhole's frame to the bit).
inline CameraModel drawn_model(const Camera& camera) {
  if (camera.model == CameraModel::kOpenCV && camera.distortion == std::array<double, 8>{})
    return CameraModel::kPinhole;
  return camera.model;
}

// Whether the model's depth (CentreProjection::depth, what splats sort by) is the distance from the camera:
// the models that project by direction (fisheye, panorama). The others' is the view z, which radial sorting
// (AccuracyModes::SortDepth::kDistance) replaces with the distance.
inline bool depth_is_distance(CameraModel model) {
  return model == CameraModel::kFisheye || model == CameraModel::kEquirectangular;
}

// Whether the depth sort keys a model's records by their distance from the camera where the model's own
// depth is the view z: radial sorting through the pinhole or OpenCV camera (projection.comp's
// DISTANCE_KEY; the float64 reference sorts the same way). The orthographic camera refuses radial sorting
// before this is asked (check_camera_model).
inline bool radial_replaces_depth(CameraModel model, AccuracyModes::SortDepth sort_depth) {
  return sort_depth == AccuracyModes::SortDepth::kDistance && !depth_is_distance(model);
}

// How many records each Gaussian projects to: 2 for the equirectangular camera, whose splats across the
// +-180 degree seam are drawn again one period (2 pi fx) to the other side; 1 for the others.
inline uint32_t seam_copies(CameraModel model) {
  return model == CameraModel::kEquirectangular ? 2 : 1;
}

// For every model but the pinhole, whose projection the reference keeps written out in its own words.
// `seam_copy` 1: the equirectangular camera's second copy, its pixel a period (2 pi fx) to the side of the
// image nearer it.
CentreProjection project_centre(const Camera& camera, const ModelLimits& limits,
                                const std::array<double, 3>& t, double near_plane, uint32_t seam_copy = 0);

// OpenCV's distortion of the normalized point (x, y) = (X / Z, Y / Z), and its 2x2 Jacobian (row-major).
struct Distorted {
  std::array<double, 2> point{};
  std::array<double, 4> jacobian{};
};
Distorted distort(const std::array<double, 8>& k, double x, double y);

// The fisheye's theta_d(theta) and its derivative.
std::array<double, 2> fisheye_theta_d(const std::array<double, 8>& k, double theta);

// The pixel of a camera-space point, for any model (the mean of project_centre, and the pinhole's
// fx x / z + cx); visible = false where the model draws nothing.
CentreProjection project_point(const Camera& camera, const std::array<double, 3>& t);

// The camera-space unit ray through image point (u, v) (pixel coordinates, centres at +0.5), for any
// model; nullopt-like false where no ray maps there (outside a fisheye's reach, past OpenCV's fold).
// Used by tests and by tools that resample one model's image into another's.
bool pixel_ray(const Camera& camera, double u, double v, std::array<double, 3>& ray);

}  // namespace tilesplat::camera_models
