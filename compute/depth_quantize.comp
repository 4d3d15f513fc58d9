#version 460
// Depth quantization (AccuracyModes::depth_key_bits = 16): one invocation per Gaussian turns the
// float bits the projection wrote into a 16-bit key, linear over the frame's visible depth range,
// as the classic web viewers do. The depth sort then needs two radix digits instead of four; the
// price is that splats closer in depth than range / 65535 tie and keep index order.
#extension GL_GOOGLE_include_directive : require
#define TS_DEPTH_QUANTIZE_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x = 256) in;

const uint CULLED_BITS = 0xffffffffu;
const uint CULLED_KEY = 0xffffu;  // culled Gaussians sort last, after every visible one
const float LAST_VISIBLE_KEY = 65534.0;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  uint bits = pc.depth_keys.v[i];
  if (bits == CULLED_BITS) {
    pc.depth_keys.v[i] = CULLED_KEY;
    return;
  }
  float near = uintBitsToFloat(pc.counters.v[COUNTER_DEPTH_MIN]);
  float far = uintBitsToFloat(pc.counters.v[COUNTER_DEPTH_MAX]);
  float scale = far > near ? LAST_VISIBLE_KEY / (far - near) : 0.0;
  float key = clamp(floor((uintBitsToFloat(bits) - near) * scale), 0.0, LAST_VISIBLE_KEY);
  pc.depth_keys.v[i] = uint(key);
}
