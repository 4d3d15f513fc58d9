#version 460
// Radix sort, step 1 of a pass (reduce): each subgroup counts the digits of its block.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#include "common.glsl"
#include "radix_common.glsl"

shared uint s_counts[SUBGROUPS_PER_WORKGROUP * RADIX];

void main() {
  uint n = pc.state.v[SORT_COUNT];
  uint blocks = pc.state.v[SORT_BLOCKS];
  for (uint i = gl_LocalInvocationIndex; i < SUBGROUPS_PER_WORKGROUP * RADIX; i += gl_WorkGroupSize.x)
    s_counts[i] = 0;
  barrier();

  uint block = gl_WorkGroupID.x * SUBGROUPS_PER_WORKGROUP + gl_SubgroupID;
  if (block < blocks) {
    uint start = block * block_keys();
    uint end = min(start + block_keys(), n);
    for (uint k = start + gl_SubgroupInvocationID; k < end; k += gl_SubgroupSize)
      atomicAdd(s_counts[gl_SubgroupID * RADIX + digit_of(radix_load_key(k))], 1u);
  }
  barrier();

  for (uint i = gl_LocalInvocationIndex; i < SUBGROUPS_PER_WORKGROUP * RADIX; i += gl_WorkGroupSize.x) {
    uint b = gl_WorkGroupID.x * SUBGROUPS_PER_WORKGROUP + i / RADIX;
    if (b < blocks) pc.histogram.v[(i % RADIX) * blocks + b] = s_counts[i];
  }
}
