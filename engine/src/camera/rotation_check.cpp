#include "camera/rotation_check.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace tilesplat {

std::optional<std::string> orthonormality_problem(const std::array<double, 9>& m) {
  double worst = 0;
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < 3; ++j) {
      double column_dot = 0;
      for (size_t k = 0; k < 3; ++k) column_dot += m[k * 3 + i] * m[k * 3 + j];
      worst = std::max(worst, std::abs(column_dot - (i == j ? 1.0 : 0.0)));
    }
  if (!(worst <= kRotationOrthonormalTolerance)) {
    std::ostringstream message;
    message << "is not orthonormal (|R^T R - I| = " << worst << ", tolerance "
            << kRotationOrthonormalTolerance << ")";
    return message.str();
  }
  return std::nullopt;
}

std::optional<std::string> rotation_problem(const std::array<double, 9>& m) {
  if (std::optional<std::string> problem = orthonormality_problem(m)) return problem;
  const double determinant = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                             m[2] * (m[3] * m[7] - m[4] * m[6]);
  if (determinant < 0) return "is a reflection (determinant -1), not a rotation";
  return std::nullopt;
}

std::array<double, 9> transposed(const std::array<double, 9>& m) {
  return {m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8]};
}

}  // namespace tilesplat
