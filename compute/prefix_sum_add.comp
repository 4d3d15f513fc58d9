#version 460
// Exclusive prefix sum, step 2: adds each block's scanned offset to its already locally scanned values.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "common.glsl"
#include "workgroup_scan.glsl"

layout(push_constant) uniform Push {
  UintArray data;
  UintArray block_offsets;
  uint count;
} pc;

void main() {
  uint offset = pc.block_offsets.v[gl_WorkGroupID.x];
  uint base = gl_WorkGroupID.x * SCAN_BLOCK + gl_LocalInvocationIndex;
  for (uint k = 0; k < SCAN_ITEMS; ++k) {
    uint i = base + k * SCAN_THREADS;
    if (i < pc.count) pc.data.v[i] += offset;
  }
}
