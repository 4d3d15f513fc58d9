// Conversions at the edge of the engine, where a frame's floats become a file's or an array's values of a
// narrower range: a finite value past the target type's range is stored as that type's largest finite
// value with its sign, and counted, instead of becoming an infinity (tilesplat::SaturatedValues). NaN
// passes through unchanged (it is no value to saturate, and finite input never makes one).
#pragma once

#include <half.h>

#include <cmath>
#include <cstdint>
#include <limits>

namespace tilesplat::detail {

// A double stored as a float: past +-FLT_MAX (where the cast would give an infinity) the largest finite
// float with the value's sign, counted in `saturated`. An infinite input is saturated too: the double
// arithmetic of a conversion may overflow where the float would have.
inline float saturate_to_float(double value, uint64_t& saturated) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (std::abs(value) > kMax) {
    ++saturated;
    return static_cast<float>(std::copysign(kMax, value));
  }
  return static_cast<float>(value);
}

// A float stored as OpenEXR's half: past +-65504 (HALF_MAX; half rounds 65520 and above to an infinity)
// the largest finite half with the value's sign, counted in `saturated`.
inline Imath::half saturate_to_half(float value, uint64_t& saturated) {
  constexpr float kMax = 65504.0f;
  if (std::abs(value) > kMax) {
    ++saturated;
    return Imath::half(std::copysign(kMax, value));
  }
  return Imath::half(value);
}

}  // namespace tilesplat::detail
