// What every reader of camera files checks of a rotation it is given as a matrix.
#pragma once

#include <array>
#include <optional>
#include <string>

namespace tilesplat {

// Rotations read from files are rounded to a few digits by their writers; this much is accepted.
inline constexpr double kRotationOrthonormalTolerance = 1e-3;

// Why the row-major 3x3 matrix is not a rotation ("is not orthonormal (|R^T R - I| = 0.2,
// tolerance 0.001)" or "is a reflection (determinant -1), not a rotation"), or nothing when it is.
// The caller prefixes what the matrix is.
std::optional<std::string> rotation_problem(const std::array<double, 9>& m);

// The transpose: world-to-camera from camera-to-world and back.
std::array<double, 9> transposed(const std::array<double, 9>& m);

}  // namespace tilesplat
