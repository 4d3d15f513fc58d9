#version 460
// Bitonic sort setup: sizes the sort's dispatches from this frame's key count (read on the GPU), so
// that the passes, recorded for the capacity, launch only the invocations the count needs.
#extension GL_GOOGLE_include_directive : require
#define TS_BITONIC_SETUP_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x = 1) in;

void main() {
  uint n = min(pc.state.v[SORT_COUNT], pc.capacity);
  uint padded = n <= 1u ? 1u : 1u << uint(findMSB(n - 1u) + 1);
  // Every pass gives each invocation group_keys keys of the padded count. No keys, no work.
  uint groups = n == 0u ? 0u : (padded + pc.group_keys - 1u) / pc.group_keys;
  uint workgroups = (groups + pc.workgroup_size - 1u) / pc.workgroup_size;
  pc.state.v[SORT_BLOCKS] = groups;
  pc.state.v[SORT_ARGS + 0] = min(workgroups, pc.max_workgroups);
  pc.state.v[SORT_ARGS + 1] = 1;
  pc.state.v[SORT_ARGS + 2] = 1;
}
