#version 460
// Onesweep sort setup: sizes the per-partition dispatches from this sort's key count (read on the GPU)
// and clears the control block (digit counts, tickets) for this sort.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_memory_scope_semantics : require
#define TS_ONESWEEP_SETUP_PUSH  // its push constants (shader_io.h)
#include "common.glsl"
#include "onesweep_common.glsl"

layout(local_size_x = 256) in;

void main() {
  if (gl_LocalInvocationIndex == 0) {
    uint n = pc.state.v[SORT_COUNT];
    uint partitions = (n + pc.partition_keys - 1) / pc.partition_keys;
    pc.state.v[SORT_BLOCKS] = partitions;
    pc.state.v[SORT_ARGS + 0] = partitions;
    pc.state.v[SORT_ARGS + 1] = 1;
    pc.state.v[SORT_ARGS + 2] = 1;
  }
  for (uint i = gl_LocalInvocationIndex; i < CTRL_UINTS; i += gl_WorkGroupSize.x) pc.control.v[i] = 0;
}
