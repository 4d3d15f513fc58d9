// The sRGB transfer function and the conversion of premultiplied images between the trained display
// values and scene-linear light (docs/colour.md).
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "image/saturate.h"
#include "tilesplat/image.h"

namespace tilesplat {

std::string to_string(ColourEncoding encoding) {
  switch (encoding) {
    case ColourEncoding::kSceneLinear:
      return "lin_rec709_scene";
    case ColourEncoding::kSrgbDisplay:
      return "srgb_rec709_display";
  }
  return "unknown";
}

// IEC 61966-2-1's pieces; the thresholds 0.04045 and 0.0031308 are where the two pieces meet.
double srgb_to_linear(double encoded) {
  const double magnitude = std::abs(encoded);
  const double linear = magnitude <= 0.04045 ? magnitude / 12.92 : std::pow((magnitude + 0.055) / 1.055, 2.4);
  return std::copysign(linear, encoded);
}

double linear_to_srgb(double linear) {
  const double magnitude = std::abs(linear);
  const double encoded =
      magnitude <= 0.0031308 ? 12.92 * magnitude : 1.055 * std::pow(magnitude, 1.0 / 2.4) - 0.055;
  return std::copysign(encoded, linear);
}

std::vector<float> convert_colours(const std::vector<float>& rgba, ColourEncoding from, ColourEncoding to,
                                   bool opaque, SaturatedValues* saturated) {
  std::vector<float> converted = rgba;
  if (from == to) return converted;
  const auto transfer = to == ColourEncoding::kSceneLinear ? srgb_to_linear : linear_to_srgb;
  std::array<uint64_t, 3> past_float{};  // per channel: conversions that passed float's range
  for (size_t pixel = 0; pixel + 3 < converted.size(); pixel += 4) {
    // The transfer function applies to a colour, not to a premultiplied value: divide by the coverage,
    // convert, multiply again. A pixel without coverage (or opaque) has its colour as it is.
    const double alpha = converted[pixel + 3];
    const bool divide = !opaque && alpha > 0.0 && alpha < 1.0;
    for (size_t c = 0; c < 3; ++c) {
      const double value = converted[pixel + c];
      converted[pixel + c] =
          detail::saturate_to_float(divide ? alpha * transfer(value / alpha) : transfer(value), past_float[c]);
    }
  }
  if (saturated)
    for (size_t c = 0; c < 3; ++c)
      if (past_float[c] > 0) saturated->channels[std::string(1, "RGB"[c])] += past_float[c];
  return converted;
}

uint64_t SaturatedValues::total() const {
  uint64_t sum = 0;
  for (const auto& [name, count] : channels) sum += count;
  return sum;
}

std::string SaturatedValues::describe() const {
  const uint64_t sum = total();
  if (sum == 0) return "none";
  std::string list;
  for (const auto& [name, count] : channels) {
    if (count == 0) continue;
    if (!list.empty()) list += ", ";
    list += name + " " + std::to_string(count);
  }
  return std::to_string(sum) + (sum == 1 ? " value (" : " values (") + list + ")";
}

SaturatedValues& SaturatedValues::operator+=(const SaturatedValues& other) {
  for (const auto& [name, count] : other.channels) channels[name] += count;
  return *this;
}

}  // namespace tilesplat
