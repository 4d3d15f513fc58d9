// The camera's effects for Python: the thin lens (depth of field), the shutter (motion blur) and the
// sample patterns both draw from.
#include <nanobind/nanobind.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <string>

#include "bindings.h"
#include "tilesplat/camera.h"
#include "tilesplat/lens.h"
#include "tilesplat/shutter.h"

namespace tilesplat::python {

using namespace nb::literals;

void bind_effects(nb::module_& m) {
  // --- the thin lens (depth of field)
  nb::class_<ThinLens>(m, "ThinLens",
                       "A thin lens for depth of field: aperture_diameter (world units; 0 = a pinhole), "
                       "focus_distance (the view depth in focus) and samples (pinhole frames averaged).")
      .def(
          "__init__",
          [](ThinLens* lens, double aperture_diameter, double focus_distance, int samples,
             const std::string& pattern) {
            new (lens) ThinLens{aperture_diameter, focus_distance, samples, parse_sample_pattern(pattern)};
            validate(*lens);
          },
          "aperture_diameter"_a = 0.0, "focus_distance"_a = 1.0, "samples"_a = 32, "pattern"_a = "even")
      .def_rw("aperture_diameter", &ThinLens::aperture_diameter)
      .def_rw("focus_distance", &ThinLens::focus_distance)
      .def_rw("samples", &ThinLens::samples)
      .def_prop_rw(
          "pattern", [](const ThinLens& lens) { return std::string(sample_pattern_name(lens.pattern)); },
          [](ThinLens& lens, const std::string& name) { lens.pattern = parse_sample_pattern(name); },
          "'even' (the golden-angle spiral of `samples`) or 'sobol' (progressive: what accumulate_samples "
          "continues)")
      .def("__repr__", [](const ThinLens& lens) {
        return "ThinLens(aperture_diameter=" + std::to_string(lens.aperture_diameter) +
               ", focus_distance=" + std::to_string(lens.focus_distance) +
               ", samples=" + std::to_string(lens.samples) + ", pattern='" +
               sample_pattern_name(lens.pattern) + "')";
      });
  m.def(
      "lens_sample",
      [](const std::string& pattern, int index, int count) {
        return lens_sample(parse_sample_pattern(pattern), index, count);
      },
      "pattern"_a, "index"_a, "count"_a,
      "Lens position `index` of a frame of `count` samples on the unit disk: pattern 'even' (the spiral "
      "of `count`) or 'sobol' (whatever the count).");
  m.def(
      "shutter_time",
      [](double open, double close, const std::string& pattern, int index, int count) {
        return shutter_time(open, close, parse_sample_pattern(pattern), index, count);
      },
      "open"_a, "close"_a, "pattern"_a, "index"_a, "count"_a,
      "Time `index` of a frame of `count` samples of a shutter open from `open` to `close`: pattern "
      "'even' (the middles of equal slices) or 'sobol' (whatever the count).");
  m.def("effect_sample_point", &effect_sample_point, "index"_a,
        "Point `index` of the progressive sample pattern in [0, 1)^3 (Sobol's sequence shifted by 1/2): "
        "dimensions 0 and 1 place the lens position, 2 the shutter's time.");
  m.def("lens_samples", &lens_samples, "count"_a,
        "The lens positions of `count` samples on the unit disk (Vogel's golden-angle spiral), as (x, y) "
        "pairs.");
  m.def("lens_sample_camera", &lens_sample_camera, "camera"_a, "lens"_a, "sample"_a,
        "The pinhole camera of one lens position: moved on the aperture, its principal point shifted so that "
        "the focus plane stays put.");
  m.def("aperture_for_f_stop", &aperture_for_f_stop, "camera"_a, "f_stop"_a, "sensor_width_mm"_a = 36.0,
        "world_units_per_metre"_a = 1.0,
        "The aperture diameter of an f-number: the focal length over f_stop.");

  // --- the shutter (motion blur)
  nb::class_<Shutter>(m, "Shutter",
                      "A shutter open from `open` to `close` (times in [0, 1]) while the camera moves to "
                      "end_camera (at time 1); samples frames averaged.")
      .def(
          "__init__",
          [](Shutter* shutter, double open, double close, int samples, std::optional<Camera> end_camera,
             const std::string& scan, const std::string& pattern) {
            new (shutter) Shutter{open,
                                  close,
                                  samples,
                                  std::move(end_camera),
                                  parse_shutter_scan(scan),
                                  parse_sample_pattern(pattern)};
            validate(*shutter);
          },
          "open"_a = 0.0, "close"_a = 0.0, "samples"_a = 16, "end_camera"_a = nb::none(), "scan"_a = "global",
          "pattern"_a = "even")
      .def_rw("open", &Shutter::open)
      .def_rw("close", &Shutter::close)
      .def_rw("samples", &Shutter::samples)
      .def_rw("end_camera", &Shutter::end_camera)
      .def_prop_rw(
          "scan", [](const Shutter& s) { return std::string(shutter_scan_name(s.scan)); },
          [](Shutter& s, const std::string& name) { s.scan = parse_shutter_scan(name); },
          "'global' (the mean over the open interval) or a rolling shutter's 'top-to-bottom', "
          "'bottom-to-top', 'left-to-right', 'right-to-left' (samples bands, each at its time)")
      .def_prop_rw(
          "pattern", [](const Shutter& s) { return std::string(sample_pattern_name(s.pattern)); },
          [](Shutter& s, const std::string& name) { s.pattern = parse_sample_pattern(name); },
          "'even' (the middles of `samples` equal slices) or 'sobol' (progressive: what accumulate_samples "
          "continues; a global shutter's)");
  m.def("shutter_times", &shutter_times, "open"_a, "close"_a, "count"_a,
        "The times of `count` samples of a shutter: the middles of equal slices of [open, close].");
  m.def("camera_between", &camera_between, "start"_a, "end"_a, "t"_a,
        "The camera at time t between start (0) and end (1): position and intrinsics blended, rotation "
        "slerped.");
}

}  // namespace tilesplat::python
