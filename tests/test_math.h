// Small independent 3D math for the tests' expected values (not the library's): row-major 3x3 matrices,
// their products, and the rotation matrix of a quaternion.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

namespace tilesplat::testing::math {

using Vec3 = std::array<double, 3>;
using Matrix3 = std::array<double, 9>;  // row-major

inline Matrix3 multiply(const Matrix3& a, const Matrix3& b) {
  Matrix3 out{};
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < 3; ++j)
      for (size_t k = 0; k < 3; ++k) out[i * 3 + j] += a[i * 3 + k] * b[k * 3 + j];
  return out;
}

inline Vec3 times(const Matrix3& m, const Vec3& v) {
  return {m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
          m[6] * v[0] + m[7] * v[1] + m[8] * v[2]};
}

// The rotation of the quaternion (w, x, y, z), normalized first (any sign gives the same matrix).
inline Matrix3 quaternion_matrix(double w, double x, double y, double z) {
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  w /= n, x /= n, y /= n, z /= n;
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

}  // namespace tilesplat::testing::math
