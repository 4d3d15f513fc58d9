#include "view_effects.h"

#include <algorithm>

#include "text.h"

namespace tilesplat::viewer {
namespace {

// The time samples key B adds up over copies that move when the view has no shutter of its own.
constexpr int kMotionSamples = 32;

}  // namespace

ViewEffects::ViewEffects(const cli::LensFlags& lens_flags, ViewShutter view_shutter, bool copies_move,
                         const std::array<double, 3>& focus_centre, bool with_mesh)
    : lens_flags_(lens_flags),
      view_shutter_(view_shutter),
      copies_move_(copies_move),
      focus_centre_(focus_centre),
      with_mesh_(with_mesh),
      depth_of_field_(lens_flags.enabled()),
      motion_blur_(view_shutter.opens()) {}

bool ViewEffects::toggle_depth_of_field() {
  if (with_mesh_) return false;
  depth_of_field_ = !depth_of_field_;
  return true;
}

bool ViewEffects::toggle_motion_blur() {
  if (with_mesh_) return false;
  motion_blur_ = !motion_blur_;
  return true;
}

void ViewEffects::apply(const Camera& camera, bool pinhole, RenderSettings& settings) const {
  // Depth of field: one lens sample a redraw (RenderSettings::accumulate_samples).
  if (draws_depth_of_field(pinhole)) {
    settings.lens = thin_lens(camera);
    settings.accumulate_samples = settings.lens.enabled();
  }
  // Motion blur: likewise one time sample a redraw (with the lens on, one joint sample).
  if (draws_motion_blur()) {
    settings.shutter = frame_shutter().for_camera(camera);
    settings.accumulate_samples = true;
  }
}

std::string ViewEffects::lens_title(const Camera& camera, uint32_t samples) const {
  if (!draws_depth_of_field(true)) return "pinhole";
  const ThinLens lens = thin_lens(camera);
  if (!lens.enabled()) return "pinhole (depth of field: the scene's centre is behind the camera)";
  return "aperture " + cli::format_number(lens.aperture_diameter, 3) + " focus " +
         cli::format_number(lens.focus_distance, 3) + " (" + std::to_string(samples) + " samples)";
}

std::string ViewEffects::motion_title(uint32_t samples) const {
  return draws_motion_blur() ? " | motion blur (" + std::to_string(samples) + " samples)" : "";
}

// On, without the mesh, over a shutter that opens on something that moves (the camera or copies of
// models); a rolling shutter's bands are tilesplat-render's.
bool ViewEffects::draws_motion_blur() const {
  const ViewShutter shutter = frame_shutter();
  return motion_blur_ && !with_mesh_ && shutter.opens() && (shutter.camera_moves() || copies_move_) &&
         shutter.scan() == ShutterScan::kGlobal;
}

// The view's shutter (the scene file's for it), else, over copies that move, one open for the whole
// frame (time 0 to 1).
ViewShutter ViewEffects::frame_shutter() const {
  if (view_shutter_.opens() || !copies_move_) return view_shutter_;
  return ViewShutter({.open = 0, .close = 1, .samples = kMotionSamples}, Camera{});
}

// The flags' aperture (--aperture, --f-stop), else 5% of the focus distance; focused on the scene's
// centre unless --focus-distance says; its samples progressive (SamplePattern::kSobol, which a still view
// continues frame after frame). Off when the scene's centre, to be focused on, is behind the camera.
ThinLens ViewEffects::thin_lens(const Camera& camera) const {
  cli::LensFlags flags = lens_flags_;
  flags.pattern = SamplePattern::kSobol;
  if (!flags.enabled()) flags.aperture = 1.0;  // replaced below, once the focus is known
  if (!flags.focus_distance && !(camera.to_camera(focus_centre_)[2] > 0)) return {};
  ThinLens lens = cli::lens_for_frame(flags, camera, focus_centre_);
  if (!lens_flags_.enabled()) lens.aperture_diameter = 0.05 * lens.focus_distance;
  return lens;
}

int samples_to_add_up(const RenderSettings& settings) {
  if (!settings.accumulate_samples) return 0;
  return std::max(settings.lens.enabled() ? settings.lens.samples : 0,
                  settings.shutter.opens() ? settings.shutter.samples : 0);
}

RenderSettings screenshot_settings(RenderSettings window, int samples) {
  if (!window.accumulate_samples) return window;
  if (window.lens.enabled()) window.lens.samples = samples;
  if (window.shutter.opens()) window.shutter.samples = samples;
  window.accumulate_samples = window.lens.enabled() && window.shutter.opens();
  return window;
}

RenderImage render_screenshot(Renderer& renderer, const Camera& camera, const RenderSettings& settings,
                              int samples) {
  if (!settings.accumulate_samples) return renderer.render(camera, settings);
  RenderSettings pinhole = settings;
  pinhole.lens = {};
  pinhole.shutter = {};
  renderer.render(camera, pinhole);
  RenderImage image;
  for (int sample = 0; sample < samples; ++sample) image = renderer.render(camera, settings);
  return image;
}

}  // namespace tilesplat::viewer
