#version 460
// Radix sort setup: sizes the per-block dispatches from this frame's key count (read on the GPU).
#extension GL_GOOGLE_include_directive : require
#define TS_RADIX_SETUP_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

const uint RADIX_BLOCK_KEYS = SORT_OWN;

layout(local_size_x = 1) in;

void main() {
  uint n = pc.state.v[SORT_COUNT];
  uint block_keys = n >= pc.large_count ? 2 * pc.block_keys : pc.block_keys;
  uint blocks = (n + block_keys - 1) / block_keys;
  pc.state.v[SORT_BLOCKS] = blocks;
  pc.state.v[RADIX_BLOCK_KEYS] = block_keys;
  pc.state.v[SORT_ARGS + 0] = (blocks + pc.subgroups_per_workgroup - 1) / pc.subgroups_per_workgroup;
  pc.state.v[SORT_ARGS + 1] = 1;
  pc.state.v[SORT_ARGS + 2] = 1;
}
