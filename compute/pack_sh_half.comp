#version 460
// fp16 SH storage (AccuracyModes::fp16_sh), made once per scene on first use: one invocation per
// output word packs two consecutive float coefficients into 16-bit halves. Halving the SH bytes is
// what the mode buys: SH are most of a scene's memory and of the projection's reads.
#extension GL_GOOGLE_include_directive : require
#define TS_PACK_SH_HALF_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x = 256) in;

// A scene has more words than a dispatch has invocations (3 of them a Gaussian at SH degree 1, 24 at
// degree 3, against the 65,535 workgroups of 256 that lavapipe dispatches): each invocation strides
// through the words by the dispatch's size.
void main() {
  const uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  for (uint w = gl_GlobalInvocationID.x; 2 * w < pc.values; w += stride) {
    float lo = pc.sh.v[2 * w];
    float hi = 2 * w + 1 < pc.values ? pc.sh.v[2 * w + 1] : 0.0;
    pc.sh_half.v[w] = packHalf2x16(vec2(lo, hi));
  }
}
