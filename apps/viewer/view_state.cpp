#include "view_state.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <utility>

namespace tilesplat::viewer {

namespace {

// What key M steps through: the reference; depth16, the web viewers' sort keys; radial, the order a turn
// in place keeps; resort8, per-pixel re-sorting, more exact than the reference; and the web viewers'
// shortcuts all together.
constexpr const char* kModeCycle[] = {"reference", "depth16", "radial", "resort8",
                                      "depth16+opacity-extent+fp16-sh+fp16-cov"};
// What key C steps through: the tile compositor, the raster one (which draws no re-sorting: M skips
// resort8 while it is on) and the stochastic one, whose frames add up while the view rests.
constexpr std::array<Compositor, 3> kCompositorCycle = {Compositor::kSorted, Compositor::kRaster,
                                                        Compositor::kStochastic};

// What key S steps through: "auto" (the default), then every strategy.
std::vector<std::string> sort_cycle() {
  std::vector<std::string> sorts = {"auto"};
  for (const std::string& name : sort_strategies()) sorts.push_back(name);
  return sorts;
}

// The index of `value` in `list`, appended when it is not there (a --mode outside the cycle).
template <typename T>
size_t find_or_append(std::vector<T>& list, const T& value) {
  const auto found = std::find(list.begin(), list.end(), value);
  if (found != list.end()) return size_t(found - list.begin());
  list.push_back(value);
  return list.size() - 1;
}

}  // namespace

ViewState::ViewState(const ViewerOptions& options, const cli::LoadedScene& loaded, cli::SceneViews views)
    : bounds_(loaded.bounds()),
      controller_(loaded.camera, bounds_),
      mesh_(!options.no_mesh),
      depth_out_(!options.no_depth_out),
      scene_name_(loaded.path.filename().string()),
      views_(std::move(views.views)),
      shutters_(std::move(views.shutters)),
      view_(options.common.view),
      effects_(options.lens, ViewShutter(loaded.shutter, loaded.camera),
               loaded.instances && loaded.instances->moves(),
               {bounds_.center[0], bounds_.center[1], bounds_.center[2]}, mesh_),
      sorts_(sort_cycle()),
      stochastic_sampler_(options.stochastic_sampler) {
  // The keys choose the mode and the sort (starting from --mode and --sort below): the base is the scene
  // file's settings and the other flags, whose SH cap then caps every mode of the cycle.
  cli::CommonOptions flags = options.common;
  flags.modes.clear();
  flags.sorts.clear();
  base_settings_ = cli::base_render_settings(flags, loaded);
  for (const char* mode : kModeCycle) modes_.push_back(parse_accuracy_modes(mode));
  if (!options.common.modes.empty()) mode_ = find_or_append(modes_, options.common.modes.front());
  if (!options.common.sorts.empty()) sort_ = find_or_append(sorts_, options.common.sorts.front());
  // --compositor: sorted or raster, and no re-sorting mode with the raster (check_viewer_flags; a scene
  // file sets no compositor).
  compositor_ =
      size_t(std::find(kCompositorCycle.begin(), kCompositorCycle.end(), base_settings_.compositor) -
             kCompositorCycle.begin());
  // Key L's lenses, without the box and the grid (drawn through a pinhole): the pinhole, a fisheye of
  // 180 degrees, the panorama, and --fisheye, --orthographic or --equirectangular where given.
  lenses_.push_back({});
  if (!mesh_) {
    lenses_.push_back({.fisheye_fov_deg = 180.0});
    lenses_.push_back({.equirectangular = true});
    if (options.camera_model.enabled()) lens_ = find_or_append(lenses_, options.camera_model);
  }
}

bool ViewState::press(int key) {
  switch (key) {
    case GLFW_KEY_N:
    case GLFW_KEY_RIGHT:
      step_view(1);
      return !views_.empty();
    case GLFW_KEY_P:
    case GLFW_KEY_LEFT:
      step_view(-1);
      return !views_.empty();
    case GLFW_KEY_M:
      next_mode();
      return true;
    case GLFW_KEY_S:
      sort_ = (sort_ + 1) % sorts_.size();
      return true;
    case GLFW_KEY_C:
      compositor_ = (compositor_ + 1) % kCompositorCycle.size();
      if (!draws(modes_[mode_])) next_mode();
      return true;
    case GLFW_KEY_D:
      depth_out_ = !depth_out_;
      return true;
    case GLFW_KEY_F:
      return effects_.toggle_depth_of_field();
    case GLFW_KEY_B:
      return effects_.toggle_motion_blur();
    case GLFW_KEY_L:
      lens_ = (lens_ + 1) % lenses_.size();
      if (!draws(modes_[mode_])) next_mode();
      return true;
    default:
      return false;
  }
}

Camera ViewState::camera() const {
  return cli::camera_for_frame(lenses_[lens_], controller_.camera());
}

RenderSettings ViewState::settings() const {
  RenderSettings settings = base_settings_;
  effects_.apply(camera(), !lenses_[lens_].enabled(), settings);  // keys F and B
  settings.sort = sorts_[sort_];
  settings.accuracy = modes_[mode_];
  settings.compositor = kCompositorCycle[compositor_];
  settings.stochastic.frames = 1;
  settings.stochastic.accumulate = true;
  settings.stochastic.sampler = stochastic_sampler_;
  // A scene file's sh_degree effect caps every mode, as in tilesplat-render.
  settings.accuracy.sh_degree_cap =
      std::min(settings.accuracy.sh_degree_cap, base_settings_.accuracy.sh_degree_cap);
  return settings;
}

bool ViewState::draws(const AccuracyModes& modes) const {
  return compositor_draws(kCompositorCycle[compositor_], modes) && camera_draws(camera(), modes);
}

void ViewState::next_mode() {
  do {
    mode_ = (mode_ + 1) % modes_.size();
  } while (!draws(modes_[mode_]));
}

void ViewState::step_view(int step) {
  if (views_.empty()) return;
  const int count = int(views_.size());
  view_ = ((view_ + step) % count + count) % count;
  controller_.set_camera(views_[size_t(view_)].camera);
  effects_.set_view_shutter(shutters_.empty()
                                ? ViewShutter()
                                : ViewShutter(shutters_[size_t(view_)], views_[size_t(view_)].camera));
}

std::string ViewState::lens_name(uint32_t accumulated_samples) const {
  const cli::CameraModelFlags& lens = lenses_[lens_];
  if (lens.fisheye_fov_deg) return "fisheye " + cli::format_fixed(*lens.fisheye_fov_deg, 0) + " deg";
  if (lens.view_height) return "orthographic " + cli::format_fixed(*lens.view_height, 2) + " tall";
  if (lens.equirectangular) return "panorama";
  return effects_.lens_title(camera(), accumulated_samples);
}

std::string ViewState::title(const FrameStats& last) const {
  std::string title = scene_name_;
  if (!views_.empty()) {
    const CameraView& view = views_[size_t(view_)];
    title += " | view " + std::to_string(view_) + (view.name.empty() ? "" : " (" + view.name + ")");
  }
  const std::string sort = sorts_[sort_] == "auto" && !last.sort_strategy.empty()
                               ? "auto (" + last.sort_strategy + ")"
                               : sorts_[sort_];
  const Compositor compositor = kCompositorCycle[compositor_];
  title += " | " + lens_name(last.accumulated_samples) + " | " + to_string(modes_[mode_]) + " | " + sort +
           " | " + to_string(compositor);
  if (compositor == Compositor::kStochastic)
    title +=
        " (" + std::to_string(last.accumulated_frames) + " " + to_string(stochastic_sampler_) + " frames)";
  return title + effects_.motion_title(last.accumulated_samples);
}

}  // namespace tilesplat::viewer
