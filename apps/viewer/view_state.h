// What the viewer shows: the camera (orbited, or stepped through the views of --cameras or the scene
// file), key L's lens, the accuracy mode, sort strategy and compositor keys M, S and C cycle through, the
// effects of keys F and B, whether the splats write their depth for the grid (key D), and the title's
// words for all of it. It knows nothing of the window's device or of how frames are scheduled and shown
// (viewer_main.cpp's Viewer does that).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "cli.h"
#include "orbit_controller.h"
#include "tilesplat/camera.h"
#include "tilesplat/renderer.h"
#include "view_effects.h"
#include "viewer_options.h"

namespace tilesplat::viewer {

class ViewState {
 public:
  ViewState(const ViewerOptions& options, const cli::LoadedScene& loaded, cli::SceneViews views);

  // A key press (GLFW_KEY_*; Esc and Q are the window's): true when it changed what is shown, so that the
  // frame must be rendered again.
  bool press(int key);
  // The mouse and the wheel move the camera; the window's size and --turn too.
  OrbitController& controller() { return controller_; }

  // The frame's camera through key L's lens, and the pinhole camera the mesh is drawn with.
  Camera camera() const;
  const Camera& pinhole_camera() const { return controller_.camera(); }
  // The frame's settings: the scene file's, the keys' choices, and the stochastic compositor adding one
  // frame a redraw to the mean of the earlier ones until anything changes (StochasticSettings::accumulate).
  // They keep the depth and count outputs the scene asks for, which the window's frames leave out.
  RenderSettings settings() const;
  bool depth_out() const { return depth_out_; }
  const Bounds& bounds() const { return bounds_; }

  // The title's words for the view: scene | view | lens | mode | sort | compositor [| motion blur], from the
  // statistics of the last frame waited for (the sort "auto" chose, the samples and frames added up).
  std::string title(const FrameStats& last) const;

 private:
  // Whether the frame draws in `modes`: the compositor's rule and the lens's (the library's own).
  bool draws(const AccuracyModes& modes) const;
  void next_mode();  // the next accuracy mode the frame draws (the reference always is one)
  void step_view(int step);
  std::string lens_name(uint32_t accumulated_samples) const;

  Bounds bounds_;
  OrbitController controller_;
  bool mesh_;       // the box and the grid are drawn (not --no-mesh): no other lens, no effects
  bool depth_out_;  // the splats write their depth for the grid (key D)
  std::string scene_name_;
  std::vector<CameraView> views_;  // of --cameras or the scene file; N and P step through them
  std::vector<Shutter> shutters_;  // the scene file's, one per view; none for --cameras
  int view_ = 0;
  ViewEffects effects_;  // keys F and B: depth of field and motion blur
  std::vector<AccuracyModes> modes_;
  size_t mode_ = 0;
  std::vector<std::string> sorts_;
  size_t sort_ = 0;
  std::vector<cli::CameraModelFlags> lenses_;  // key L's cycle
  size_t lens_ = 0;
  size_t compositor_ = 0;                 // in the cycle of key C
  StochasticSampler stochastic_sampler_;  // --stochastic-sampler
  RenderSettings base_settings_;          // the scene file's background, effects and outputs
};

}  // namespace tilesplat::viewer
