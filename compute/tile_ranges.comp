#version 460
// Tile ranges: after the tile sort, each tile's keys are contiguous. One invocation per key finds the
// boundaries where the tile id changes and records [start, end) for the tiles on either side.
#extension GL_GOOGLE_include_directive : require
#define TS_TILE_RANGES_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x = 256) in;
layout(constant_id = 0) const bool WIDE_KEYS = false;

#include "sort_keys.glsl"

#ifdef TS_TEXEL_BUFFERS
// The CPU-driver variant (tile_ranges_texel): the sorted keys and the frame's counters through texel
// buffers, which llvmpipe reads with SIMD gathers (vk::texel_buffers_wanted). Narrow keys are R32_UINT
// texels, wide ones R32G32_UINT (low word first: the tile is the second word).
layout(set = 0, binding = 0) uniform utextureBuffer key_texels;
layout(set = 0, binding = 1) uniform utextureBuffer counter_texels;  // R32_UINT
uint tile_of(uint i) {
  uvec2 words = texelFetch(key_texels, int(i)).xy;
  return WIDE_KEYS ? words.y : words.x;
}
uint sort_count() { return texelFetch(counter_texels, int(COUNTER_SORT_COUNT)).x; }
#else
uint tile_of(uint i) { return uint(load_key(pc.keys, i) >> (WIDE_KEYS ? 32 : 0)); }
uint sort_count() { return pc.counters.v[COUNTER_SORT_COUNT]; }
#endif

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint n = sort_count();
  if (i >= n) return;
  uint tile = tile_of(i);
  uint prev = i == 0 ? 0xffffffffu : tile_of(i - 1);
  if (prev != tile) {
    if (i > 0 && prev < pc.tiles) pc.ranges.v[prev].y = i;
    if (tile < pc.tiles) pc.ranges.v[tile].x = i;
  }
  if (i == n - 1 && tile < pc.tiles) pc.ranges.v[tile].y = n;
}
