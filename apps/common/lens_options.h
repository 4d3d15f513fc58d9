// Depth of field from the command line, as tilesplat-render and tilesplat-viewer take it: --aperture or
// --f-stop (through --sensor-width and --units-per-metre), --focus-distance and --lens-samples.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "arg_parser.h"
#include "tilesplat/camera.h"
#include "tilesplat/lens.h"

namespace tilesplat::cli {

// An aperture (a diameter, or an f-number through the sensor's width and the scene's scale), focused at a
// view depth or, unless --focus-distance says, at the scene's centre as each frame's camera sees it.
struct LensFlags {
  std::optional<double> aperture;                // --aperture D, world units
  std::optional<double> f_stop;                  // --f-stop N
  std::optional<double> focus_distance;          // --focus-distance Z
  double sensor_width_mm = 36.0;                 // --sensor-width MM
  double units_per_metre = 1.0;                  // --units-per-metre U
  int samples = 32;                              // --lens-samples N
  SamplePattern pattern = SamplePattern::kEven;  // tilesplat-render's --sample-pattern; the viewer's sobol
  bool enabled() const { return aperture.has_value() || f_stop.has_value(); }
};

// Declares the flags in a "depth of field" section; `samples_help` says what --lens-samples counts.
void add_lens_options(ArgParser& parser, LensFlags& flags, const std::string& samples_help);
// --aperture with --f-stop, a lens-shaping flag without an aperture, an f-number flag without --f-stop.
// Throws UsageError.
void check_lens_options(const ArgParser& parser, const LensFlags& flags);

// The lens of one frame: the flags' aperture and focus for `camera`, the focus on `scene_centre` unless
// --focus-distance was given. Off (the pinhole) without --aperture or --f-stop. Throws UsageError for a
// scene centre behind the camera when it would be the focus.
ThinLens lens_for_frame(const LensFlags& flags, const Camera& camera,
                        const std::array<double, 3>& scene_centre);
// "aperture:D,focus:Z,samples:N" (f/N for an f-number, focus:scene-centre by default, ",pattern:sobol" for
// the progressive pattern), for the EXR's renderSettings; empty when off.
std::string lens_text(const LensFlags& flags);

}  // namespace tilesplat::cli
