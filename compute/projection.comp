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
#include "common.glsl"
#include "sh.glsl"
#include "tile_coverage.glsl"

#ifdef TS_FP32_PROJECTION
#define real float
#define real2 vec2
#define real3 vec3
#define real4 vec4
#define realmat3 mat3
#define to_real(bits) float(packDouble2x32(bits))
#else
#define real double
#define real2 dvec2
#define real3 dvec3
#define real4 dvec4
#define realmat3 dmat3
#endif

layout(local_size_x = 256) in;
layout(constant_id = 0) const int SH_DEGREE = 0;

// Camera, written by the host each frame. Doubles are stored as bit pairs so that the float32
// variant's SPIR-V needs no Float64 capability.
layout(buffer_reference, std430, buffer_reference_align = 8) buffer CameraParams {
  uvec2 rotation[9];         // world-to-camera rotation, row-major, as doubles
  uvec2 centre[3];           // camera centre (world), as doubles
  uvec2 focal_principal[4];  // fx, fy, cx, cy, as doubles
  vec4 clip;                 // 1.3 tan(fov_x/2), 1.3 tan(fov_y/2), near, unused
  uvec4 grid;                // tiles x, tiles y, width, height
};

layout(push_constant) uniform Push {
  FloatArray positions;
  FloatArray log_scales;
  FloatArray rotations;
  FloatArray opacity_logits;
  FloatArray sh;
  CameraParams camera;
  Vec4Array splats;
  Uvec2Array rects;
  UintArray tile_counts;
  UintArray depth_keys;  // the depth sort's input (32-bit keys): view depth bits, culled last
  UintArray depth_values;
  UintArray counters;
  uint count;
} pc;

#ifndef TS_FP32_PROJECTION
real to_real(uvec2 bits) { return packDouble2x32(bits); }
#endif

bool is_finite(real v) { return !isnan(v) && !isinf(v); }

// Returns the tiles touched (0 = culled) and fills the splat record.
uint project(uint i, out vec4 record[SPLAT_VEC4S], out uvec2 rect) {
  CameraParams cam = pc.camera;
  real3 world = real3(pc.positions.v[3 * i], pc.positions.v[3 * i + 1], pc.positions.v[3 * i + 2]);
  real3 rel = world - real3(to_real(cam.centre[0]), to_real(cam.centre[1]), to_real(cam.centre[2]));
  realmat3 W;  // column-major: W[c][r] = rotation[r][c]
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) W[c][r] = to_real(cam.rotation[3 * r + c]);
  real3 t = W * rel;
  if (!(t.z > real(cam.clip.z)) || !is_finite(t.x) || !is_finite(t.y) || !is_finite(t.z)) return 0;

  // exp has no float64 overload in GLSL; its float32 rounding is far below what changes a decision.
  real3 s = real3(exp(vec3(pc.log_scales.v[3 * i], pc.log_scales.v[3 * i + 1], pc.log_scales.v[3 * i + 2])));
  real4 q = real4(pc.rotations.v[4 * i], pc.rotations.v[4 * i + 1], pc.rotations.v[4 * i + 2],
                  pc.rotations.v[4 * i + 3]);  // w x y z
  real qn = dot(q, q);
  q = qn > 0.0 ? q / sqrt(qn) : real4(1, 0, 0, 0);
  real w = q.x, x = q.y, y = q.z, z = q.w;
  realmat3 R = realmat3(1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z), 2.0 * (x * z - w * y),
                        2.0 * (x * y - w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + w * x),
                        2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y));

  real fx = to_real(cam.focal_principal[0]), fy = to_real(cam.focal_principal[1]);
  real cx = to_real(cam.focal_principal[2]), cy = to_real(cam.focal_principal[3]);
  real inv_z = 1.0 / t.z;
  real tx = clamp(t.x * inv_z, -real(cam.clip.x), real(cam.clip.x)) * t.z;
  real ty = clamp(t.y * inv_z, -real(cam.clip.y), real(cam.clip.y)) * t.z;
  // The 2x3 Jacobian's rows, applied to the world-to-camera rotation and then to R S:
  // cov2d = (J W R S)(J W R S)^T, never forming the 3D covariance (better conditioned).
  real3 j0 = real3(fx * inv_z, 0.0, -fx * tx * inv_z * inv_z);
  real3 j1 = real3(0.0, fy * inv_z, -fy * ty * inv_z * inv_z);
  realmat3 RS = R * realmat3(s.x, 0, 0, 0, s.y, 0, 0, 0, s.z);
  realmat3 WRS = W * RS;
  real3 u = j0 * WRS;  // row 0 of J W R S
  real3 v = j1 * WRS;  // row 1
  real a = dot(u, u) + 0.3;
  real b = dot(u, v);
  real c = dot(v, v) + 0.3;
  // det(uu^T + vv^T + 0.3 I) without cancellation: |u x v|^2 + 0.3 (|u|^2 + |v|^2) + 0.09.
  real3 uxv = cross(u, v);
  real det = dot(uxv, uxv) + 0.3 * (dot(u, u) + dot(v, v)) + 0.09;
  real2 mean = real2(fx * t.x * inv_z + cx, fy * t.y * inv_z + cy);
  if (!(det > 0.0) || !is_finite(a) || !is_finite(b) || !is_finite(c) || !is_finite(det) ||
      !is_finite(mean.x) || !is_finite(mean.y))
    return 0;

  real mid = 0.5 * (a + c);
  real lambda = mid + sqrt(max(real(0.1), mid * mid - det));
  real radius = ceil(3.0 * sqrt(lambda));
  if (!is_finite(radius)) return 0;
  real2 grid = real2(cam.grid.xy);
  // Clamp before converting: a huge radius must not overflow the integer rect.
  real2 rect_min = clamp(floor((mean - radius) / real(TILE_SIZE)), real2(0.0), grid);
  real2 rect_max = clamp(floor((mean + radius + real(TILE_SIZE - 1)) / real(TILE_SIZE)), real2(0.0), grid);
  uvec2 lo = uvec2(rect_min);
  uvec2 hi = uvec2(rect_max);
  if ((hi.x - lo.x) * (hi.y - lo.y) == 0) return 0;

  // Of the reference rect, only the tiles the alpha >= 1/255 ellipse reaches (tile_coverage.glsl).
  float opacity = 1.0 / (1.0 + exp(-pc.opacity_logits.v[i]));
  vec2 mean_hi = vec2(mean);
  vec4 cov_det = vec4(a, b, c, det);
  float tau = coverage_tau(opacity);
  uint touched = 0;
  for (uint ty = lo.y; ty < hi.y; ++ty) {
    uvec2 span = row_span(mean_hi, cov_det, tau, ty, lo, hi);
    touched += span.y - span.x;
  }
  if (touched == 0) return 0;

  vec3 dir = vec3(normalize(rel));
  vec3 colour = max(eval_sh(SH_DEGREE, pc.sh, i, dir) + 0.5, vec3(0.0));
  // The mean is stored as float hi + lo so that (pixel - mean) in the composite stays accurate.
  vec2 mean_lo = vec2(mean - real2(mean_hi));
  record[0] = vec4(mean_hi, float(t.z), opacity);
  record[1] = vec4(vec3(c / det, -b / det, a / det), mean_lo.x);
  record[2] = vec4(colour, mean_lo.y);
  record[3] = cov_det;
  rect = uvec2(lo.x | (lo.y << 16), hi.x | (hi.y << 16));
  return touched;
}

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint touched = 0;
  if (i < pc.count) {
    vec4 record[SPLAT_VEC4S];
    uvec2 rect;
    touched = project(i, record, rect);
    if (touched > 0) {
      for (uint k = 0; k < SPLAT_VEC4S; ++k) pc.splats.v[SPLAT_VEC4S * i + k] = record[k];
      pc.rects.v[i] = rect;
    }
    pc.tile_counts.v[i] = touched;
    // View depth > near > 0, so its IEEE bits order like unsigned integers. Culled Gaussians touch
    // no tile; they sort last only to keep the visible ones together.
    pc.depth_keys.v[i] = touched > 0 ? floatBitsToUint(record[0].z) : 0xffffffffu;
    pc.depth_values.v[i] = i;
  }
  uint visible = subgroupAdd(touched > 0 ? 1u : 0u);
  if (subgroupElect() && visible > 0) atomicAdd(pc.counters.v[COUNTER_VISIBLE], visible);
}
