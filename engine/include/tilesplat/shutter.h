/// @file
/// Motion blur from a moving camera: a shutter open over part of the frame's time, the frame the mean of
/// pinhole frames at the shutter's times (docs/effects.md, "Motion blur").
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/effect_samples.h"
#include "tilesplat/export.h"

namespace tilesplat {

/// How a shutter exposes the image: all of it over the open interval (global), or a band at a time.
/// A rolling shutter reads the image out in `samples` bands of rows (or columns) in the scan's direction,
/// band k (counted from where the scan starts) exposed at shutter_times(open, close, samples)[k]; each
/// band's pixels are those of the frame at its time (no blur within a band). The bands split the rows
/// (columns) as evenly as integers allow; a scan of more bands than rows (columns) has one per row.
enum class ShutterScan {
  kGlobal,       ///< every pixel sees the whole open interval: the frame is the mean over its times
  kTopToBottom,  ///< rows, the top one first (most CMOS sensors)
  kBottomToTop,  ///< rows, the bottom one first
  kLeftToRight,  ///< columns, the leftmost first (a sensor mounted on its side)
  kRightToLeft,  ///< columns, the rightmost first
};
/// "global", "top-to-bottom", "bottom-to-top", "left-to-right", "right-to-left".
TILESPLAT_API const char* shutter_scan_name(ShutterScan scan);
/// The scan named so (shutter_scan_name's names); throws std::invalid_argument naming the known ones.
TILESPLAT_API ShutterScan parse_shutter_scan(const std::string& name);

/// A shutter over camera motion. The frame's time runs from 0, where the camera is the one rendered, to 1,
/// where it is `end_camera`; between them camera_between() moves it. The shutter is open from `open` to
/// `close`, and the frame is the mean, in linear light (as a ThinLens frame's: tilesplat/lens.h), of
/// `samples` pinhole frames at its times (shutter_time(open, close, pattern, i, samples)). Off (the frame it
/// always was) unless the shutter opens for a while (close > open) over a camera that moves (end_camera set),
/// or over a scene file's models that move (Renderer::render(const SceneInstances&, ...)). A rolling shutter
/// (`scan` other than ShutterScan::kGlobal) stitches its bands' frames instead of averaging them.
struct Shutter {
  double open = 0;                   ///< when the shutter opens, in [0, 1]
  double close = 0;                  ///< when it closes, in [open, 1]
  int samples = 16;  ///< times averaged, or a rolling shutter's bands: 1 to kMaxShutterSamples
  std::optional<Camera> end_camera;  ///< the camera at time 1: the same size as the rendered one
  ShutterScan scan = ShutterScan::kGlobal;  ///< global, or a rolling shutter's direction
  /// Where the times lie: the middles of `samples` equal slices (the default), or the progressive
  /// pattern that RenderSettings::accumulate_samples continues call after call (a global shutter's only:
  /// a rolling shutter's bands take the slices in order).
  SamplePattern pattern = SamplePattern::kEven;
  /// Whether the shutter blurs anything: open for a while over a camera that moves.
  bool enabled() const { return opens() && end_camera.has_value(); }
  /// Whether the shutter is open for a while (close > open): what blurs a scene's moving models
  /// (SceneInstances::moves), with or without an end camera.
  bool opens() const { return close > open; }
  /// Member-wise equality.
  bool operator==(const Shutter&) const = default;
};

/// The most time samples a frame may average.
inline constexpr int kMaxShutterSamples = 4096;

/// The times of `count` samples of a shutter open from `open` to `close`: the middles of `count` equal
/// slices, open + (i + 0.5) (close - open) / count. Throws std::invalid_argument for a count outside
/// 1..kMaxShutterSamples or times outside 0 <= open <= close <= 1.
TILESPLAT_API std::vector<double> shutter_times(double open, double close, int count);

/// Time `index` (0 <= index) of a frame of `count` samples of a shutter open from `open` to `close`,
/// placed by `pattern`: for SamplePattern::kEven shutter_times(open, close, count)[index] (index < count);
/// for SamplePattern::kSobol open + (close - open) u, u dimension 2 of effect_sample_point(index), whatever
/// the count. Throws std::invalid_argument as shutter_times does,
/// or for an index out of range.
TILESPLAT_API double shutter_time(double open, double close, SamplePattern pattern, int index, int count);

/// The camera at time `t` in [0, 1] between `start` (0) and `end` (1): the position and the intrinsics
/// blended linearly, the rotation by the shortest-arc slerp. Throws std::invalid_argument for cameras of
/// different sizes or t outside [0, 1].
TILESPLAT_API Camera camera_between(const Camera& start, const Camera& end, double t);

/// Throws std::invalid_argument naming the field for times outside 0 <= open <= close <= 1 (or not finite),
/// a sample count outside 1..kMaxShutterSamples, an end camera validate(Camera) refuses, or a rolling
/// shutter with the progressive pattern.
TILESPLAT_API void validate(const Shutter& shutter);

}  // namespace tilesplat
