#version 460
// Host depth (a host's depth image on the device, render_to_image): between the host's window depths,
// d = a + b / z (DepthConvention), and the view depths z the composite compares splats with. One
// invocation per pixel.
//   DIRECTION 0, in:  view[i] = b / (window[i] - a), or +inf where that is not positive (a depth at or
//                     beyond infinity, and a NaN: no surface at that pixel)
//   DIRECTION 1, out: window[i] = a + b / surface[i] where the splats' alpha reached the threshold
//                     (surface[i] > 0), else left as it is (the host's own depth)
// In float64, as host_depth.cpp computes it for depths in host memory, so that both give the same
// floats; in float32 on devices without float64 (TS_FP32_HOST_DEPTH).
#extension GL_GOOGLE_include_directive : require
#define TS_HOST_DEPTH_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;
layout(constant_id = 0) const uint DIRECTION = 0;

#ifdef TS_FP32_HOST_DEPTH
#define real float
real convention_a() { return pc.a32; }
real convention_b() { return pc.b32; }
#else
#define real double
real convention_a() { return packDouble2x32(pc.a_bits); }
real convention_b() { return packDouble2x32(pc.b_bits); }
#endif

void main() {
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= pc.width || pixel.y >= pc.height) return;
  uint i = pixel.y * pc.width + pixel.x;
  if (DIRECTION == 0) {
    real z = convention_b() / (real(pc.window.v[i]) - convention_a());
    pc.view.v[i] = z > 0 ? float(z) : uintBitsToFloat(0x7f800000u);
  } else {
    float surface = pc.view.v[i];
    if (surface > 0) pc.window.v[i] = float(convention_a() + convention_b() / real(surface));
  }
}
