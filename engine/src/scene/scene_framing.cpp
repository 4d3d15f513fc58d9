// Cameras framed on a scene: the orbits of tilesplat/camera.h and tilesplat/camera_path.h around the
// scene's bounds. They live with the scene, which knows cameras; the cameras know no scene, only Bounds.
// The Bounds overloads check the frame count and the image size.
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/camera_path.h"
#include "tilesplat/scene.h"

namespace tilesplat {

Camera orbit_camera(const GaussianScene& scene, int width, int height, const OrbitParams& params) {
  return orbit_camera(compute_bounds(scene), width, height, params);
}

std::vector<Camera> orbit_cameras(const GaussianScene& scene, int frames, int width, int height,
                                  const OrbitParams& params) {
  return orbit_cameras(compute_bounds(scene), frames, width, height, params);
}

}  // namespace tilesplat
