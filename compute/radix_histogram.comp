#version 460
// Radix sort, step 1 of a pass (reduce): each subgroup counts the digits of its block.
//
// GPUs count with shared-memory atomics. The CPU-driver variant (radix_histogram_texel) counts in a
// private array per invocation and adds the lanes' counts up at the end: llvmpipe runs a
// shared-memory atomic as a loop over the SIMD lanes, one locked instruction each, where an indexed
// private array is read and written with unrolled scalar loads and stores (2^22 keys: 417-435 ms
// to 376-386 ms for the whole sort; docs/benchmarks.md).
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#define TS_RADIX_PASS_PUSH  // its push constants (shader_io.h)
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
#ifdef TS_TEXEL_BUFFERS
    uint counts[RADIX];
    for (uint d = 0; d < RADIX; ++d) counts[d] = 0u;
    for (uint k = start + gl_SubgroupInvocationID; k < end; k += gl_SubgroupSize) ++counts[digit_of(radix_load_key(k))];
    for (uint d = 0; d < RADIX; ++d) {
      uint total = subgroupAdd(counts[d]);
      if (subgroupElect()) s_counts[gl_SubgroupID * RADIX + d] = total;
    }
#else
    for (uint k = start + gl_SubgroupInvocationID; k < end; k += gl_SubgroupSize)
      atomicAdd(s_counts[gl_SubgroupID * RADIX + digit_of(radix_load_key(k))], 1u);
#endif
  }
  barrier();

  for (uint i = gl_LocalInvocationIndex; i < SUBGROUPS_PER_WORKGROUP * RADIX; i += gl_WorkGroupSize.x) {
    uint b = gl_WorkGroupID.x * SUBGROUPS_PER_WORKGROUP + i / RADIX;
    if (b < blocks) pc.histogram.v[(i % RADIX) * blocks + b] = s_counts[i];
  }
}
