#version 460
// Tile ranges: after the tile sort, each tile's keys (tile ids) are contiguous. One invocation per key finds the
// boundaries where the tile id changes and records [start, end) for the tiles on either side.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 256) in;

layout(push_constant) uniform Push {
  UintArray keys;  // the sorted tile ids (32-bit keys)
  Uvec2Array ranges;  // zero-filled before this pass
  UintArray counters;
  uint tiles;  // keys with a tile id >= tiles are padding (see key_emission.comp)
} pc;

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint n = pc.counters.v[COUNTER_SORT_COUNT];
  if (i >= n) return;
  uint tile = pc.keys.v[i];
  uint prev = i == 0 ? 0xffffffffu : pc.keys.v[i - 1];
  if (prev != tile) {
    if (i > 0 && prev < pc.tiles) pc.ranges.v[prev].y = i;
    if (tile < pc.tiles) pc.ranges.v[tile].x = i;
  }
  if (i == n - 1 && tile < pc.tiles) pc.ranges.v[tile].y = n;
}
