/// @file
/// A thin lens in front of the pinhole camera: depth of field as the mean of pinhole frames seen from
/// points of the aperture (docs/effects.md, "Depth of field").
#pragma once

#include <array>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/effect_samples.h"
#include "tilesplat/export.h"

namespace tilesplat {

/// A thin lens: an aperture of `aperture_diameter` (world units) focused at `focus_distance` (view depth,
/// world units). A frame through it is the mean, in linear light, of `samples` pinhole frames, one from each
/// of its lens positions (lens_sample(pattern, i, samples)) scaled to the aperture, each with its principal
/// point shifted so that the plane at focus_distance stays where the pinhole camera sees it
/// (lens_sample_camera). Splats on that plane stay sharp; the others blur by their circle of confusion. An
/// aperture of 0 is the pinhole: no samples, the frame of a camera that never had a lens, to the bit and in
/// time.
///
/// "In linear light": each frame's colours are decoded from display values (A * decode(C / A), as
/// convert_colours does; decode(C) for a frame over a background, whose colours hold it), averaged, and
/// encoded back; alpha is the mean alpha, depth the alpha-weighted mean depth, splat counts the rounded mean.
struct ThinLens {
  double aperture_diameter = 0;  ///< world units; 0 = off (a pinhole)
  double focus_distance = 1;     ///< the view depth in focus, world units; > 0
  int samples = 32;              ///< lens positions averaged, 1 to kMaxLensSamples
  /// Where the positions lie: the golden-angle spiral of `samples` (the default), or the progressive
  /// pattern that RenderSettings::accumulate_samples continues call after call.
  SamplePattern pattern = SamplePattern::kEven;
  /// Whether the lens does anything (an aperture above 0).
  bool enabled() const { return aperture_diameter > 0; }
  /// Member-wise equality.
  bool operator==(const ThinLens&) const = default;
};

/// The most lens samples a frame may average.
inline constexpr int kMaxLensSamples = 4096;

/// The lens positions of a frame of `count` samples, on the unit disk: Vogel's golden-angle spiral,
/// sample i at radius sqrt((i + 0.5) / count) and angle i * pi (3 - sqrt(5)). Evenly spread for every count
/// (each sample stands for an equal area of the aperture), deterministic, and the same on every device.
/// Throws std::invalid_argument for a count outside 1..kMaxLensSamples.
TILESPLAT_API std::vector<std::array<double, 2>> lens_samples(int count);

/// Lens position `index` (0 <= index) of a frame of `count` samples placed by `pattern`, on the unit disk:
/// for SamplePattern::kEven lens_samples(count)[index] (index < count); for SamplePattern::kSobol the
/// concentric_disk_point of dimensions 0 and 1 of effect_sample_point(index), whatever the count. Throws
/// std::invalid_argument for a count outside 1..kMaxLensSamples or an index out of range.
TILESPLAT_API std::array<double, 2> lens_sample(SamplePattern pattern, int index, int count);

/// The pinhole camera of the lens position `sample` (a point of the unit disk, as lens_samples gives them):
/// the camera moved by (x, y) * aperture_diameter / 2 along its own x and y axes, its principal point moved
/// by (fx x, fy y) * aperture_diameter / (2 focus_distance) pixels the same way, so that every point at view
/// depth focus_distance projects where it does in `camera`. Throws std::invalid_argument for a lens
/// validate(ThinLens) refuses.
TILESPLAT_API Camera lens_sample_camera(const Camera& camera, const ThinLens& lens,
                                        const std::array<double, 2>& sample);

/// The aperture diameter (world units) of an f-number: the focal length over f_stop. The focal length in
/// millimetres is fx * sensor_width_mm / width (a full-frame sensor is 36 mm wide); `world_units_per_metre`
/// says how large the scene's unit is (1: the scene is in metres). Throws std::invalid_argument for a value
/// that is not positive and finite.
TILESPLAT_API double aperture_for_f_stop(const Camera& camera, double f_stop, double sensor_width_mm = 36.0,
                                         double world_units_per_metre = 1.0);

/// Throws std::invalid_argument naming the field for an aperture below 0 or not finite, or, with an
/// aperture, a focus distance that is not positive and finite or a sample count outside 1..kMaxLensSamples.
TILESPLAT_API void validate(const ThinLens& lens);

}  // namespace tilesplat
