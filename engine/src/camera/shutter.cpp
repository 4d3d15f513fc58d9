// The shutter: its sample times and the camera between the frame's start and end.
#include "tilesplat/shutter.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "camera/rotation_interpolation.h"

namespace tilesplat {
namespace {

void check_times(double open, double close) {
  if (!(std::isfinite(open) && std::isfinite(close) && 0 <= open && open <= close && close <= 1))
    throw std::invalid_argument("shutter: open and close must be times with 0 <= open <= close <= 1, got " +
                                std::to_string(open) + " and " + std::to_string(close));
}

// The even pattern's time: the middle of slice `index` of `count` equal slices of [open, close].
double slice_middle(double open, double close, int index, int count) {
  return open + (index + 0.5) * (close - open) / count;
}

void check_count(const char* what, int count) {
  if (count < 1 || count > kMaxShutterSamples)
    throw std::invalid_argument(std::string(what) + ": count must be 1 to " +
                                std::to_string(kMaxShutterSamples) + ", got " + std::to_string(count));
}

}  // namespace

const char* shutter_scan_name(ShutterScan scan) {
  switch (scan) {
    case ShutterScan::kGlobal:
      return "global";
    case ShutterScan::kTopToBottom:
      return "top-to-bottom";
    case ShutterScan::kBottomToTop:
      return "bottom-to-top";
    case ShutterScan::kLeftToRight:
      return "left-to-right";
    case ShutterScan::kRightToLeft:
      return "right-to-left";
  }
  return "unknown";
}

ShutterScan parse_shutter_scan(const std::string& name) {
  for (ShutterScan scan : {ShutterScan::kGlobal, ShutterScan::kTopToBottom, ShutterScan::kBottomToTop,
                           ShutterScan::kLeftToRight, ShutterScan::kRightToLeft})
    if (name == shutter_scan_name(scan)) return scan;
  throw std::invalid_argument(
      "unknown shutter scan '" + name +
      "' (known: global, top-to-bottom, bottom-to-top, left-to-right, right-to-left)");
}

void validate(const Shutter& shutter) {
  check_times(shutter.open, shutter.close);
  if (shutter.samples < 1 || shutter.samples > kMaxShutterSamples)
    throw std::invalid_argument("shutter: samples must be 1 to " + std::to_string(kMaxShutterSamples) +
                                ", got " + std::to_string(shutter.samples));
  if (shutter.end_camera) validate(*shutter.end_camera);
  if (std::string(shutter_scan_name(shutter.scan)) == "unknown")
    throw std::invalid_argument("shutter: unknown scan " + std::to_string(int(shutter.scan)));
  if (std::string(sample_pattern_name(shutter.pattern)) == "unknown")
    throw std::invalid_argument("shutter: unknown sample pattern " + std::to_string(int(shutter.pattern)));
  if (shutter.scan != ShutterScan::kGlobal && shutter.pattern != SamplePattern::kEven)
    throw std::invalid_argument(
        "shutter: a rolling shutter exposes its bands at the even pattern's times, in order; the " +
        std::string(sample_pattern_name(shutter.pattern)) + " pattern is a global shutter's");
}

std::vector<double> shutter_times(double open, double close, int count) {
  check_times(open, close);
  check_count("shutter_times", count);
  std::vector<double> times(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) times[static_cast<size_t>(i)] = slice_middle(open, close, i, count);
  return times;
}

double shutter_time(double open, double close, SamplePattern pattern, int index, int count) {
  check_times(open, close);
  check_count("shutter_time", count);
  if (index < 0 || (pattern == SamplePattern::kEven && index >= count))
    throw std::invalid_argument("shutter_time: index " + std::to_string(index) + " is outside the " +
                                sample_pattern_name(pattern) + " pattern's " + std::to_string(count) +
                                " samples");
  if (pattern == SamplePattern::kEven) return slice_middle(open, close, index, count);
  return open + (close - open) * effect_sample_point(uint32_t(index))[2];
}

Camera camera_between(const Camera& start, const Camera& end, double t) {
  if (start.width != end.width || start.height != end.height)
    throw std::invalid_argument("camera_between: the cameras differ in size (" + std::to_string(start.width) +
                                "x" + std::to_string(start.height) + " and " + std::to_string(end.width) +
                                "x" + std::to_string(end.height) + ")");
  if (!(t >= 0 && t <= 1))
    throw std::invalid_argument("camera_between: t must be in [0, 1], got " + std::to_string(t));
  const auto blend = [t](double a, double b) { return a + (b - a) * t; };
  Camera camera = start;
  camera.fx = blend(start.fx, end.fx);
  camera.fy = blend(start.fy, end.fy);
  camera.cx = blend(start.cx, end.cx);
  camera.cy = blend(start.cy, end.cy);
  for (size_t k = 0; k < 3; ++k) camera.position[k] = blend(start.position[k], end.position[k]);
  // A camera that turns; one that does not keeps its rotation to the bit (a still camera over moving models).
  if (t > 0 && start.rotation != end.rotation)
    camera.rotation = matrix_of(slerp(quaternion_of(start.rotation), quaternion_of(end.rotation), t));
  return camera;
}

}  // namespace tilesplat
