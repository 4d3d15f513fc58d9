// The shutter a scene file gives a view (SceneDescription::shutters), carried wherever the window's
// camera goes, for the viewer's motion blur (key B).
#pragma once

#include <array>

#include "tilesplat/camera.h"
#include "tilesplat/shutter.h"

namespace tilesplat::viewer {

// The view's camera motion is taken relative to the camera: from any orbit, the window's camera turns
// and moves in its own axes as the view's camera does from its start to its end, so a view's blur looks
// the same wherever the mouse has taken it (at the view itself, the end camera is the view's own). The
// times are the view's; the samples are progressive (sobol), one a redraw.
class ViewShutter {
 public:
  ViewShutter() = default;  // closed
  // `shutter`'s end camera (if any) is where `view_camera` is when it closes.
  ViewShutter(const Shutter& shutter, const Camera& view_camera);

  // Whether the shutter is open for a while (Shutter::opens).
  bool opens() const { return shutter_.opens(); }
  // Whether the camera moves while it is open (it has an end camera).
  bool camera_moves() const { return camera_moves_; }
  // The samples the view's shutter asks for: how many a still view adds up.
  int samples() const { return shutter_.samples; }
  // How the shutter scans the frame (a global one exposes it all at once).
  ShutterScan scan() const { return shutter_.scan; }
  // The shutter of a frame seen from `camera`: the view's times and scan, its end camera `camera` moved
  // as the view's camera moves (none when it stays), the sobol pattern.
  Shutter for_camera(const Camera& camera) const;

 private:
  Shutter shutter_;
  bool camera_moves_ = false;
  std::array<double, 9> turn_{};   // the end camera's axes in the start camera's: R_end R_start^T
  std::array<double, 3> shift_{};  // the end position in the start camera's axes: R_start (p_end - p_start)
};

}  // namespace tilesplat::viewer
