// Mouse camera control: orbit around a pivot (the scene's centre), pan, zoom.
#pragma once

#include <array>

#include "tilesplat/camera.h"
#include "tilesplat/scene.h"

namespace tilesplat::viewer {

// Moves the camera it was given instead of rebuilding one from angles, so that until the first
// drag the camera is exactly that one (a cameras.json view, or the apps' orbit camera) and a
// frame equals tilesplat-render's of the same view. World up is -Y, as in the trainer's captures
// and orbit_camera().
class OrbitController {
 public:
  // The pivot starts at the bounds' centre; their radius scales the smallest zoom step.
  OrbitController(const Camera& camera, const Bounds& scene_bounds);

  // Jumps to another camera (a view of the cameras file) at the current image size; keeps the pivot.
  void set_camera(const Camera& camera);
  // A new image size: the vertical field of view stays, the horizontal one follows the aspect.
  void resize(int width, int height);

  // Mouse moves in pixels. Orbit: a drag across the window's height turns the camera half a turn
  // about world up (horizontal) or its own right axis (vertical), the scene following the mouse.
  void orbit(double dx, double dy);
  // Slides the camera and the pivot in the image plane so that the pivot's depth follows the mouse.
  void pan(double dx, double dy);
  // Turns the camera about world up through the pivot (--turn: a turntable, as a steady horizontal drag).
  void turn(double degrees);
  // Scroll steps (positive: closer), each 15% of the way to the pivot's depth.
  void zoom(double steps);

  const Camera& camera() const { return camera_; }

 private:
  Camera camera_;
  std::array<double, 3> pivot_;
  double min_depth_;
};

}  // namespace tilesplat::viewer
