#version 460
// Radix sort, step 2 of a pass (scan): one workgroup per digit scans that digit's counts across all
// blocks (exclusive, in place) and records the digit's total.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "common.glsl"
#include "workgroup_scan.glsl"

layout(push_constant) uniform Push {
  UintArray histogram;
  UintArray digit_totals;
  UintArray state;  // the sort's state block
} pc;

void main() {
  uint digit = gl_WorkGroupID.x;
  uint blocks = pc.state.v[SORT_BLOCKS];
  uint row = digit * blocks;
  uint linear = gl_SubgroupID * gl_SubgroupSize + gl_SubgroupInvocationID;
  uint running = 0;
  for (uint chunk = 0; chunk < blocks; chunk += SCAN_BLOCK) {
    uint base = chunk + linear * SCAN_ITEMS;
    uint v[SCAN_ITEMS];
    uint thread_sum = 0;
    for (uint k = 0; k < SCAN_ITEMS; ++k) {
      v[k] = base + k < blocks ? pc.histogram.v[row + base + k] : 0u;
      thread_sum += v[k];
    }
    uint chunk_total;
    uint prefix = running + workgroup_exclusive_scan(thread_sum, chunk_total);
    for (uint k = 0; k < SCAN_ITEMS; ++k) {
      if (base + k < blocks) pc.histogram.v[row + base + k] = prefix;
      prefix += v[k];
    }
    running += chunk_total;
    barrier();  // the scan's shared memory is reused by the next chunk
  }
  if (gl_LocalInvocationIndex == 0) pc.digit_totals.v[digit] = running;
}
