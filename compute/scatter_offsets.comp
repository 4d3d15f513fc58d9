#version 460
// Key emission, step 1. The prefix sum ran over the tile counts in depth order; this hands each
// Gaussian its offset, so that the emission reads its per-Gaussian inputs in index order
// (sequential) instead of in depth order (four random reads per Gaussian instead of one write).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 256) in;

layout(push_constant) uniform Push {
  UintArray depth_order;    // Gaussian indices, front to back
  UintArray depth_offsets;  // exclusive prefix sum of the tile counts, in depth order
  UintArray offsets;        // out: the same offsets, per Gaussian
  uint count;
} pc;

void main() {
  uint position = gl_GlobalInvocationID.x;
  if (position < pc.count) pc.offsets.v[pc.depth_order.v[position]] = pc.depth_offsets.v[position];
}
