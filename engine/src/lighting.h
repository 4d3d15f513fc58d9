// Relighting's lights in the form both renderers evaluate (tilesplat::Lighting has the model): made
// once per frame, in float64, so that the float64 reference and the GPU projection start from the
// same bits (the GPU reads these doubles from its light buffer).
#pragma once

#include <array>
#include <vector>

#include "tilesplat/render_settings.h"

namespace tilesplat {

struct PreparedLight {
  bool point = false;
  // Directional: w, the unit vector toward the light (-direction normalized). Point: its position.
  std::array<double, 3> vector = {0, 0, 0};
  std::array<double, 3> radiance = {0, 0, 0};  // color * intensity
};

struct PreparedLighting {
  std::array<double, 3> ambient = {0, 0, 0};
  std::vector<PreparedLight> lights;
};

// Validates (tilesplat::validate) and converts.
PreparedLighting prepare_lighting(const Lighting& lighting);

// The factor the unlit colour is multiplied by, for a splat at `x` with the unit normal `n` (already
// turned toward the camera). The GPU (projection.comp, light_factor) runs the same operations in the
// same order.
std::array<double, 3> light_factor(const PreparedLighting& lighting, const std::array<double, 3>& x,
                                   const std::array<double, 3>& n);

}  // namespace tilesplat
