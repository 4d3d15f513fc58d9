#version 460
// Radix sort setup: sizes the per-block dispatches from this frame's key count (read on the GPU).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

const uint RADIX_BLOCK_KEYS = SORT_OWN;

layout(local_size_x = 1) in;

layout(push_constant) uniform Push {
  UintArray state;  // the sort's state block
  uint block_keys;        // the block size for counts below large_count
  uint large_count;       // from this count on, blocks are twice as large
  uint subgroups_per_workgroup;
} pc;

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
