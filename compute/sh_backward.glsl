// The SH basis to degree 3 (sh.glsl's constants, signs and order) and its derivatives with respect to
// the direction, for the projection backward: colour_c = sum_k basis_k(dir) coefficient_(k, c) + 0.5, so
// d colour_c / d coefficient_(k, c) = basis_k, and d colour_c / d dir = sum_k coefficient_(k, c) grad basis_k.
// The including shader defines `real` and `real3`.

// The 16 basis values at the unit direction d (the unused bands zero).
void sh_basis(int degree, real3 d, out real basis[16]) {
  for (int k = 0; k < 16; ++k) basis[k] = 0.0;
  real x = d.x, y = d.y, z = d.z;
  basis[0] = real(SH_C0);
  if (degree < 1) return;
  basis[1] = -real(SH_C1) * y;
  basis[2] = real(SH_C1) * z;
  basis[3] = -real(SH_C1) * x;
  if (degree < 2) return;
  real xx = x * x, yy = y * y, zz = z * z;
  basis[4] = real(SH_C2[0]) * x * y;
  basis[5] = real(SH_C2[1]) * y * z;
  basis[6] = real(SH_C2[2]) * (2.0 * zz - xx - yy);
  basis[7] = real(SH_C2[3]) * x * z;
  basis[8] = real(SH_C2[4]) * (xx - yy);
  if (degree < 3) return;
  basis[9] = real(SH_C3[0]) * y * (3.0 * xx - yy);
  basis[10] = real(SH_C3[1]) * x * y * z;
  basis[11] = real(SH_C3[2]) * y * (4.0 * zz - xx - yy);
  basis[12] = real(SH_C3[3]) * z * (2.0 * zz - 3.0 * xx - 3.0 * yy);
  basis[13] = real(SH_C3[4]) * x * (4.0 * zz - xx - yy);
  basis[14] = real(SH_C3[5]) * z * (xx - yy);
  basis[15] = real(SH_C3[6]) * x * (xx - 3.0 * yy);
}

// d basis_k / d (x, y, z) at d, the basis taken as the polynomials above (the caller carries the
// gradient through the normalization of the direction).
void sh_basis_gradient(int degree, real3 d, out real3 gradient[16]) {
  for (int k = 0; k < 16; ++k) gradient[k] = real3(0.0);
  if (degree < 1) return;
  real x = d.x, y = d.y, z = d.z;
  gradient[1] = real3(0.0, -real(SH_C1), 0.0);
  gradient[2] = real3(0.0, 0.0, real(SH_C1));
  gradient[3] = real3(-real(SH_C1), 0.0, 0.0);
  if (degree < 2) return;
  real xx = x * x, yy = y * y, zz = z * z;
  gradient[4] = real(SH_C2[0]) * real3(y, x, 0.0);
  gradient[5] = real(SH_C2[1]) * real3(0.0, z, y);
  gradient[6] = real(SH_C2[2]) * real3(-2.0 * x, -2.0 * y, 4.0 * z);
  gradient[7] = real(SH_C2[3]) * real3(z, 0.0, x);
  gradient[8] = real(SH_C2[4]) * real3(2.0 * x, -2.0 * y, 0.0);
  if (degree < 3) return;
  gradient[9] = real(SH_C3[0]) * real3(6.0 * x * y, 3.0 * xx - 3.0 * yy, 0.0);
  gradient[10] = real(SH_C3[1]) * real3(y * z, x * z, x * y);
  gradient[11] = real(SH_C3[2]) * real3(-2.0 * x * y, 4.0 * zz - xx - 3.0 * yy, 8.0 * y * z);
  gradient[12] = real(SH_C3[3]) * real3(-6.0 * x * z, -6.0 * y * z, 6.0 * zz - 3.0 * xx - 3.0 * yy);
  gradient[13] = real(SH_C3[4]) * real3(4.0 * zz - 3.0 * xx - yy, -2.0 * x * y, 8.0 * x * z);
  gradient[14] = real(SH_C3[5]) * real3(2.0 * x * z, -2.0 * y * z, xx - yy);
  gradient[15] = real(SH_C3[6]) * real3(3.0 * xx - 3.0 * yy, -6.0 * x * y, 0.0);
}
