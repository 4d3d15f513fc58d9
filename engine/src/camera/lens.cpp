// The thin lens: its sample positions, the pinhole camera of each, and the aperture of an f-number.
#include "tilesplat/lens.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace tilesplat {
namespace {

bool positive_finite(double value) {
  return std::isfinite(value) && value > 0;
}

}  // namespace

void validate(const ThinLens& lens) {
  if (!(std::isfinite(lens.aperture_diameter) && lens.aperture_diameter >= 0))
    throw std::invalid_argument("lens: aperture_diameter must be 0 or above and finite, got " +
                                std::to_string(lens.aperture_diameter));
  if (!lens.enabled()) return;
  if (!positive_finite(lens.focus_distance))
    throw std::invalid_argument("lens: focus_distance must be a positive, finite view depth, got " +
                                std::to_string(lens.focus_distance));
  if (std::string(sample_pattern_name(lens.pattern)) == "unknown")
    throw std::invalid_argument("lens: unknown sample pattern " + std::to_string(int(lens.pattern)));
  if (lens.samples < 1 || lens.samples > kMaxLensSamples)
    throw std::invalid_argument("lens: samples must be 1 to " + std::to_string(kMaxLensSamples) + ", got " +
                                std::to_string(lens.samples));
}

namespace {

void check_lens_count(const char* what, int count) {
  if (count < 1 || count > kMaxLensSamples)
    throw std::invalid_argument(std::string(what) + ": count must be 1 to " +
                                std::to_string(kMaxLensSamples) + ", got " + std::to_string(count));
}

// Vogel's spiral: sample i of `count`.
std::array<double, 2> spiral_sample(int index, int count) {
  const double golden_angle = std::numbers::pi * (3.0 - std::sqrt(5.0));
  const double radius = std::sqrt((index + 0.5) / count);
  const double angle = index * golden_angle;
  return {radius * std::cos(angle), radius * std::sin(angle)};
}

}  // namespace

std::vector<std::array<double, 2>> lens_samples(int count) {
  check_lens_count("lens_samples", count);
  std::vector<std::array<double, 2>> samples(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) samples[static_cast<size_t>(i)] = spiral_sample(i, count);
  return samples;
}

std::array<double, 2> lens_sample(SamplePattern pattern, int index, int count) {
  check_lens_count("lens_sample", count);
  if (index < 0 || (pattern == SamplePattern::kEven && index >= count))
    throw std::invalid_argument("lens_sample: index " + std::to_string(index) + " is outside the " +
                                sample_pattern_name(pattern) + " pattern's " + std::to_string(count) +
                                " samples");
  if (pattern == SamplePattern::kEven) return spiral_sample(index, count);
  const std::array<double, 3> point = effect_sample_point(uint32_t(index));
  return concentric_disk_point(point[0], point[1]);
}

Camera lens_sample_camera(const Camera& camera, const ThinLens& lens, const std::array<double, 2>& sample) {
  validate(lens);
  if (!(std::isfinite(sample[0]) && std::isfinite(sample[1])))
    throw std::invalid_argument("lens_sample_camera: the sample position must be finite");
  const double radius = 0.5 * lens.aperture_diameter;
  const double dx = sample[0] * radius, dy = sample[1] * radius;  // along the camera's x and y
  Camera moved = camera;
  // The rotation's rows are the camera's axes in world space.
  for (int k = 0; k < 3; ++k) moved.position[k] += dx * camera.rotation[k] + dy * camera.rotation[3 + k];
  if (lens.enabled()) {
    moved.cx += camera.fx * dx / lens.focus_distance;
    moved.cy += camera.fy * dy / lens.focus_distance;
  }
  return moved;
}

double aperture_for_f_stop(const Camera& camera, double f_stop, double sensor_width_mm,
                           double world_units_per_metre) {
  if (!positive_finite(f_stop))
    throw std::invalid_argument("f-stop must be positive and finite, got " + std::to_string(f_stop));
  if (!positive_finite(sensor_width_mm))
    throw std::invalid_argument("sensor width must be positive and finite, got " +
                                std::to_string(sensor_width_mm));
  if (!positive_finite(world_units_per_metre))
    throw std::invalid_argument("world units per metre must be positive and finite, got " +
                                std::to_string(world_units_per_metre));
  validate(camera);
  const double focal_mm = camera.fx * sensor_width_mm / camera.width;
  return focal_mm / f_stop / 1000.0 * world_units_per_metre;
}

}  // namespace tilesplat
