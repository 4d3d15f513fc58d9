#version 460
// Tile ranges: after the tile sort, each tile's keys are contiguous. One invocation per key finds the
// boundaries where the tile id changes and records [start, end) for the tiles on either side.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 256) in;
layout(constant_id = 0) const bool WIDE_KEYS = false;

layout(push_constant) uniform Push {
  uint64_t keys;  // the sorted keys: tile ids, or tile << 32 | depth bits (64-bit keys)
  Uvec2Array ranges;  // zero-filled before this pass
  UintArray counters;
  uint tiles;  // keys with a tile id >= tiles are padding (see key_emission.comp)
} pc;

#include "sort_keys.glsl"

uint tile_of(uint i) { return uint(load_key(pc.keys, i) >> (WIDE_KEYS ? 32 : 0)); }

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint n = pc.counters.v[COUNTER_SORT_COUNT];
  if (i >= n) return;
  uint tile = tile_of(i);
  uint prev = i == 0 ? 0xffffffffu : tile_of(i - 1);
  if (prev != tile) {
    if (i > 0 && prev < pc.tiles) pc.ranges.v[prev].y = i;
    if (tile < pc.tiles) pc.ranges.v[tile].x = i;
  }
  if (i == n - 1 && tile < pc.tiles) pc.ranges.v[tile].y = n;
}
