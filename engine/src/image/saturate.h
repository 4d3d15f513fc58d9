// Conversions at the edge of the engine, where a frame's floats become a file's or an array's values of a
// narrower range: a finite value past the target type's range is stored as that type's largest finite value
// with its sign, and counted, instead of becoming an infinity (tilesplat::SaturatedValues). NaN passes through
// unchanged (it is no value to saturate, and finite input never makes one). The half conversion is
// exr_io.cpp's, beside OpenEXR's half type (the readers, built alone for the fuzzers, have no OpenEXR).
#pragma once

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

}  // namespace tilesplat::detail
