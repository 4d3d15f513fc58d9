#include "settings_checks.h"

#include <cmath>
#include <stdexcept>
#include <string>

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

}  // namespace tilesplat
