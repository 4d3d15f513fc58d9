/// @file
/// Where an averaged effect takes its samples: the lens positions of depth of field and the shutter times
/// of motion blur, spread for a count known in advance or as one progressive sequence
/// (docs/effects.md, "Sample patterns").
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "tilesplat/export.h"

namespace tilesplat {

/// How a ThinLens places its lens positions and a Shutter its times.
enum class SamplePattern {
  /// Spread for the frame's count N (the default): the lens's golden-angle spiral over N, the shutter's
  /// middles of N equal slices. The N samples change with N, so a frame of N is not a prefix of a frame
  /// of 2N.
  kEven,
  /// Progressive: sample i is point i of effect_sample_point() whatever the count, so that a frame of N
  /// samples is the first N of any longer frame's, and samples can be added call after call
  /// (RenderSettings::accumulate_samples). Every power-of-two prefix is stratified.
  kSobol,
};
/// "even", "sobol".
TILESPLAT_API const char* sample_pattern_name(SamplePattern pattern);
/// The pattern named so (sample_pattern_name's names); throws std::invalid_argument naming the known ones.
TILESPLAT_API SamplePattern parse_sample_pattern(const std::string& name);

/// Point `index` of the progressive pattern in [0, 1)^3: the first three dimensions of Sobol's sequence
/// (direction numbers of Joe and Kuo), each Owen-scrambled with a fixed seed (Burley's hash-based nested
/// uniform scramble), so that a point lies anywhere within its stratum rather than on the strata's corners,
/// whose bias would leave the mean of N samples a fraction 1/(2N) off the middle. Dimensions 0 and 1 place
/// the lens position (a (0,2)-sequence: each aligned block of 2^k points has one point in every dyadic box
/// of area 2^-k, which the scramble keeps), dimension 2 the shutter's time (one point in each of 2^k equal
/// slices), so that the lens and the time of one sample are independent. Multiples of 2^-32, exact in
/// double precision; the same on every device.
TILESPLAT_API std::array<double, 3> effect_sample_point(uint32_t index);

/// The unit square onto the unit disk by Shirley and Chiu's concentric map: area-preserving (a uniform
/// point of the square is a uniform point of the disk) and continuous, so that strata of the square stay
/// compact on the disk. (0.5, 0.5) goes to the centre.
TILESPLAT_API std::array<double, 2> concentric_disk_point(double u, double v);

}  // namespace tilesplat
