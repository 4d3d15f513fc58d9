// Relighting: validation of the lights and the per-splat light factor of the float64 reference.
#include "lighting.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace tilesplat {
namespace {

std::string vector_text(const std::array<float, 3>& v) {
  char text[96];
  std::snprintf(text, sizeof(text), "(%g, %g, %g)", double(v[0]), double(v[1]), double(v[2]));
  return text;
}

std::string number_text(float v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", double(v));
  return text;
}

[[noreturn]] void bad(const std::string& field, const std::string& why) {
  throw std::invalid_argument("lighting." + field + ": " + why);
}

bool finite(const std::array<float, 3>& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

// Radiances: finite and non-negative (a negative light would subtract colour, a NaN poison it).
void check_radiance(const std::string& field, const std::array<float, 3>& v) {
  if (!finite(v) || v[0] < 0 || v[1] < 0 || v[2] < 0)
    bad(field, "must be finite and non-negative, got " + vector_text(v));
}

double dot(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

}  // namespace

void validate(const Lighting& lighting) {
  check_radiance("ambient", lighting.ambient);
  for (size_t i = 0; i < lighting.lights.size(); ++i) {
    const Light& light = lighting.lights[i];
    const std::string name = "lights[" + std::to_string(i) + "].";
    if (light.type != Light::Type::kDirectional && light.type != Light::Type::kPoint)
      bad(name + "type", "must be directional or point");
    if (light.type == Light::Type::kDirectional) {
      if (!finite(light.direction)) bad(name + "direction", "must be finite, got " + vector_text(light.direction));
      if (light.direction[0] == 0 && light.direction[1] == 0 && light.direction[2] == 0)
        bad(name + "direction", "must not be zero: it says where the light travels");
    } else if (!finite(light.position)) {
      bad(name + "position", "must be finite, got " + vector_text(light.position));
    }
    check_radiance(name + "color", light.color);
    if (!std::isfinite(light.intensity) || light.intensity < 0)
      bad(name + "intensity", "must be finite and non-negative, got " + number_text(light.intensity));
  }
}

PreparedLighting prepare_lighting(const Lighting& lighting) {
  validate(lighting);
  PreparedLighting out;
  for (size_t c = 0; c < 3; ++c) out.ambient[c] = lighting.ambient[c];
  for (const Light& light : lighting.lights) {
    PreparedLight p;
    p.point = light.type == Light::Type::kPoint;
    if (p.point) {
      for (size_t c = 0; c < 3; ++c) p.vector[c] = light.position[c];
    } else {
      // In double a non-zero float direction has a non-zero, finite length: no underflow, no overflow.
      const std::array<double, 3> d = {light.direction[0], light.direction[1], light.direction[2]};
      const double length = std::sqrt(dot(d, d));
      for (size_t c = 0; c < 3; ++c) p.vector[c] = -d[c] / length;
    }
    for (size_t c = 0; c < 3; ++c) p.radiance[c] = double(light.color[c]) * double(light.intensity);
    out.lights.push_back(p);
  }
  return out;
}

std::array<double, 3> light_factor(const PreparedLighting& lighting, const std::array<double, 3>& x,
                                   const std::array<double, 3>& n) {
  std::array<double, 3> factor = lighting.ambient;
  for (const PreparedLight& light : lighting.lights) {
    std::array<double, 3> w = light.vector;
    double falloff = 1;
    if (light.point) {
      const std::array<double, 3> d = {light.vector[0] - x[0], light.vector[1] - x[1], light.vector[2] - x[2]};
      const double distance2 = dot(d, d);
      if (!(distance2 > 0)) continue;  // the splat is at the light: no direction, no light
      const double distance = std::sqrt(distance2);
      for (size_t c = 0; c < 3; ++c) w[c] = d[c] / distance;
      falloff = 1 / distance2;
    }
    const double cosine = dot(n, w);
    if (cosine > 0)
      for (size_t c = 0; c < 3; ++c) factor[c] += light.radiance[c] * (cosine * falloff);
  }
  return factor;
}

}  // namespace tilesplat
