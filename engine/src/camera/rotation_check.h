// The one rule for a rotation given as a matrix, wherever it comes from: the camera files (cameras.json,
// transforms.json, keyframe paths), a scene file's cameras, and a host's view matrix
// (Camera::from_matrices). Orthonormal within kRotationOrthonormalTolerance, and, except for a host's view
// matrix, no reflection.
#pragma once

#include <array>
#include <optional>
#include <string>

namespace tilesplat {

// The largest |R^T R - I| element accepted. Writers of files round rotations to a few digits (a 4-digit
// rotation is off by about 1e-4); a host's float matrix is off by about 1e-7. A real scale (a view matrix
// that scales the scene) is off by far more, and refused.
inline constexpr double kRotationOrthonormalTolerance = 1e-3;

// Why the row-major 3x3 matrix is not orthonormal ("is not orthonormal (|R^T R - I| = 0.2, tolerance
// 0.001)"), or nothing when it is: a rotation, or a rotation and a mirror (which a host's view matrix may
// be: Camera::from_matrices renders it mirrored). The caller prefixes what the matrix is.
std::optional<std::string> orthonormality_problem(const std::array<double, 9>& m);

// Why it is not a rotation: orthonormality_problem's answer, or "is a reflection (determinant -1), not a
// rotation"; nothing when it is one.
std::optional<std::string> rotation_problem(const std::array<double, 9>& m);

// The transpose: world-to-camera from camera-to-world and back.
std::array<double, 9> transposed(const std::array<double, 9>& m);

}  // namespace tilesplat
