// The real spherical-harmonics basis to degree 3 in the 3DGS trainer's sign convention, written once for
// the reference's colour (eval_sh, in double) and its backward (in reference::Dual, whose derivatives
// carry the colour's dependence on the viewing direction to the Gaussian's mean).
#pragma once

#include <array>

namespace tilesplat::reference {

inline constexpr double kShC0 = 0.28209479177387814;
inline constexpr double kShC1 = 0.4886025119029199;
inline constexpr double kShC2[5] = {1.0925484305920792, -1.0925484305920792, 0.31539156525252005,
                                    -1.0925484305920792, 0.5462742152960396};
inline constexpr double kShC3[7] = {-0.5900435899266435, 2.890611442640554,   -0.4570457994644658,
                                    0.3731763325901154,  -0.4570457994644658, 1.445305721320277,
                                    -0.5900435899266435};

// The (degree + 1)^2 basis functions at the unit direction (x, y, z); the rest of the 16 are zero.
// A colour channel is sum_k basis[k] * coefficient[k].
template <typename S>
std::array<S, 16> sh_basis(int degree, const S& x, const S& y, const S& z) {
  std::array<S, 16> b{};
  b[0] = S(kShC0);
  if (degree < 1) return b;
  b[1] = -kShC1 * y;
  b[2] = kShC1 * z;
  b[3] = -kShC1 * x;
  if (degree < 2) return b;
  const S xx = x * x, yy = y * y, zz = z * z;
  const S xy = x * y, yz = y * z, xz = x * z;
  b[4] = kShC2[0] * xy;
  b[5] = kShC2[1] * yz;
  b[6] = kShC2[2] * (2.0 * zz - xx - yy);
  b[7] = kShC2[3] * xz;
  b[8] = kShC2[4] * (xx - yy);
  if (degree < 3) return b;
  b[9] = kShC3[0] * y * (3.0 * xx - yy);
  b[10] = kShC3[1] * xy * z;
  b[11] = kShC3[2] * y * (4.0 * zz - xx - yy);
  b[12] = kShC3[3] * z * (2.0 * zz - 3.0 * xx - 3.0 * yy);
  b[13] = kShC3[4] * x * (4.0 * zz - xx - yy);
  b[14] = kShC3[5] * z * (xx - yy);
  b[15] = kShC3[6] * x * (xx - 3.0 * yy);
  return b;
}

}  // namespace tilesplat::reference
