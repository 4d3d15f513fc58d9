#include "backward/gradient_checks.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include "camera/camera_models.h"

namespace tilesplat {
namespace {

void check_channel(const std::vector<float>& values, size_t per_pixel, size_t pixels, const char* name,
                   const std::string& caller) {
  if (values.empty()) return;
  if (values.size() != per_pixel * pixels)
    throw std::invalid_argument(
        caller + ": FrameGradients::" + name + " has " + std::to_string(values.size()) + " values, not " +
        std::to_string(per_pixel * pixels) + " (" + std::to_string(per_pixel) + " per pixel) or none");
  for (size_t k = 0; k < values.size(); ++k)
    if (!std::isfinite(values[k]))
      throw std::invalid_argument(caller + ": FrameGradients::" + name + "[" + std::to_string(k) +
                                  "] is not finite");
}

}  // namespace

void check_differentiable(const Camera& camera, const RenderSettings& settings, const std::string& caller) {
  auto refuse = [&](const std::string& what) {
    throw NotDifferentiable(caller + ": the backward pass does not cover " + what);
  };
  if (camera_models::drawn_model(camera) != CameraModel::kPinhole)
    refuse(std::string("the ") + camera_model_name(camera.model) + " camera model (only the pinhole's)");
  if (settings.compositor != Compositor::kSorted)
    refuse("the " + to_string(settings.compositor) + " compositor (only the sorted one)");
  if (!(settings.accuracy == AccuracyModes{}))
    refuse("the accuracy mode " + to_string(settings.accuracy) + " (only the reference)");
  if (settings.lighting.enabled()) refuse("relighting");
  if (settings.host) refuse("a host's depth");
  if (settings.lens.enabled()) refuse("depth of field (RenderSettings::lens)");
  if (settings.shutter.enabled()) refuse("motion blur (RenderSettings::shutter)");
  if (settings.accumulate_samples) refuse("accumulated samples");
  if (!settings.region.whole()) refuse("a region of the image (only the whole image)");
}

void check_frame_gradients(const FrameGradients& gradients, int width, int height,
                           const std::string& caller) {
  const size_t pixels = size_t(std::max(width, 0)) * size_t(std::max(height, 0));
  check_channel(gradients.rgb, 3, pixels, "rgb", caller);
  check_channel(gradients.alpha, 1, pixels, "alpha", caller);
  check_channel(gradients.expected_depth, 1, pixels, "expected_depth", caller);
  check_channel(gradients.accumulated_depth, 1, pixels, "accumulated_depth", caller);
}

}  // namespace tilesplat
