#version 460
// Exclusive prefix sum, step 1 of reduce-then-scan: each workgroup scans its block of 1024 values
// locally and writes the block's total, which the next level scans. Portable to any subgroup size:
// element order follows (subgroup id, lane), never an assumed mapping of invocations to subgroups.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#define TS_PREFIX_SUM_BLOCKS_PUSH  // its push constants (shader_io.h)
#include "common.glsl"
#include "workgroup_scan.glsl"

void main() {
  uint linear = gl_SubgroupID * gl_SubgroupSize + gl_SubgroupInvocationID;
  uint base = gl_WorkGroupID.x * SCAN_BLOCK + linear * SCAN_ITEMS;
  uint v[SCAN_ITEMS];
  uint thread_sum = 0;
  for (uint k = 0; k < SCAN_ITEMS; ++k) {
    uint index = base + k;
    if (pc.gather != 0u && index < pc.count) index = pc.order.v[index];
    v[k] = base + k < pc.count ? pc.src.v[index] : 0u;
    thread_sum += v[k];
  }
  uint block_total;
  uint running = workgroup_exclusive_scan(thread_sum, block_total);
  for (uint k = 0; k < SCAN_ITEMS; ++k) {
    if (base + k < pc.count) pc.dst.v[base + k] = running;
    running += v[k];
  }
  if (gl_LocalInvocationIndex == 0) pc.block_sums.v[gl_WorkGroupID.x] = block_total;
}
