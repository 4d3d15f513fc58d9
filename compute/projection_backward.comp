#version 460
// Projection backward: one invocation per Gaussian drawn by the pinhole camera (docs/gradients.md). It
// recomputes what projection.comp computed of the Gaussian and carries the splat's screen-space gradient
// (composite_backward.comp's sums) back through each step in reverse: the conic's inverse, the antialiased
// opacity compensation, the 2D covariance (J W R S)(J W R S)^T + d I, the clamped EWA Jacobian, the
// quaternion's rotation and its normalization, the scales' exp, the pinhole's mean, and the SH colour with
// its viewing direction. A Gaussian whose gradient is not finite gets zero and is counted
// (BACKWARD_COUNTER_UNFORMED), so that no NaN reaches the others. Float64 where the device has it, as the
// projection; TS_FP32_PROJECTION builds the float32 variant.
#extension GL_GOOGLE_include_directive : require
#define TS_PROJECTION_BACKWARD_PUSH
#include "common.glsl"

#ifdef TS_FP32_PROJECTION
#define real float
#define real2 vec2
#define real3 vec3
#define real4 vec4
#define realmat2 mat2
#define realmat3 mat3
#define to_real(bits) float(packDouble2x32(bits))
#else
#define real double
#define real2 dvec2
#define real3 dvec3
#define real4 dvec4
#define realmat2 dmat2
#define realmat3 dmat3
real to_real(uvec2 bits) { return packDouble2x32(bits); }
#endif

layout(local_size_x = 256) in;
layout(constant_id = 0) const int SH_DEGREE = 0;  // the scene's (the backward covers no SH cap)
layout(constant_id = 1) const int SH_COEFFS = 1;  // (SH_DEGREE + 1)^2
layout(constant_id = 2) const uint DILATION_TENTHS = 3;
layout(constant_id = 3) const bool COMPENSATE_OPACITY = false;
const bool SH_HALF = false;

uvec2 camera_word(uint k) { return Uvec2Array(pc.camera).v[k]; }
uint sh_word(uint64_t sh, uint i) { return UintArray(sh).v[i]; }
#include "sh.glsl"
#include "sh_backward.glsl"

bool is_finite(real v) { return !isnan(v) && !isinf(v); }

// d L / d q of the rotation R(q) of a unit quaternion (w x y z), from d L / d R (column-major, as R).
real4 rotation_backward(real4 q, realmat3 g) {
  real w = q.x, x = q.y, y = q.z, z = q.w;
  // G_rc = g[c][r]
  real g00 = g[0][0], g01 = g[1][0], g02 = g[2][0];
  real g10 = g[0][1], g11 = g[1][1], g12 = g[2][1];
  real g20 = g[0][2], g21 = g[1][2], g22 = g[2][2];
  return 2.0 * real4(-z * g01 + y * g02 + z * g10 - x * g12 - y * g20 + x * g21,
                     y * g01 + z * g02 + y * g10 - 2.0 * x * g11 - w * g12 + z * g20 + w * g21 - 2.0 * x * g22,
                     -2.0 * y * g00 + x * g01 + w * g02 + x * g10 + z * g12 - w * g20 + z * g21 - 2.0 * y * g22,
                     -2.0 * z * g00 - w * g01 + x * g02 + w * g10 - 2.0 * z * g11 + y * g12 + x * g20 + y * g21);
}

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count || pc.tile_counts.v[i] == 0) return;  // not drawn: its gradients stay zero
  uint n = pc.count;
  uint base = SPLAT_GRADIENT_FLOATS * i;
  real g[SPLAT_GRADIENT_FLOATS];
  for (uint k = 0; k < SPLAT_GRADIENT_FLOATS; ++k) g[k] = real(pc.splat_gradients.v[base + k]);

  // The forward, as projection.comp computes it for the pinhole.
  real3 world = real3(pc.positions.v[3 * i], pc.positions.v[3 * i + 1], pc.positions.v[3 * i + 2]);
  real3 centre = real3(to_real(camera_word(CAMERA_CENTRE)), to_real(camera_word(CAMERA_CENTRE + 1)),
                       to_real(camera_word(CAMERA_CENTRE + 2)));
  real3 rel = world - centre;
  realmat3 W;  // column-major: W[c][r] = rotation[r][c]
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) W[c][r] = to_real(camera_word(CAMERA_ROTATION + 3 * r + c));
  real3 t = W * rel;
  real fx = to_real(camera_word(CAMERA_FOCAL)), fy = to_real(camera_word(CAMERA_FOCAL + 1));
  real limit_x = to_real(camera_word(CAMERA_CLIP)), limit_y = to_real(camera_word(CAMERA_CLIP + 1));
  real inv_z = 1.0 / t.z;
  real rx = t.x * inv_z, ry = t.y * inv_z;
  bool clamped_x = rx < -limit_x || rx > limit_x, clamped_y = ry < -limit_y || ry > limit_y;
  real rx_c = clamp(rx, -limit_x, limit_x), ry_c = clamp(ry, -limit_y, limit_y);
  real3 j0 = real3(fx * inv_z, 0.0, -fx * rx_c * t.z * inv_z * inv_z);
  real3 j1 = real3(0.0, fy * inv_z, -fy * ry_c * t.z * inv_z * inv_z);

  vec4 stored_q = vec4(pc.rotations.v[4 * i], pc.rotations.v[4 * i + 1], pc.rotations.v[4 * i + 2],
                       pc.rotations.v[4 * i + 3]);
  real4 q = real4(stored_q);
  real largest = max(max(abs(q.x), abs(q.y)), max(abs(q.z), abs(q.w)));
  bool identity = !(largest >= real(FLT_MIN));
  real q_norm = identity ? 1.0 : sqrt(dot(q, q));
  real4 qn = identity ? real4(1, 0, 0, 0) : q / q_norm;
  real w = qn.x, x = qn.y, y = qn.z, z = qn.w;
  realmat3 R = realmat3(1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z), 2.0 * (x * z - w * y),
                        2.0 * (x * y - w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + w * x),
                        2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y));
  vec3 log_scale = vec3(pc.log_scales.v[3 * i], pc.log_scales.v[3 * i + 1], pc.log_scales.v[3 * i + 2]);
  real3 s = real3(exp(log_scale));
  realmat3 RS = R * realmat3(s.x, 0, 0, 0, s.y, 0, 0, 0, s.z);
  realmat3 M = W * RS;
  real3 u = j0 * M, v = j1 * M;  // rows of J W R S
  const real d = real(DILATION_TENTHS) / 10.0;
  real a = dot(u, u) + d, b = dot(u, v), c = dot(v, v) + d;
  real3 uxv = cross(u, v);
  real det0 = dot(uxv, uxv);
  real det = det0 + d * (dot(u, u) + dot(v, v)) + d * d;
  real A = c / det, B = -b / det, C = a / det;

  // The conic Q = inverse of the covariance S: dL/dS = -Q (dL/dQ) Q, with dL/dQ symmetric and B counted
  // once in each off-diagonal.
  realmat2 Q = realmat2(A, B, B, C);
  realmat2 gQ = realmat2(g[2], 0.5 * g[3], 0.5 * g[3], g[4]);
  realmat2 gS = -(Q * gQ * Q);
  real g_a = gS[0][0], g_b = gS[1][0] + gS[0][1], g_c = gS[1][1];

  // opacity = sigmoid(logit) (times sqrt(det0 / det) where compensated, above its floor).
  float logit = pc.opacity_logits.v[i];
  real sigma = real(1.0 / (1.0 + exp(-logit)));
  // sigmoid' = e / (1 + e)^2 with e = exp(-|logit|): accurate where sigma (1 - sigma) would cancel (an
  // opacity near 1, whose 1 - sigma is a few float steps).
  real e = real(exp(-abs(logit)));
  real d_sigma = e / ((1.0 + e) * (1.0 + e));
  real g_opacity = g[4 + 1];
  real g_logit;
  if (COMPENSATE_OPACITY) {
    real ratio = max(det0, real(0.0)) / det;
    real compensation = sqrt(max(real(2.5e-5), ratio));
    g_logit = g_opacity * compensation * d_sigma;
    if (det0 > 0.0 && ratio > 2.5e-5) {
      real g_ratio = g_opacity * sigma * 0.5 / compensation;
      g_a += g_ratio * ((c - d) / det - ratio * c / det);
      g_c += g_ratio * ((a - d) / det - ratio * a / det);
      g_b += g_ratio * (-2.0 * b / det + ratio * 2.0 * b / det);
    }
  } else {
    g_logit = g_opacity * d_sigma;
  }

  // a = u.u + d, b = u.v, c = v.v + d.
  real3 g_u = 2.0 * g_a * u + g_b * v;
  real3 g_v = g_b * u + 2.0 * g_c * v;
  // u = j0 M, v = j1 M.
  real3 g_j0 = M * g_u, g_j1 = M * g_v;
  realmat3 gM = outerProduct(j0, g_u) + outerProduct(j1, g_v);
  // M = W R S: through W (constant) to R S, then to R and the scales.
  realmat3 gRS = transpose(W) * gM;
  real3 g_s = real3(dot(gRS[0], R[0]), dot(gRS[1], R[1]), dot(gRS[2], R[2]));
  realmat3 gR = realmat3(gRS[0] * s.x, gRS[1] * s.y, gRS[2] * s.z);
  real3 g_log_scale = g_s * s;
  real4 g_qn = rotation_backward(qn, gR);
  // q / |q|: the component along q drops out.
  real4 g_q = identity ? real4(0.0) : (g_qn - qn * dot(qn, g_qn)) / q_norm;

  // The Jacobian's rows to t: j0 = (fx / z, 0, -fx rx_c / z), rx_c = clamp(x / z), likewise j1.
  real3 g_t = real3(0.0);
  g_t.z += -fx * inv_z * inv_z * g_j0.x - fy * inv_z * inv_z * g_j1.y;
  if (clamped_x) {
    g_t.z += g_j0.z * fx * rx_c * inv_z * inv_z;
  } else {
    g_t.x += g_j0.z * -fx * inv_z * inv_z;
    g_t.z += g_j0.z * 2.0 * fx * t.x * inv_z * inv_z * inv_z;
  }
  if (clamped_y) {
    g_t.z += g_j1.z * fy * ry_c * inv_z * inv_z;
  } else {
    g_t.y += g_j1.z * -fy * inv_z * inv_z;
    g_t.z += g_j1.z * 2.0 * fy * t.y * inv_z * inv_z * inv_z;
  }
  // The mean (fx x / z + cx, fy y / z + cy) and the view depth z.
  g_t.x += g[0] * fx * inv_z;
  g_t.y += g[1] * fy * inv_z;
  g_t.z += -g[0] * fx * t.x * inv_z * inv_z - g[1] * fy * t.y * inv_z * inv_z + g[9];
  real3 g_world = transpose(W) * g_t;

  // The colour max(SH(dir) + 0.5, 0), dir = rel / |rel|: a clamped channel passes nothing.
  vec3 colour = eval_sh(SH_DEGREE, uint64_t(pc.sh), i, vec3(normalize(rel))) + 0.5;
  real3 g_colour = real3(colour.r > 0.0 ? g[6] : 0.0, colour.g > 0.0 ? g[7] : 0.0, colour.b > 0.0 ? g[8] : 0.0);
  real rel_length = length(rel);
  real3 dir = rel / rel_length;
  real basis[16];
  real3 basis_gradient[16];
  sh_basis(SH_DEGREE, dir, basis);
  sh_basis_gradient(SH_DEGREE, dir, basis_gradient);
  uint sh_base = i * uint(SH_COEFFS) * 3;
  real3 g_dir = real3(0.0);
  for (int k = 0; k < SH_COEFFS; ++k) {
    real3 coefficient = real3(pc.sh.v[sh_base + 3 * k], pc.sh.v[sh_base + 3 * k + 1], pc.sh.v[sh_base + 3 * k + 2]);
    g_dir += basis_gradient[k] * dot(coefficient, g_colour);
  }
  g_world += (g_dir - dir * dot(dir, g_dir)) / rel_length;

  // Finite, as floats, or nothing of this Gaussian is written.
  bool finite = true;
  for (int k = 0; k < 3; ++k) finite = finite && abs(g_world[k]) <= FLT_MAX && abs(g_log_scale[k]) <= FLT_MAX;
  for (int k = 0; k < 4; ++k) finite = finite && abs(g_q[k]) <= FLT_MAX;
  finite = finite && abs(g_logit) <= FLT_MAX;
  for (int k = 0; k < SH_COEFFS; ++k) finite = finite && abs(basis[k] * g_colour.r) <= FLT_MAX &&
                                               abs(basis[k] * g_colour.g) <= FLT_MAX &&
                                               abs(basis[k] * g_colour.b) <= FLT_MAX;
  for (int k = 0; k < 2; ++k) finite = finite && abs(g[k]) <= FLT_MAX && abs(g[10 + k]) <= FLT_MAX;
  if (!finite) {
    atomicAdd(pc.counters.v[BACKWARD_COUNTER_UNFORMED], 1u);
    return;
  }
  // The outputs: positions 3N, log scales 3N, rotations 4N, logits N, SH 3KN, means2d 2N, |means2d| 2N.
  FloatArray out_ = pc.gradients;
  for (uint k = 0; k < 3; ++k) {
    out_.v[3 * i + k] = float(g_world[k]);
    out_.v[3 * n + 3 * i + k] = float(g_log_scale[k]);
  }
  for (uint k = 0; k < 4; ++k) out_.v[6 * n + 4 * i + k] = float(g_q[k]);
  out_.v[10 * n + i] = float(g_logit);
  uint sh_out = 11 * n + sh_base;
  for (uint k = 0; k < uint(SH_COEFFS); ++k) {
    out_.v[sh_out + 3 * k] = float(basis[k] * g_colour.r);
    out_.v[sh_out + 3 * k + 1] = float(basis[k] * g_colour.g);
    out_.v[sh_out + 3 * k + 2] = float(basis[k] * g_colour.b);
  }
  uint screen_out = (11 + 3 * uint(SH_COEFFS)) * n;
  out_.v[screen_out + 2 * i] = float(g[0]);
  out_.v[screen_out + 2 * i + 1] = float(g[1]);
  out_.v[screen_out + 2 * n + 2 * i] = float(g[10]);
  out_.v[screen_out + 2 * n + 2 * i + 1] = float(g[11]);
}
