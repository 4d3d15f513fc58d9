// The effects a view at rest refines in the viewer, one sample a redraw added up on the device until the
// camera (or anything else) changes: key F's thin lens (depth of field) and key B's shutter (motion
// blur). Neither is drawn with the mesh (the box's depth is a still pinhole's: --no-mesh draws them).
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "lens_options.h"
#include "tilesplat/camera.h"
#include "tilesplat/renderer.h"
#include "view_shutter.h"

namespace tilesplat::viewer {

class ViewEffects {
 public:
  // `lens_flags`: --aperture, --f-stop, --focus-distance, --lens-samples (depth of field on from the start
  // when they open a lens); `view_shutter`: the first view's (motion blur on from the start when it opens);
  // `copies_move`: the scene file's models move; `focus_centre`: where key F focuses unless
  // --focus-distance says; `with_mesh`: the box and the grid are drawn, and neither effect.
  ViewEffects(const cli::LensFlags& lens_flags, ViewShutter view_shutter, bool copies_move,
              const std::array<double, 3>& focus_centre, bool with_mesh);

  // Keys F and B: false (nothing changed) with the mesh.
  bool toggle_depth_of_field();
  bool toggle_motion_blur();
  // Another view: its shutter (closed for a view the scene file opens none for), and motion blur as the
  // scene file gives the view (on when its shutter opens), whatever key B made of the view before.
  void set_view_shutter(ViewShutter shutter) {
    view_shutter_ = shutter;
    motion_blur_ = shutter.opens();
  }

  // Sets the lens, the shutter and accumulate_samples of a frame seen from `camera`; `pinhole`: key L's
  // lens is the pinhole (depth of field is a pinhole's alone; motion blur goes with every lens).
  void apply(const Camera& camera, bool pinhole, RenderSettings& settings) const;

  // The title's lens words for a pinhole view: "pinhole", or the aperture, the focus and the samples.
  std::string lens_title(const Camera& camera, uint32_t samples) const;
  // " | motion blur (N samples)" while key B blurs, else empty.
  std::string motion_title(uint32_t samples) const;

 private:
  bool draws_depth_of_field(bool pinhole) const { return depth_of_field_ && !with_mesh_ && pinhole; }
  bool draws_motion_blur() const;
  ViewShutter frame_shutter() const;
  ThinLens thin_lens(const Camera& camera) const;

  cli::LensFlags lens_flags_;
  ViewShutter view_shutter_;
  bool copies_move_;
  std::array<double, 3> focus_centre_;
  bool with_mesh_;
  bool depth_of_field_;  // key F
  bool motion_blur_;     // key B
};

// The samples a view at rest adds up under `settings` (ViewEffects::apply's): the most its lens or its
// shutter asks for; 0 when it accumulates none.
int samples_to_add_up(const RenderSettings& settings);

// The window's frame (`window`, accumulating `samples` lens or time samples) as one screenshot: either
// effect alone takes them all in one call; a lens and a shutter together take joint samples, which
// only calls of one sample add up (render_screenshot makes them).
RenderSettings screenshot_settings(RenderSettings window, int samples);
// Renders screenshot_settings' frame from `camera` (a call of all the samples, or `samples` calls of
// one after a frame that accumulates nothing, which ends the window's sums).
RenderImage render_screenshot(Renderer& renderer, const Camera& camera, const RenderSettings& settings,
                              int samples);

}  // namespace tilesplat::viewer
