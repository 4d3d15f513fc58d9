#version 460
// Radix sort, step 2 of a pass (scan): one subgroup per digit scans that digit's counts across all
// blocks (exclusive, in place) and records the digit's total. Subgroup scans need no workgroup
// barriers, and a workgroup covers several digits: a CPU driver pays for every workgroup and every
// barrier, which made a workgroup-per-digit scan cost several milliseconds even for a few keys.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#define TS_RADIX_SCAN_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint DIGITS_PER_WORKGROUP = 8;  // subgroups per workgroup

const uint RADIX = 256;

void main() {
  // The loop keeps every digit covered once even where the driver picks another subgroup size than
  // the one the workgroup was sized for.
  uint first = gl_WorkGroupID.x * DIGITS_PER_WORKGROUP;
  uint last = min(first + DIGITS_PER_WORKGROUP, RADIX);
  uint blocks = pc.state.v[SORT_BLOCKS];
  for (uint digit = first + gl_SubgroupID; digit < last; digit += gl_NumSubgroups) {
    uint row = digit * blocks;
    uint running = 0;
    for (uint base = 0; base < blocks; base += gl_SubgroupSize) {
      uint b = base + gl_SubgroupInvocationID;
      uint count = b < blocks ? pc.histogram.v[row + b] : 0u;
      uint prefix = running + subgroupExclusiveAdd(count);
      if (b < blocks) pc.histogram.v[row + b] = prefix;
      running += subgroupAdd(count);
    }
    if (subgroupElect()) pc.digit_totals.v[digit] = running;
  }
}
