// The effects' sample patterns: Sobol's sequence in three dimensions and the concentric map onto the disk.
#include "tilesplat/effect_samples.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "shader_io.h"

namespace tilesplat {
namespace {

// Direction numbers v[d][k] (bit k of the index contributes v[d][k] to dimension d), 32 bits each, from
// the primitive polynomials and initial numbers m of Joe and Kuo's table: dimension 0 is van der Corput's
// sequence (v = 2^(31 - k)); dimension 1 has the polynomial x + 1 (m1 = 1); dimension 2 x^2 + x + 1
// (m1 = 1, m2 = 3). m_k = 2 a_1 m_(k-1) ^ ... ^ 2^(s-1) a_(s-1) m_(k-s+1) ^ 2^s m_(k-s) ^ m_(k-s).
struct Directions {
  std::array<std::array<uint32_t, 32>, 3> v{};
};

constexpr Directions make_directions() {
  Directions d;
  for (int k = 0; k < 32; ++k) d.v[0][k] = uint32_t(1) << (31 - k);
  // Dimension 1: s = 1, no a_j.
  std::array<uint64_t, 33> m{};
  m[1] = 1;
  for (int k = 2; k <= 32; ++k) m[k] = (m[k - 1] << 1) ^ m[k - 1];
  for (int k = 1; k <= 32; ++k) d.v[1][k - 1] = uint32_t(m[k] << (32 - k));
  // Dimension 2: s = 2, a_1 = 1.
  m = {};
  m[1] = 1;
  m[2] = 3;
  for (int k = 3; k <= 32; ++k) m[k] = (m[k - 1] << 1) ^ (m[k - 2] << 2) ^ m[k - 2];
  for (int k = 1; k <= 32; ++k) d.v[2][k - 1] = uint32_t(m[k] << (32 - k));
  return d;
}

constexpr Directions kDirections = make_directions();

uint32_t reverse_bits(uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}

// Owen's nested uniform scramble in base 2 by Burley's hash ("Practical Hash-based Owen Scrambling", JCGT
// 2020): on the bit-reversed value, Laine and Karras's permutation, in which each bit changes only the
// bits above it, so that each digit of the value is flipped by a hash of the digits before it. Elementary
// boxes map to elementary boxes (the net stays a net), and each point lands uniformly within its box.
uint32_t owen_scramble(uint32_t value, uint32_t seed) {
  using namespace shader_io;  // the multipliers composite_stochastic.comp scrambles with too
  uint32_t x = reverse_bits(value);
  x += seed;
  x ^= x * LAINE_KARRAS_MULTIPLIER_0;
  x ^= x * LAINE_KARRAS_MULTIPLIER_1;
  x ^= x * LAINE_KARRAS_MULTIPLIER_2;
  x ^= x * LAINE_KARRAS_MULTIPLIER_3;
  return reverse_bits(x);
}

// One fixed scramble per dimension: the pattern is the same on every device and run.
constexpr std::array<uint32_t, 3> kScrambleSeeds = {0x2c1b3c6du, 0x297a2d39u, 0x8b4f1d3fu};

}  // namespace

const char* sample_pattern_name(SamplePattern pattern) {
  switch (pattern) {
    case SamplePattern::kEven:
      return "even";
    case SamplePattern::kSobol:
      return "sobol";
  }
  return "unknown";
}

SamplePattern parse_sample_pattern(const std::string& name) {
  for (SamplePattern pattern : {SamplePattern::kEven, SamplePattern::kSobol})
    if (name == sample_pattern_name(pattern)) return pattern;
  throw std::invalid_argument("unknown sample pattern '" + name + "' (known: even, sobol)");
}

std::array<double, 3> effect_sample_point(uint32_t index) {
  std::array<double, 3> point{};
  for (size_t dim = 0; dim < 3; ++dim) {
    uint32_t bits = 0;
    for (int k = 0; k < 32; ++k)
      if (index & (uint32_t(1) << k)) bits ^= kDirections.v[dim][size_t(k)];
    point[dim] = std::ldexp(double(owen_scramble(bits, kScrambleSeeds[dim])), -32);
  }
  return point;
}

std::array<double, 2> concentric_disk_point(double u, double v) {
  const double a = 2 * u - 1, b = 2 * v - 1;
  if (a == 0 && b == 0) return {0, 0};
  const double quarter = std::numbers::pi / 4;
  double radius, angle;
  if (std::abs(a) > std::abs(b)) {
    radius = a;
    angle = quarter * (b / a);
  } else {
    radius = b;
    angle = 2 * quarter - quarter * (a / b);
  }
  return {radius * std::cos(angle), radius * std::sin(angle)};
}

}  // namespace tilesplat
