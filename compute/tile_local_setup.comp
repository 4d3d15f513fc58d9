#version 460
// Tile-local sort setup: sizes the dispatch of the passes over the keys from this frame's key count
// (read on the GPU). Those passes loop over the keys, so a capped workgroup count covers any count.
#extension GL_GOOGLE_include_directive : require
#define TS_TILE_LOCAL_SETUP_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x = 1) in;

void main() {
  uint n = min(pc.state.v[SORT_COUNT], pc.capacity);
  uint workgroups = (n + pc.workgroup_size - 1u) / pc.workgroup_size;
  pc.state.v[SORT_BLOCKS] = workgroups;
  pc.state.v[SORT_ARGS + 0] = min(workgroups, pc.max_workgroups);
  pc.state.v[SORT_ARGS + 1] = 1;
  pc.state.v[SORT_ARGS + 2] = 1;
}
