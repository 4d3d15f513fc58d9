// Rotations as unit quaternions for interpolating cameras: a rotation matrix's quaternion, the matrix of a
// quaternion, and the shortest-arc slerp between two. Camera paths and the shutter's camera motion use them.
#pragma once

#include <array>

namespace tilesplat {

using Quaternion = std::array<double, 4>;  // w, x, y, z

// The unit quaternion of a row-major rotation matrix (Shepperd's method).
Quaternion quaternion_of(const std::array<double, 9>& rotation);
// The row-major rotation matrix of a unit quaternion.
std::array<double, 9> matrix_of(const Quaternion& q);
// The shortest-arc spherical interpolation from a (s = 0) to b (s = 1), normalised.
Quaternion slerp(const Quaternion& a, Quaternion b, double s);

}  // namespace tilesplat
