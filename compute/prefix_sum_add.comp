#version 460
// Exclusive prefix sum, step 2: adds each block's scanned offset to its already locally scanned values.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#define TS_PREFIX_SUM_ADD_PUSH  // its push constants (shader_io.h)
#include "common.glsl"
#include "workgroup_scan.glsl"

void main() {
  uint offset = pc.block_offsets.v[gl_WorkGroupID.x];
  uint base = gl_WorkGroupID.x * SCAN_BLOCK + gl_LocalInvocationIndex;
  for (uint k = 0; k < SCAN_ITEMS; ++k) {
    uint i = base + k * SCAN_THREADS;
    if (i < pc.count) pc.data.v[i] += offset;
  }
}
