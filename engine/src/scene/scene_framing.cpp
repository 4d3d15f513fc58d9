// Cameras framed on a scene: the orbits of tilesplat/camera.h and tilesplat/camera_path.h around the
// scene's bounds. They live with the scene, which knows cameras; the cameras know no scene, only Bounds.
#include <stdexcept>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/camera_path.h"
#include "tilesplat/scene.h"

namespace tilesplat {

// The sizes are checked before the scene is measured, so that a bad size fails at once, as it always did.
Camera orbit_camera(const GaussianScene& scene, int width, int height, const OrbitParams& params) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("orbit_camera: width and height must be positive");
  return orbit_camera(compute_bounds(scene), width, height, params);
}

std::vector<Camera> orbit_cameras(const GaussianScene& scene, int frames, int width, int height,
                                  const OrbitParams& params) {
  if (frames < 1) throw std::invalid_argument("orbit_cameras: frames must be at least 1");
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("camera path: width and height must be positive");
  return orbit_cameras(compute_bounds(scene), frames, width, height, params);
}

}  // namespace tilesplat
