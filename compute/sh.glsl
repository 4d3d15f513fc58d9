// Real spherical harmonics to degree 3, as in the original 3DGS rasterizer (same constants, signs,
// and coefficient order). Coefficients are coefficient-major with RGB innermost.

const float SH_C0 = 0.28209479177387814;
const float SH_C1 = 0.4886025119029199;
const float SH_C2[5] = float[5](1.0925484305920792, -1.0925484305920792, 0.31539156525252005,
                                -1.0925484305920792, 0.5462742152960396);
const float SH_C3[7] = float[7](-0.5900435899266435, 2.890611442640554, -0.4570457994644658,
                                0.3731763325901154, -0.4570457994644658, 1.445305721320277,
                                -0.5900435899266435);

// The including shader declares SH_COEFFS (coefficients stored per Gaussian: the scene's, which may
// be more than the evaluated degree uses) and SH_HALF (stored as packed 16-bit floats, two a uint).
// It also declares sh_word(sh, i): word i of the coefficients (a float's bits, or two halves).
vec3 sh_coeff(uint64_t sh, uint base, uint k) {
  uint o = base + 3 * k;
  if (SH_HALF) {
    // Three consecutive halves start on either half of a word.
    vec2 w0 = unpackHalf2x16(sh_word(sh, o >> 1));
    vec2 w1 = unpackHalf2x16(sh_word(sh, (o >> 1) + 1));
    return (o & 1u) == 0u ? vec3(w0, w1.x) : vec3(w0.y, w1);
  }
  return uintBitsToFloat(uvec3(sh_word(sh, o), sh_word(sh, o + 1), sh_word(sh, o + 2)));
}

// degree is a specialization constant at every call site, so the unused bands compile away.
vec3 eval_sh(int degree, uint64_t sh, uint gaussian, vec3 dir) {
  uint base = gaussian * uint(SH_COEFFS) * 3;
  vec3 result = SH_C0 * sh_coeff(sh, base, 0);
  if (degree > 0) {
    float x = dir.x, y = dir.y, z = dir.z;
    result += -SH_C1 * y * sh_coeff(sh, base, 1) + SH_C1 * z * sh_coeff(sh, base, 2) -
              SH_C1 * x * sh_coeff(sh, base, 3);
    if (degree > 1) {
      float xx = x * x, yy = y * y, zz = z * z;
      float xy = x * y, yz = y * z, xz = x * z;
      result += SH_C2[0] * xy * sh_coeff(sh, base, 4) + SH_C2[1] * yz * sh_coeff(sh, base, 5) +
                SH_C2[2] * (2.0 * zz - xx - yy) * sh_coeff(sh, base, 6) +
                SH_C2[3] * xz * sh_coeff(sh, base, 7) + SH_C2[4] * (xx - yy) * sh_coeff(sh, base, 8);
      if (degree > 2) {
        result += SH_C3[0] * y * (3.0 * xx - yy) * sh_coeff(sh, base, 9) +
                  SH_C3[1] * xy * z * sh_coeff(sh, base, 10) +
                  SH_C3[2] * y * (4.0 * zz - xx - yy) * sh_coeff(sh, base, 11) +
                  SH_C3[3] * z * (2.0 * zz - 3.0 * xx - 3.0 * yy) * sh_coeff(sh, base, 12) +
                  SH_C3[4] * x * (4.0 * zz - xx - yy) * sh_coeff(sh, base, 13) +
                  SH_C3[5] * z * (xx - yy) * sh_coeff(sh, base, 14) +
                  SH_C3[6] * x * (xx - 3.0 * yy) * sh_coeff(sh, base, 15);
      }
    }
  }
  return result;
}
