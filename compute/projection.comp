#version 460
// Projection: one invocation per Gaussian. EWA splatting of the 3D covariance to screen space, SH
// colour, radius and tile rectangle. It writes the number of tiles touched, and that count alone
// decides visibility for every later pass (0 = culled), so no pass can disagree about a Gaussian.
//
// The geometry runs in float64 where the device has it (the default build of this file): the pass is
// memory bound, so doubles cost little, and they make every per-splat value the correctly rounded
// float of the reference's value. That matters at the discontinuities of the reference (alpha >= 1/255,
// T < 1e-4, the depth order of near-coincident splats, the tile rect), where float32 rounding flips
// decisions. TS_FP32_PROJECTION builds the float32 variant for devices without shaderFloat64.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#define TS_PROJECTION_PUSH  // its push constants (shader_io.h)
#include "common.glsl"
#include "tile_coverage.glsl"

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
#endif

layout(local_size_x = 256) in;
// The accuracy modes (AccuracyModes), each a specialization constant so that a mode that is off
// costs nothing: its code compiles away.
layout(constant_id = 0) const int SH_DEGREE = 0;       // evaluated: min(scene degree, cap)
layout(constant_id = 1) const int SH_COEFFS = 1;       // stored per Gaussian: (scene degree + 1)^2
layout(constant_id = 2) const bool SH_HALF = false;    // SH stored as 16-bit floats
layout(constant_id = 3) const bool COV_HALF = false;   // 3D covariance read as six 16-bit floats
layout(constant_id = 4) const bool OPACITY_EXTENT = false;  // sqrt(2 ln(o / alpha cut-off)) sigma, not 3
layout(constant_id = 5) const bool SQUARE_TILES = false;    // every tile of the rect, no ellipse test
layout(constant_id = 6) const float ALPHA_INV = 255.0;      // 1 / the alpha cut-off
layout(constant_id = 7) const uint DEPTH_KEY_BITS = 32;     // 32: float bits; 24: their top 24; 16: see below
layout(constant_id = 8) const bool RAY_DEPTH = false;       // write the per-pixel re-sorting data
// The antialiasing mode (tilesplat::Antialiasing), a scene effect: the low-pass filter added to the
// 2D covariance, and whether opacity is scaled by sqrt(det before / det after) to keep the
// footprint's integral (gsplat's "antialiased" and Mip-Splatting's 2D filter).
layout(constant_id = 9) const uint DILATION_TENTHS = 3;  // 0.3 px^2 (classic, antialiased) or 0.1 (mip)
layout(constant_id = 10) const bool COMPENSATE_OPACITY = false;
// Relighting (tilesplat::Lighting, a scene effect; the model is written there): LIGHTING multiplies
// the SH colour by the light factor of the lights in pc.lighting. Off, its code compiles away and no
// normal is read. FILE_NORMALS: the scene has a normal buffer (pc.lighting.normals); without one every
// splat uses its shortest axis. The lights are data, not constants: changing them rebuilds nothing.
layout(constant_id = 11) const bool LIGHTING = false;
layout(constant_id = 12) const bool FILE_NORMALS = false;
// The camera model (tilesplat::CameraModel): 0 pinhole, 1 OpenCV, 2 fisheye, 3 orthographic, 4
// equirectangular. The pinhole's code is the only code of the default pipeline.
layout(constant_id = 13) const uint CAMERA_MODEL = 0;
// Radial sorting (AccuracyModes::SortDepth::kDistance): the depth key is the centre's distance from the
// camera, not its z; a turn in place keeps every distance, so it keeps the order. Only the pinhole and
// OpenCV cameras set it: the other models' depth is already the distance, or, orthographic, has none.
layout(constant_id = 14) const bool DISTANCE_KEY = false;
const uint MODEL_PINHOLE = 0, MODEL_OPENCV = 1, MODEL_FISHEYE = 2, MODEL_ORTHOGRAPHIC = 3, MODEL_EQUIRECTANGULAR = 4;
// Records per Gaussian (camera_models::seam_copies): the equirectangular camera draws a splat a second
// time a period to the side, so that one across the +-180 degree seam shows on both edges. Gaussian i's
// records are i and count + i.
const uint SEAM_COPIES = CAMERA_MODEL == MODEL_EQUIRECTANGULAR ? 2u : 1u;

// CameraParams and LightParams, the blocks the host writes for this pass, are in shader_io.h.

#ifdef TS_TEXEL_BUFFERS
// The CPU-driver variant (projection_texel): the Gaussians' attributes in and the projected records out
// through texel buffers, which llvmpipe reads and writes with SIMD gathers and scatters, where a load or
// store at a per-invocation address is a loop over the SIMD lanes per component (vk::
// texel_buffers_wanted). The same buffers as the push constants' addresses; nothing else differs.
layout(set = 0, binding = 0) uniform textureBuffer position_texels;   // R32_SFLOAT
layout(set = 0, binding = 1) uniform textureBuffer log_scale_texels;  // R32_SFLOAT
layout(set = 0, binding = 2) uniform textureBuffer rotation_texels;   // R32G32B32A32_SFLOAT
layout(set = 0, binding = 3) uniform textureBuffer opacity_texels;    // R32_SFLOAT
layout(set = 0, binding = 4) uniform utextureBuffer sh_texels;        // R32_UINT: float bits or half pairs
layout(set = 0, binding = 5, rgba32f) uniform writeonly imageBuffer splat_texels;
layout(set = 0, binding = 6, rg32ui) uniform writeonly uimageBuffer rect_texels;
layout(set = 0, binding = 7, r32ui) uniform writeonly uimageBuffer tile_count_texels;
layout(set = 0, binding = 8, r32ui) uniform writeonly uimageBuffer depth_key_texels;
layout(set = 0, binding = 9, r32ui) uniform writeonly uimageBuffer depth_value_texels;
layout(set = 0, binding = 10) uniform utextureBuffer camera_texels;  // R32G32_UINT: CameraParams' uvec2s
uvec2 camera_word(uint k) { return texelFetch(camera_texels, int(k)).xy; }
vec3 position_of(uint i) {
  return vec3(texelFetch(position_texels, int(3 * i)).x, texelFetch(position_texels, int(3 * i + 1)).x,
              texelFetch(position_texels, int(3 * i + 2)).x);
}
vec3 log_scale_of(uint i) {
  return vec3(texelFetch(log_scale_texels, int(3 * i)).x, texelFetch(log_scale_texels, int(3 * i + 1)).x,
              texelFetch(log_scale_texels, int(3 * i + 2)).x);
}
vec4 quaternion_of(uint i) { return texelFetch(rotation_texels, int(i)); }
float opacity_logit_of(uint i) { return texelFetch(opacity_texels, int(i)).x; }
uint sh_word(uint64_t sh, uint i) { return texelFetch(sh_texels, int(i)).x; }
void write_projected(uint i, vec4 record[SPLAT_VEC4S], uvec2 rect, bool touched) {
  if (touched) {
    for (uint k = 0; k < SPLAT_VEC4S; ++k) imageStore(splat_texels, int(SPLAT_VEC4S * i + k), record[k]);
    imageStore(rect_texels, int(i), uvec4(rect, 0u, 0u));
  }
}
void write_tile_count(uint i, uint touched) { imageStore(tile_count_texels, int(i), uvec4(touched)); }
void write_depth_pair(uint i, uint key) {
  imageStore(depth_key_texels, int(i), uvec4(key));
  imageStore(depth_value_texels, int(i), uvec4(i));
}
#else
uvec2 camera_word(uint k) { return Uvec2Array(pc.camera).v[k]; }
vec3 position_of(uint i) { return vec3(pc.positions.v[3 * i], pc.positions.v[3 * i + 1], pc.positions.v[3 * i + 2]); }
vec3 log_scale_of(uint i) { return vec3(pc.log_scales.v[3 * i], pc.log_scales.v[3 * i + 1], pc.log_scales.v[3 * i + 2]); }
vec4 quaternion_of(uint i) {
  return vec4(pc.rotations.v[4 * i], pc.rotations.v[4 * i + 1], pc.rotations.v[4 * i + 2], pc.rotations.v[4 * i + 3]);
}
float opacity_logit_of(uint i) { return pc.opacity_logits.v[i]; }
uint sh_word(uint64_t sh, uint i) { return UintArray(sh).v[i]; }
void write_projected(uint i, vec4 record[SPLAT_VEC4S], uvec2 rect, bool touched) {
  if (touched) {
    for (uint k = 0; k < SPLAT_VEC4S; ++k) pc.splats.v[SPLAT_VEC4S * i + k] = record[k];
    pc.rects.v[i] = rect;
  }
}
void write_tile_count(uint i, uint touched) { pc.tile_counts.v[i] = touched; }
void write_depth_pair(uint i, uint key) {
  pc.depth_keys.v[i] = key;
  pc.depth_values.v[i] = i;
}
#endif

#include "sh.glsl"  // after sh_word

#ifndef TS_FP32_PROJECTION
real to_real(uvec2 bits) { return packDouble2x32(bits); }
#endif

bool is_finite(real v) { return !isnan(v) && !isinf(v); }

// Gaussian i's rotation from its stored quaternion (w x y z). Zeros and float denormals are the zero
// quaternion, the identity (whether or not the device flushes denormals on load: the reference
// decides the same way).
realmat3 rotation_of(uint i) {
  real4 q = real4(quaternion_of(i));
  real largest = max(max(abs(q.x), abs(q.y)), max(abs(q.z), abs(q.w)));
  q = largest >= real(FLT_MIN) ? q / sqrt(dot(q, q)) : real4(1, 0, 0, 0);  // doubles: no overflow
  real w = q.x, x = q.y, y = q.z, z = q.w;
  return realmat3(1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z), 2.0 * (x * z - w * y),
                  2.0 * (x * y - w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + w * x),
                  2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y));
}

// Relighting's normal: the file's when finite and non-zero (zeros and denormals are none, as for the
// quaternion), else the shortest axis (the rotation's column of the smallest stored log scale, the
// first on ties). Turned toward the camera; rel = x - camera centre.
real3 lighting_normal(uint i, real3 rel) {
  real3 n;
  bool from_file = false;
  if (FILE_NORMALS) {
    FloatArray normals = FloatArray(LightParams(pc.lighting).normals);
    vec3 f = vec3(normals.v[3 * i], normals.v[3 * i + 1], normals.v[3 * i + 2]);
    float largest = max(max(abs(f.x), abs(f.y)), abs(f.z));
    if (!any(isnan(f)) && !any(isinf(f)) && largest >= FLT_MIN) {
      n = real3(f);
      n /= sqrt(dot(n, n));
      from_file = true;
    }
  }
  if (!from_file) {
    vec3 s = log_scale_of(i);
    int axis = s.x <= s.y && s.x <= s.z ? 0 : (s.y <= s.z ? 1 : 2);
    n = rotation_of(i)[axis];
  }
  // dot(n, camera centre - x) < 0, as -dot(n, rel) (negation is exact).
  if (-dot(n, rel) < 0.0) n = -n;
  return n;
}

// The factor the unlit colour is multiplied by: ambient + sum of radiance max(0, n . w) falloff, in the
// operations and order of the reference's light_factor (engine/src/lighting.cpp).
real3 light_factor(real3 world, real3 n) {
  LightParams lp = LightParams(pc.lighting);
  real3 factor = real3(to_real(lp.ambient[0]), to_real(lp.ambient[1]), to_real(lp.ambient[2]));
  for (uint l = 0; l < lp.count; ++l) {
    real3 v = real3(to_real(lp.lights[l].vector[0]), to_real(lp.lights[l].vector[1]),
                    to_real(lp.lights[l].vector[2]));
    real3 radiance = real3(to_real(lp.lights[l].radiance[0]), to_real(lp.lights[l].radiance[1]),
                           to_real(lp.lights[l].radiance[2]));
    real3 w = v;
    real falloff = 1.0;
    if (lp.lights[l].point != 0) {
      real3 d = v - world;
      real distance2 = dot(d, d);
      if (!(distance2 > 0.0)) continue;  // the splat is at the light: no direction, no light
      real distance = sqrt(distance2);
      w = real3(d.x / distance, d.y / distance, d.z / distance);
      falloff = 1.0 / distance2;
    }
    real cosine = dot(n, w);
    if (cosine > 0.0) factor += radiance * (cosine * falloff);
  }
  return factor;
}

// For the per-pixel re-sorting (composite_resort.comp): the depth of a Gaussian's density maximum
// along the camera ray d = (x, y, 1) is t(d) = (d . Q mu) / (d . Q d) with Q = Sigma^-1 in camera
// space. Any multiple of Q gives the same t, so the adjugate is stored, scaled to its largest entry:
// no inverse, no overflow for needles, and a flat splat (singular Sigma) becomes the exact ray-plane
// intersection. [0] = Q mu, Q_xx; [1] = Q_xy, Q_xz, Q_yy, Q_yz; [2] = Q_zz, mean depth.
void write_ray_depth(uint i, real3 mu, realmat3 S) {
  real qxx = S[1][1] * S[2][2] - S[2][1] * S[2][1];
  real qxy = S[2][1] * S[2][0] - S[1][0] * S[2][2];
  real qxz = S[1][0] * S[2][1] - S[1][1] * S[2][0];
  real qyy = S[0][0] * S[2][2] - S[2][0] * S[2][0];
  real qyz = S[1][0] * S[2][0] - S[0][0] * S[2][1];
  real qzz = S[0][0] * S[1][1] - S[1][0] * S[1][0];
  real scale = max(max(max(abs(qxx), abs(qxy)), max(abs(qxz), abs(qyy))), max(abs(qyz), abs(qzz)));
  scale = scale > 0.0 && is_finite(scale) ? 1.0 / scale : 0.0;
  realmat3 Q = realmat3(qxx, qxy, qxz, qxy, qyy, qyz, qxz, qyz, qzz) * scale;
  vec3 qmu = vec3(Q * mu);
  pc.ray_depth.v[RAY_DEPTH_VEC4S * i + 0] = vec4(qmu, float(Q[0][0]));
  pc.ray_depth.v[RAY_DEPTH_VEC4S * i + 1] = vec4(float(Q[0][1]), float(Q[0][2]), float(Q[1][1]), float(Q[1][2]));
  pc.ray_depth.v[RAY_DEPTH_VEC4S * i + 2] = vec4(float(Q[2][2]), float(mu.z), 0.0, 0.0);
}

#ifdef TS_FP32_PROJECTION
real atan2_real(real y, real x) { return atan(y, x); }
#else
// atan(a) for a in [0, 1] in double (GLSL's atan is float32 only): two argument reductions,
// atan(a) = pi/6 + atan((sqrt3 a - 1) / (sqrt3 + a)) above tan(pi/12) and atan(a) = 2 atan(a / (1 +
// sqrt(1 + a^2))), leave |a| < 0.14, where 11 terms of the series are below double rounding.
real atan_unit(real a) {
  const real SQRT3 = 1.7320508075688772LF, TAN_PI_12 = 0.2679491924311227LF;
  real offset = 0.0;
  if (a > TAN_PI_12) {
    a = (SQRT3 * a - 1.0) / (SQRT3 + a);
    offset = 0.5235987755982988LF;  // pi / 6
  }
  a = a / (1.0 + sqrt(1.0 + a * a));
  real a2 = a * a;
  real series = 0.0;
  for (int k = 10; k >= 0; --k) series = series * a2 + real((k % 2 == 0 ? 1.0 : -1.0) / double(2 * k + 1));
  return offset + 2.0 * a * series;
}
// atan2(y, x) in [-pi, pi], as C's (atan2(0, x) = 0 for x >= 0; the sign of a zero y is not kept).
real atan2_real(real y, real x) {
  const real PI = 3.141592653589793LF;
  real ay = abs(y);
  real angle;
  if (x == 0.0) {
    angle = ay > 0.0 ? 0.5 * PI : 0.0;
  } else {
    real ratio = ay / abs(x);
    angle = ratio <= 1.0 ? atan_unit(ratio) : 0.5 * PI - atan_unit(abs(x) / ay);
    if (x < 0.0) angle = PI - angle;
  }
  return y < 0.0 ? -angle : angle;
}
#endif

// OpenCV's distortion of the normalized point p (camera_models.cpp, distort): the distorted point and
// its 2x2 Jacobian (column-major, d[c][r] = d distorted_r / d p_c).
real2 distort(real2 p, out realmat2 d) {
  real k[8];
  for (uint i = 0; i < 8; ++i) k[i] = to_real(camera_word(CAMERA_DISTORTION + i));
  real p1 = k[2], p2 = k[3];
  real x = p.x, y = p.y;
  real r2 = x * x + y * y;
  real num = 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
  real den = 1.0 + r2 * (k[5] + r2 * (k[6] + r2 * k[7]));
  real dnum = k[0] + r2 * (2.0 * k[1] + r2 * 3.0 * k[4]);
  real dden = k[5] + r2 * (2.0 * k[6] + r2 * 3.0 * k[7]);
  real radial = num / den;
  real slope = (dnum * den - num * dden) / (den * den);
  real cross_term = 2.0 * x * y * slope + 2.0 * p1 * x + 2.0 * p2 * y;
  d = realmat2(radial + 2.0 * x * x * slope + 2.0 * p1 * y + 6.0 * p2 * x, cross_term,  //
               cross_term, radial + 2.0 * y * y * slope + 6.0 * p1 * y + 2.0 * p2 * x);
  return real2(x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
               y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y);
}

// A splat centre t through the camera models other than the pinhole (camera_models.cpp,
// project_centre, in the same operations): its pixel, the rows of d pixel / d t, and the depth it
// sorts by. `seam_copy` 1: the equirectangular camera's second record. False: not drawn.
bool project_centre(real3 t, uint seam_copy, out real2 mean, out real3 j0, out real3 j1, out real depth) {
  real fx = to_real(camera_word(CAMERA_FOCAL)), fy = to_real(camera_word(CAMERA_FOCAL + 1));
  real cx = to_real(camera_word(CAMERA_FOCAL + 2)), cy = to_real(camera_word(CAMERA_FOCAL + 3));
  real near_plane = to_real(camera_word(CAMERA_CLIP + 2));
  real reach = to_real(camera_word(CAMERA_CLIP + 3));
  real x = t.x, y = t.y, z = t.z;
  mean = real2(0.0);
  j0 = real3(0.0);
  j1 = real3(0.0);
  depth = z;
  if (CAMERA_MODEL == MODEL_OPENCV) {
    if (!(z > near_plane)) return false;
    real xn = x / z, yn = y / z;
    if (!(xn * xn + yn * yn < reach * reach)) return false;
    realmat2 unused;
    real2 centre = distort(real2(xn, yn), unused);
    mean = real2(fx * centre.x + cx, fy * centre.y + cy);
    real limit_x = to_real(camera_word(CAMERA_CLIP)), limit_y = to_real(camera_word(CAMERA_CLIP + 1));
    real xc = clamp(xn, -limit_x, limit_x), yc = clamp(yn, -limit_y, limit_y);
    realmat2 d;
    distort(real2(xc, yc), d);
    // d[c][r]: d00 = d[0][0], d01 = d[1][0], d10 = d[0][1], d11 = d[1][1].
    if (!(d[0][0] * d[1][1] - d[1][0] * d[0][1] > 0.0)) return false;
    real inv_z = 1.0 / z;
    j0 = real3(fx * d[0][0] * inv_z, fx * d[1][0] * inv_z, -fx * (d[0][0] * xc + d[1][0] * yc) * inv_z);
    j1 = real3(fy * d[0][1] * inv_z, fy * d[1][1] * inv_z, -fy * (d[0][1] * xc + d[1][1] * yc) * inv_z);
    return true;
  }
  if (CAMERA_MODEL == MODEL_FISHEYE) {
    real r2 = x * x + y * y;
    real rho2 = r2 + z * z;
    real rho = sqrt(rho2);
    if (!(rho > near_plane)) return false;
    real r = sqrt(r2);
    real theta = atan2_real(r, z);
    if (!(theta < reach)) return false;
    real k1 = to_real(camera_word(CAMERA_DISTORTION)), k2 = to_real(camera_word(CAMERA_DISTORTION + 1));
    real k3 = to_real(camera_word(CAMERA_DISTORTION + 2)), k4 = to_real(camera_word(CAMERA_DISTORTION + 3));
    real t2 = theta * theta;
    real theta_d = theta * (1.0 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))));
    real slope = 1.0 + t2 * (3.0 * k1 + t2 * (5.0 * k2 + t2 * (7.0 * k3 + t2 * 9.0 * k4)));
    real s, h;
    if (r2 > 0.0) {
      s = theta_d / r;
      h = (slope * z / rho2 - s) / r2;
    } else {
      s = 1.0 / z;
      h = (2.0 * k1 - 2.0 / 3.0) / (z * z * z);
    }
    mean = real2(fx * s * x + cx, fy * s * y + cy);
    real along = slope / rho2;
    j0 = real3(fx * (s + x * x * h), fx * x * y * h, -fx * x * along);
    j1 = real3(fy * x * y * h, fy * (s + y * y * h), -fy * y * along);
    depth = rho;
    return true;
  }
  if (CAMERA_MODEL == MODEL_EQUIRECTANGULAR) {
    real q2 = x * x + z * z;
    real rho2 = q2 + y * y;
    real rho = sqrt(rho2);
    if (!(rho > near_plane) || !(q2 > 0.0)) return false;
    real q = sqrt(q2);
    const real TWO_PI = real(6.283185307179586LF);
    real longitude = atan2_real(x, z);
    if (seam_copy == 1) longitude += longitude < 0.0 ? TWO_PI : -TWO_PI;
    mean = real2(fx * longitude + cx, fy * atan2_real(y, q) + cy);
    j0 = real3(fx * z / q2, 0.0, -fx * x / q2);
    real across = fy / (q * rho2);
    j1 = real3(-across * x * y, fy * q / rho2, -across * y * z);
    depth = rho;
    return true;
  }
  // MODEL_ORTHOGRAPHIC
  if (!(z > near_plane)) return false;
  mean = real2(fx * x + cx, fy * y + cy);
  j0 = real3(fx, 0.0, 0.0);
  j1 = real3(0.0, fy, 0.0);
  return true;
}

// Returns the tiles touched (0 = culled) and fills the splat record of Gaussian i's copy `seam_copy`.
// `sort_depth`: what the depth sort orders the record by (its view depth, or the distance: DISTANCE_KEY).
uint project(uint i, uint seam_copy, out vec4 record[SPLAT_VEC4S], out uvec2 rect, out float sort_depth) {
  sort_depth = 0.0;  // a culled record's: it sorts last whatever this is
  real3 world = real3(position_of(i));
  real3 rel = world - real3(to_real(camera_word(CAMERA_CENTRE)), to_real(camera_word(CAMERA_CENTRE + 1)), to_real(camera_word(CAMERA_CENTRE + 2)));
  realmat3 W;  // column-major: W[c][r] = rotation[r][c]
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) W[c][r] = to_real(camera_word(CAMERA_ROTATION + 3 * r + c));
  real3 t = W * rel;
  if (CAMERA_MODEL == MODEL_PINHOLE) {
    if (!(t.z > to_real(camera_word(CAMERA_CLIP + 2))) || !is_finite(t.x) || !is_finite(t.y) || !is_finite(t.z)) return 0;
  } else if (!is_finite(t.x) || !is_finite(t.y) || !is_finite(t.z)) {
    return 0;
  }

  // The 3D shape: R S from the log scales and quaternion (reference), or the covariance itself,
  // precomputed on the host and stored in 16 bits (COV_HALF, as web viewers do).
  realmat3 RS;
  realmat3 sigma;
  if (COV_HALF) {
    vec2 xx_xy = unpackHalf2x16(pc.covariances.v[3 * i]);
    vec2 xz_yy = unpackHalf2x16(pc.covariances.v[3 * i + 1]);
    vec2 yz_zz = unpackHalf2x16(pc.covariances.v[3 * i + 2]);
    sigma = realmat3(xx_xy.x, xx_xy.y, xz_yy.x, xx_xy.y, xz_yy.y, yz_zz.x, xz_yy.x, yz_zz.x, yz_zz.y);
  } else {
    // exp has no float64 overload in GLSL; its float32 rounding is far below what changes a decision.
    real3 s = real3(exp(log_scale_of(i)));
    RS = rotation_of(i) * realmat3(s.x, 0, 0, 0, s.y, 0, 0, 0, s.z);
  }

  // The 2x3 Jacobian's rows, applied to the world-to-camera rotation and then to R S:
  // cov2d = (J W R S)(J W R S)^T, never forming the 3D covariance (better conditioned).
  real3 j0, j1;
  real2 mean;
  real depth = t.z;  // what the splat sorts by and depth images average: z, a fisheye's distance
  if (CAMERA_MODEL == MODEL_PINHOLE) {
    real fx = to_real(camera_word(CAMERA_FOCAL)), fy = to_real(camera_word(CAMERA_FOCAL + 1));
    real cx = to_real(camera_word(CAMERA_FOCAL + 2)), cy = to_real(camera_word(CAMERA_FOCAL + 3));
    real inv_z = 1.0 / t.z;
    real limit_x = to_real(camera_word(CAMERA_CLIP)), limit_y = to_real(camera_word(CAMERA_CLIP + 1));
    real tx = clamp(t.x * inv_z, -limit_x, limit_x) * t.z;
    real ty = clamp(t.y * inv_z, -limit_y, limit_y) * t.z;
    j0 = real3(fx * inv_z, 0.0, -fx * tx * inv_z * inv_z);
    j1 = real3(0.0, fy * inv_z, -fy * ty * inv_z * inv_z);
    mean = real2(fx * t.x * inv_z + cx, fy * t.y * inv_z + cy);
  } else if (!project_centre(t, seam_copy, mean, j0, j1, depth)) {
    return 0;
  }
  real a, b, c, det;
  real det_unfiltered;  // of the 2D covariance before the low-pass filter
  const real d = real(DILATION_TENTHS) / 10.0;  // the double nearest 0.3 or 0.1, as the reference's
  if (COV_HALF) {
    real3 u = j0 * W;  // rows of J W
    real3 v = j1 * W;
    real3 su = sigma * u;
    real3 sv = sigma * v;
    a = dot(u, su) + d;
    b = dot(u, sv);
    c = dot(v, sv) + d;
    det = a * c - b * b;
    det_unfiltered = (a - d) * (c - d) - b * b;
  } else {
    realmat3 WRS = W * RS;
    real3 u = j0 * WRS;  // row 0 of J W R S
    real3 v = j1 * WRS;  // row 1
    a = dot(u, u) + d;
    b = dot(u, v);
    c = dot(v, v) + d;
    // det(uu^T + vv^T + d I) without cancellation: |u x v|^2 + d (|u|^2 + |v|^2) + d^2.
    real3 uxv = cross(u, v);
    det_unfiltered = dot(uxv, uxv);
    det = det_unfiltered + d * (dot(u, u) + dot(v, v)) + d * d;
  }
  // The composite works in float32 relative to the mean, so the mean must be a finite float.
  if (!(det > 0.0) || !is_finite(a) || !is_finite(b) || !is_finite(c) || !is_finite(det) ||
      !(abs(mean.x) <= real(FLT_MAX)) || !(abs(mean.y) <= real(FLT_MAX)))
    return 0;

  // A NaN logit has no opacity (min(0.99, NaN) would draw it opaque): culled. +-inf are 1 and 0.
  float logit = opacity_logit_of(i);
  if (isnan(logit)) return 0;
  float opacity = 1.0 / (1.0 + exp(-logit));
  if (COMPENSATE_OPACITY) opacity *= float(sqrt(max(real(2.5e-5), max(det_unfiltered, real(0.0)) / det)));
  real mid = 0.5 * (a + c);
  real lambda = mid + sqrt(max(real(0.1), mid * mid - det));
  // Where alpha = o exp(-k^2 / 2) falls to the cut-off along the major axis: k = sqrt(2 ln(o / cut-off)).
  real sigmas = OPACITY_EXTENT ? real(min(sqrt(max(2.0 * log(ALPHA_INV * opacity), 0.0)), 3.33)) : 3.0;
  real radius = ceil(sigmas * sqrt(lambda));
  if (!is_finite(radius)) return 0;
  // The frame's tiles in the camera's grid: the image's, or a region's (RenderSettings::region).
  real2 first_tile = real2(camera_word(CAMERA_TILES)), end_tile = real2(camera_word(CAMERA_TILES + 1));
  // Clamp before converting: a huge radius must not overflow the integer rect.
  real2 rect_min = clamp(floor((mean - radius) / real(TILE_SIZE)), first_tile, end_tile);
  real2 rect_max = clamp(floor((mean + radius + real(TILE_SIZE - 1)) / real(TILE_SIZE)), first_tile, end_tile);
  uvec2 lo = uvec2(rect_min);
  uvec2 hi = uvec2(rect_max);
  if ((hi.x - lo.x) * (hi.y - lo.y) == 0) return 0;

  // Of the rect, only the tiles the alpha >= cut-off ellipse reaches (tile_coverage.glsl).
  vec2 mean_hi = vec2(mean);
  vec4 cov_det = vec4(a, b, c, det);
  uint touched = 0;
  if (SQUARE_TILES) {
    touched = (hi.x - lo.x) * (hi.y - lo.y);
  } else {
    float tau = coverage_tau(opacity, ALPHA_INV);
    for (uint ty = lo.y; ty < hi.y; ++ty) {
      uvec2 span = row_span(mean_hi, cov_det, tau, ty, lo, hi);
      touched += span.y - span.x;
    }
  }
  if (touched == 0) return 0;

  // The SH are seen along the ray from the camera; an orthographic camera's rays are all its axis.
  vec3 dir = CAMERA_MODEL == MODEL_ORTHOGRAPHIC ? vec3(W[0][2], W[1][2], W[2][2]) : vec3(normalize(rel));
  vec3 colour = eval_sh(SH_DEGREE, pc.sh, i, dir) + 0.5;
  if (any(isnan(colour)) || any(isinf(colour))) return 0;  // NaN or Inf coefficients: culled
  colour = max(colour, vec3(0.0));
  if (LIGHTING) {  // the unlit colour is the albedo
    real3 lit = real3(colour) * light_factor(world, lighting_normal(i, rel));
    // The lit colour must be a finite float too (the reference culls alike).
    if (!(lit.x <= real(FLT_MAX)) || !(lit.y <= real(FLT_MAX)) || !(lit.z <= real(FLT_MAX))) return 0;
    colour = vec3(lit);
  }
  // The mean is stored as float hi + lo so that (pixel - mean) in the composite stays accurate.
  vec2 mean_lo = vec2(mean - real2(mean_hi));
  record[0] = vec4(mean_hi, float(depth), opacity);
  sort_depth = float(DISTANCE_KEY ? length(t) : depth);
  record[1] = vec4(vec3(c / det, -b / det, a / det), mean_lo.x);
  record[2] = vec4(colour, mean_lo.y);
  record[3] = cov_det;
  rect = uvec2(lo.x | (lo.y << 16), hi.x | (hi.y << 16));
  if (RAY_DEPTH) write_ray_depth(i, t, COV_HALF ? W * sigma * transpose(W) : (W * RS) * transpose(W * RS));
  return touched;
}

// The frame's (Gaussian, tile) pair count in 64 bits. The prefix sum over the 32-bit tile counts
// wraps past 2^32 pairs (100k splats covering a 4K frame want 6.5e9), so the projection also counts
// them exactly: the low word's carries go to COUNTER_PAIRS_HIGH, which the frame setup and the host
// read to refuse a frame they cannot hold instead of rendering a wrapped count.
void count_pairs(uint touched) {
  // Halves of 16 bits: a subgroup's sum of each fits 32 bits for any subgroup size up to 65536.
  uint64_t sum = (uint64_t(subgroupAdd(touched >> 16)) << 16) + subgroupAdd(touched & 0xffffu);
  if (!subgroupElect() || sum == 0) return;
  uint low = uint(sum);
  uint high = uint(sum >> 32);
  uint before = atomicAdd(pc.counters.v[COUNTER_PAIRS_LOW], low);
  high += before + low < before ? 1u : 0u;  // this add carried out of the low word
  if (high > 0) atomicAdd(pc.counters.v[COUNTER_PAIRS_HIGH], high);
}

void main() {
  uint j = gl_GlobalInvocationID.x;  // the record: Gaussian i's copy seam_copy
  uint touched = 0;
  uint depth_near = 0xffffffffu, depth_far = 0u;
  if (j < pc.count * SEAM_COPIES) {
    uint seam_copy = j < pc.count ? 0u : 1u;
    uint i = j - seam_copy * pc.count;
    vec4 record[SPLAT_VEC4S];
    uvec2 rect;
    float sort_depth;
    touched = project(i, seam_copy, record, rect, sort_depth);
    write_projected(j, record, rect, touched > 0);
    write_tile_count(j, touched);
    // The sort depth (view depth > near > 0, or a distance > 0), so its IEEE bits order like unsigned
    // integers; their top 24 bits too.
    // 16-bit keys are made by depth_quantize.comp once the visible range is known: here the float
    // bits. Culled Gaussians touch no tile; they sort last only to keep the visible ones together.
    uint depth_bits = floatBitsToUint(sort_depth);
    uint key = DEPTH_KEY_BITS == 24 ? depth_bits >> 8 : depth_bits;
    write_depth_pair(j, touched > 0 ? key : (DEPTH_KEY_BITS == 24 ? 0xffffffu : 0xffffffffu));
    depth_near = touched > 0 ? depth_bits : 0xffffffffu;
    depth_far = touched > 0 ? depth_bits : 0u;
  }
  uint visible = subgroupAdd(touched > 0 ? 1u : 0u);
  if (subgroupElect() && visible > 0) atomicAdd(pc.counters.v[COUNTER_VISIBLE], visible);
  count_pairs(touched);
  if (DEPTH_KEY_BITS == 16) {  // the visible depth range the 16-bit keys are quantized over
    depth_near = subgroupMin(depth_near);
    depth_far = subgroupMax(depth_far);
    if (subgroupElect() && visible > 0) {
      atomicMin(pc.counters.v[COUNTER_DEPTH_MIN], depth_near);
      atomicMax(pc.counters.v[COUNTER_DEPTH_MAX], depth_far);
    }
  }
}
