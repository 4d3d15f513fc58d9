#include "settings_checks.h"

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "camera/camera_models.h"

namespace tilesplat {

void check_near_plane(double near_plane) {
  if (!(std::isfinite(near_plane) && near_plane > 0))
    throw std::invalid_argument("RenderSettings::near_plane must be a positive, finite view depth, got " +
                                std::to_string(near_plane));
}

void check_max_alpha(const RenderSettings& settings) {
  const double cutoff = settings.accuracy.alpha_cutoff;
  if (!(settings.max_alpha > cutoff && settings.max_alpha < 1))
    throw std::invalid_argument("RenderSettings::max_alpha must be above the alpha cut-off (" +
                                std::to_string(cutoff) + ") and below 1, got " +
                                std::to_string(settings.max_alpha));
}

void check_lens(const RenderSettings& settings, const Camera& camera) {
  validate(settings.lens);
  validate(camera);
  // The thin lens shears a pinhole's frustum (lens_sample_camera moves the principal point); the other
  // models have no such shear written yet.
  if (settings.lens.enabled() && camera_models::drawn_model(camera) != CameraModel::kPinhole)
    throw std::invalid_argument(
        std::string("RenderSettings::lens: depth of field needs a pinhole camera, not ") +
        camera_model_name(camera.model));
  if (settings.host)
    throw std::invalid_argument(
        "RenderSettings::lens: depth of field cannot be combined with a host's depth "
        "(RenderSettings::host)");
}

void check_shutter(const RenderSettings& settings, const Camera& camera) {
  validate(settings.shutter);
  validate(camera);
  const Camera& end = *settings.shutter.end_camera;
  if (end.model != camera.model || end.distortion != camera.distortion)
    throw std::invalid_argument(
        "RenderSettings::shutter: the end camera's model or coefficients differ from the camera's: a camera "
        "moves, its lens stays");
  if (end.width != camera.width || end.height != camera.height)
    throw std::invalid_argument("RenderSettings::shutter: the end camera is " + std::to_string(end.width) +
                                "x" + std::to_string(end.height) + ", the camera " +
                                std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                                ": a camera moves, it does not change size");
  if (settings.host)
    throw std::invalid_argument(
        "RenderSettings::shutter: motion blur cannot be combined with a host's depth "
        "(RenderSettings::host)");
}

namespace {

// Why `camera` cannot draw in `modes`, or nothing: the one rule of camera_draws and check_camera_model.
std::optional<std::string> camera_refusal(const Camera& camera, const AccuracyModes& modes) {
  const CameraModel model = camera_models::drawn_model(camera);
  if (model != CameraModel::kPinhole && modes.resort_window > 0)
    return "per-pixel re-sorting (resort" + std::to_string(modes.resort_window) +
           ") needs a pinhole camera, not " + camera_model_name(camera.model);
  // An orthographic camera's centre is at infinity: every distance from it is the same infinite one.
  if (model == CameraModel::kOrthographic && modes.sort_depth == AccuracyModes::SortDepth::kDistance)
    return "radial sorting orders by the distance from the camera's centre, and an orthographic camera has "
           "none (it looks from infinitely far): sort by view depth";
  return std::nullopt;
}

}  // namespace

bool camera_draws(const Camera& camera, const AccuracyModes& modes) {
  return !camera_refusal(camera, modes).has_value();
}

void check_camera_model(const RenderSettings& settings, const Camera& camera) {
  if (const auto why = camera_refusal(camera, settings.accuracy)) throw std::invalid_argument(*why);
}

void check_region(const RenderSettings& settings, const Camera& camera) {
  validate(settings.region, camera.width, camera.height);
  if (settings.host && !settings.region.whole())
    throw std::invalid_argument("RenderSettings::region " + to_string(settings.region) +
                                ": a region cannot be combined with a host's depth (RenderSettings::host), "
                                "which is the whole image's");
}

void check_single_frame(const RenderSettings& settings) {
  validate(settings.lens);  // an aperture below 0 or NaN is not "off"
  validate(settings.shutter);
  if (settings.lens.enabled())
    throw std::invalid_argument(
        "RenderSettings::lens: depth of field is rendered by Renderer::render() and "
        "render_reference(), not by render_to_image or a frame submitted without waiting");
  if (settings.shutter.enabled())
    throw std::invalid_argument(
        "RenderSettings::shutter: motion blur is rendered by Renderer::render() and "
        "render_reference(), not by render_to_image or a frame submitted without waiting");
}

void check_accumulated_samples(const RenderSettings& settings, const Camera& camera) {
  const auto progressive = [](SamplePattern pattern, const char* effect) {
    if (pattern != SamplePattern::kSobol)
      throw std::invalid_argument(std::string("RenderSettings::accumulate_samples continues a sequence of "
                                              "samples from call to call: the ") +
                                  effect + "'s pattern must be sobol, not " + sample_pattern_name(pattern));
  };
  if (settings.lens.enabled()) {
    check_lens(settings, camera);
    progressive(settings.lens.pattern, "lens");
  }
  if (settings.shutter.enabled()) {
    check_shutter(settings, camera);
    progressive(settings.shutter.pattern, "shutter");
  }
}

}  // namespace tilesplat
