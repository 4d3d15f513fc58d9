#include "lens_options.h"

#include <cmath>

#include "cli.h"

namespace tilesplat::cli {

void add_lens_options(ArgParser& parser, LensFlags& flags, const std::string& samples_help) {
  parser.section("depth of field (a thin lens: the mean of --lens-samples pinhole frames over the aperture)");
  const auto positive = [](const char* flag, const std::string& text) {
    const double value = parse_double(flag, text);
    if (!(value > 0 && std::isfinite(value)))
      throw UsageError(std::string(flag) + " must be a positive number, got " + single_quoted(text));
    return value;
  };
  parser.add_value(
      "--aperture", "D", "the lens's aperture diameter, in the scene's units",
      [&flags, positive](const std::string& text) { flags.aperture = positive("--aperture", text); });
  parser.add_value(
      "--f-stop", "N",
      "the aperture as an f-number: the focal length (fx and --sensor-width) over N, in metres "
      "times --units-per-metre",
      [&flags, positive](const std::string& text) { flags.f_stop = positive("--f-stop", text); });
  parser.add_value("--focus-distance", "Z",
                   "the view depth in focus, in the scene's units (default: the scene's centre)",
                   [&flags, positive](const std::string& text) {
                     flags.focus_distance = positive("--focus-distance", text);
                   });
  parser.add_int("--lens-samples", "N", samples_help, &flags.samples, 1, kMaxLensSamples);
  parser.add_value("--sensor-width", "MM",
                   "the sensor's width for --f-stop, in millimetres (default 36: full frame)",
                   [&flags, positive](const std::string& text) {
                     flags.sensor_width_mm = positive("--sensor-width", text);
                   });
  parser.add_value("--units-per-metre", "U", "the scene's units in a metre, for --f-stop (default 1)",
                   [&flags, positive](const std::string& text) {
                     flags.units_per_metre = positive("--units-per-metre", text);
                   });
}

void check_lens_options(const ArgParser& parser, const LensFlags& flags) {
  if (flags.aperture && flags.f_stop)
    throw UsageError("--aperture and --f-stop both give the aperture: one of them");
  if (!flags.enabled())
    for (const char* lens_flag :
         {"--focus-distance", "--lens-samples", "--sensor-width", "--units-per-metre"})
      if (parser.seen(lens_flag))
        throw UsageError(std::string(lens_flag) +
                         " shapes the lens, and neither --aperture nor --f-stop gave one");
  if (!flags.f_stop)
    for (const char* f_stop_flag : {"--sensor-width", "--units-per-metre"})
      if (parser.seen(f_stop_flag)) throw UsageError(std::string(f_stop_flag) + " applies to --f-stop only");
}

ThinLens lens_for_frame(const LensFlags& flags, const Camera& camera,
                        const std::array<double, 3>& scene_centre) {
  if (!flags.enabled()) return {};
  ThinLens lens;
  lens.samples = flags.samples;
  lens.pattern = flags.pattern;
  lens.aperture_diameter = flags.aperture ? *flags.aperture
                                          : aperture_for_f_stop(camera, *flags.f_stop, flags.sensor_width_mm,
                                                                flags.units_per_metre);
  if (flags.focus_distance) {
    lens.focus_distance = *flags.focus_distance;
  } else {
    lens.focus_distance = camera.to_camera(scene_centre)[2];
    if (!(lens.focus_distance > 0))
      throw UsageError("the scene's centre is behind the camera: give --focus-distance");
  }
  return lens;
}

std::string lens_text(const LensFlags& flags) {
  if (!flags.enabled()) return {};
  std::string text = flags.aperture ? "aperture:" + format_number(*flags.aperture, 6)
                                    : "f/" + format_number(*flags.f_stop, 3) +
                                          ":sensor:" + format_number(flags.sensor_width_mm, 3) +
                                          "mm:units-per-metre:" + format_number(flags.units_per_metre, 6);
  text += ",focus:" +
          (flags.focus_distance ? format_number(*flags.focus_distance, 6) : std::string("scene-centre"));
  text += ",samples:" + std::to_string(flags.samples);
  if (flags.pattern != SamplePattern::kEven)
    text += std::string(",pattern:") + sample_pattern_name(flags.pattern);
  return text;
}

}  // namespace tilesplat::cli
