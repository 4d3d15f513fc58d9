// Pinhole cameras in the original trainer's convention (OpenCV axes: x right, y down, z forward).
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "tilesplat/export.h"
#include "tilesplat/scene.h"

namespace tilesplat {

struct TILESPLAT_API Camera {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0;  // focal lengths in pixels
  double cx = 0, cy = 0;  // principal point in pixels (image centre by default)
  // World to camera: x_cam = rotation * (x_world - position). rotation is row-major 3x3.
  std::array<double, 9> rotation = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::array<double, 3> position = {0, 0, 0};  // camera centre in world space

  std::array<double, 3> to_camera(const std::array<double, 3>& world) const;
  // Horizontal and vertical tan(fov / 2).
  double tan_half_fov_x() const { return width / (2.0 * fx); }
  double tan_half_fov_y() const { return height / (2.0 * fy); }

  bool operator==(const Camera&) const = default;
};

// Throws std::invalid_argument ("invalid camera: ...", saying what) for a camera no renderer can use:
// a size that is not positive, focal lengths that are not positive and finite, or a non-finite
// principal point, rotation or position. Both renderers call it; device limits are checked on top.
TILESPLAT_API void validate(const Camera& camera);

// One entry of the trainer's cameras.json.
struct CameraView {
  int id = 0;
  std::string name;
  Camera camera;  // at the file's resolution
};

// Reads cameras.json. Throws SceneError naming the file and the bad entry.
TILESPLAT_API std::vector<CameraView> load_cameras_json(const std::filesystem::path& path);

// The same view at another resolution: intrinsics scale with the image size.
// width or height <= 0 keeps the aspect ratio from the other; both <= 0 keeps the original size.
TILESPLAT_API Camera resize_camera(const Camera& camera, int width, int height);

// A look-at camera on an orbit around the scene that frames its bounds.
// azimuth and elevation in degrees; vertical_fov in degrees.
struct OrbitParams {
  double azimuth_deg = 0;
  double elevation_deg = 20;
  double vertical_fov_deg = 50;
  double distance_scale = 1.0;  // multiply the framing distance
};
TILESPLAT_API Camera orbit_camera(const GaussianScene& scene, int width, int height,
                                  const OrbitParams& params = {});

// The camera turned by `radians` (right-handed) about the line through `pivot` along the unit
// `axis`: its position moves around the line and its axes turn with it, so the scene turns the
// other way in its view. Orbiting is a pivot at the scene; pivot = camera.position turns it in place.
TILESPLAT_API Camera turn_camera(const Camera& camera, const std::array<double, 3>& pivot,
                                 const std::array<double, 3>& axis, double radians);

// A camera at `eye` looking at `target`; `up` is the world up direction (the camera's -y).
TILESPLAT_API Camera look_at_camera(const std::array<double, 3>& eye, const std::array<double, 3>& target,
                                    const std::array<double, 3>& up, int width, int height,
                                    double vertical_fov_deg);

}  // namespace tilesplat
