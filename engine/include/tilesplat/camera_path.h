/// @file
/// Cameras for the frames of a video: an orbit around the scene, or a path through keyframes
/// (Catmull-Rom positions, slerped rotations). The keyframe file format is docs/camera-paths.md.
#pragma once

#include <array>
#include <filesystem>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/export.h"
#include "tilesplat/scene_error.h"

namespace tilesplat {

/// One key of a camera path. World space, in the trainer's convention (camera x right, y down,
/// z forward, as Camera).
struct CameraKeyframe {
  std::array<double, 3> position = {0, 0, 0};                    ///< the camera centre
  std::array<double, 9> rotation = {1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< world-to-camera, row-major, as Camera
  double vertical_fov_deg = 50;                                  ///< vertical field of view, in degrees
};

/// Keyframes and how to pass through them.
struct CameraPath {
  std::vector<CameraKeyframe> keys;  ///< at least 2, met at evenly spaced times
  /// Whether the path returns from the last key to the first (a closed loop, for turntables).
  bool loop = false;
};

/// Reads a keyframe file (docs/camera-paths.md). Throws SceneError naming the file and the key
/// when it is missing, not valid JSON, has fewer than 2 keys, or a key has a non-finite or
/// non-orthonormal value, a look-at target at the eye, or a field of view outside (0, 180).
TILESPLAT_API CameraPath load_camera_path(const std::filesystem::path& path);

/// The camera at time `t` of the path: t = 0 is the first key; t = 1 the last key of an open path,
/// or the first again of a loop. Positions follow a uniform Catmull-Rom spline through the keys
/// (the end keys repeated on an open path), rotations the shortest-arc slerp between neighbouring
/// keys, the field of view its linear blend. The image is width x height with the principal point
/// at the centre and square pixels. Throws std::invalid_argument for fewer than 2 keys, a size that
/// is not positive, or t outside [0, 1].
TILESPLAT_API Camera camera_on_path(const CameraPath& path, double t, int width, int height);

/// `frames` cameras along the path: t = f / (frames - 1) for an open path (the first and last frame
/// sit on the end keys; one frame is the first key), t = f / frames for a loop (the last frame
/// stops one step short of the first). Throws std::invalid_argument as camera_on_path, or when
/// frames < 1.
TILESPLAT_API std::vector<Camera> sample_camera_path(const CameraPath& path, int frames, int width,
                                                     int height);

/// `frames` orbit cameras (orbit_camera) evenly spaced around the scene: frame f at azimuth
/// params.azimuth_deg + 360 * f / frames. Throws std::invalid_argument when frames < 1 or the size
/// is not positive.
TILESPLAT_API std::vector<Camera> orbit_cameras(const GaussianScene& scene, int frames, int width, int height,
                                                const OrbitParams& params = {});
/// The same around given bounds (compute_bounds).
TILESPLAT_API std::vector<Camera> orbit_cameras(const Bounds& bounds, int frames, int width, int height,
                                                const OrbitParams& params = {});

}  // namespace tilesplat
