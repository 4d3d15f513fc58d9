#include "host_depth.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "camera/camera_models.h"

namespace tilesplat {

void validate_host_depth(const RenderSettings& settings, const Camera& camera) {
  if (!settings.host) return;
  const HostDepth& host = *settings.host;
  auto fail = [](const std::string& why) { throw std::invalid_argument("host depth: " + why); };
  if (settings.compositor == Compositor::kStochastic)
    fail(
        "the stochastic compositor does not depth-test against a host's surfaces: use the sorted compositor");
  // The raster compositor's depth attachment holds view depths times 2^-64, normal floats from 2^-62.
  if (settings.compositor == Compositor::kRaster && !(settings.near_plane >= 0x1p-62))
    fail("the raster compositor tests a host's depth for view depths above 2^-62; the near plane is " +
         std::to_string(settings.near_plane));
  if (settings.accuracy.resort_window > 0)
    fail("per-pixel re-sorting (resort" + std::to_string(settings.accuracy.resort_window) +
         ") does not depth-test against a host's surfaces: render without it");
  if (camera_models::drawn_model(camera) != CameraModel::kPinhole)
    fail(std::string("a host's depth buffer is a pinhole projection's; the camera is ") +
         camera_model_name(camera.model));
  if (!std::isfinite(host.convention.a) || !std::isfinite(host.convention.b) || host.convention.b == 0)
    fail("the depth convention must have finite a and b, b not 0 (DepthConvention::from_projection)");
  if (!(host.alpha_threshold > 0.0f && host.alpha_threshold <= 1.0f))
    fail("alpha_threshold must be in (0, 1], not " + std::to_string(host.alpha_threshold));
  const size_t pixels = size_t(camera.width) * size_t(camera.height);
  if (!host.depth.empty() && host.depth.size() != pixels)
    fail("the depth image has " + std::to_string(host.depth.size()) + " values, the camera's image " +
         std::to_string(camera.width) + "x" + std::to_string(camera.height) + " needs " +
         std::to_string(pixels));
  for (size_t i = 0; i < host.depth.size(); ++i)
    if (std::isnan(host.depth[i]))
      fail("the depth image is NaN at pixel (" + std::to_string(i % size_t(camera.width)) + ", " +
           std::to_string(i / size_t(camera.width)) + ")");
}

std::vector<float> host_view_depths(const HostDepth& host) {
  std::vector<float> view_depth(host.depth.size());
  for (size_t i = 0; i < host.depth.size(); ++i)
    view_depth[i] = float(host.convention.view_depth(host.depth[i]));
  return view_depth;
}

float host_depth_out(const HostDepth& host, double surface_z, size_t pixel) {
  if (surface_z > 0) return float(host.convention.window_depth(surface_z));
  return host.depth.empty() ? float(host.convention.far_depth()) : host.depth[pixel];
}

}  // namespace tilesplat
