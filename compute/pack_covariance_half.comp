#version 460
// fp16 covariance (AccuracyModes::fp16_covariance), made once per scene on first use: the 3D
// covariance R S S^T R^T of each Gaussian, stored as six 16-bit floats (xx xy, xz yy, yz zz), the
// compact layout of the web viewers. Computed in float32, whose rounding is far below the final
// rounding to half: entries under 6e-8 flush to zero (needles flatten) and over 65504 become
// infinite (the projection then culls the splat).
#extension GL_GOOGLE_include_directive : require
#define TS_PACK_COVARIANCE_HALF_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x = 256) in;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  vec3 s = exp(vec3(pc.log_scales.v[3 * i], pc.log_scales.v[3 * i + 1], pc.log_scales.v[3 * i + 2]));
  vec4 q = vec4(pc.rotations.v[4 * i], pc.rotations.v[4 * i + 1], pc.rotations.v[4 * i + 2], pc.rotations.v[4 * i + 3]);
  // Zeros and denormals are the zero quaternion, the identity (as in projection.comp). Dividing by
  // the largest component first keeps the dot product from overflowing for components near 1e20.
  float largest = max(max(abs(q.x), abs(q.y)), max(abs(q.z), abs(q.w)));
  q = largest >= FLT_MIN ? normalize(q / largest) : vec4(1, 0, 0, 0);
  float w = q.x, x = q.y, y = q.z, z = q.w;
  mat3 R = mat3(1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z), 2.0 * (x * z - w * y),
                2.0 * (x * y - w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + w * x),
                2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y));
  mat3 M = R * mat3(s.x, 0, 0, 0, s.y, 0, 0, 0, s.z);
  mat3 S = M * transpose(M);
  pc.covariances.v[3 * i] = packHalf2x16(vec2(S[0][0], S[1][0]));
  pc.covariances.v[3 * i + 1] = packHalf2x16(vec2(S[2][0], S[1][1]));
  pc.covariances.v[3 * i + 2] = packHalf2x16(vec2(S[2][1], S[2][2]));
}
