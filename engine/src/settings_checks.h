// The checks of RenderSettings values that the GPU frame (plan_frame) and the float64 reference share,
// so that both refuse the same values in the same words.
#pragma once

#include "tilesplat/render_settings.h"

namespace tilesplat {

// RenderSettings::near_plane: positive and finite. Throws std::invalid_argument.
void check_near_plane(double near_plane);
// RenderSettings::max_alpha: finite, above accuracy.alpha_cutoff and below 1. Throws std::invalid_argument.
void check_max_alpha(const RenderSettings& settings);

}  // namespace tilesplat
