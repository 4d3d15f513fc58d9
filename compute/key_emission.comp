#version 460
// Key emission, step 2: one invocation per Gaussian writes, for every tile its ellipse covers, the
// tile id as the key and the Gaussian's index as the value, at the offset the prefix sum gave it.
// The offsets were taken in depth order, so the pairs lie front to back in memory, equal depths by
// Gaussian index, and the stable tile sort that follows leaves each tile's run in exactly the
// (tile, depth, index) order of the reference, with only the tile bits to sort.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "tile_coverage.glsl"

layout(local_size_x = 256) in;

layout(push_constant) uniform Push {
  Vec4Array splats;
  Uvec2Array rects;
  UintArray tile_counts;
  UintArray offsets;  // per Gaussian: where its pairs start (scatter_offsets.comp)
  UintArray keys;  // 32-bit keys: the tile sort's keys fit (passes/key_buffers.h)
  UintArray values;
  uint count;
  uint tiles_x;
  uint capacity;
  uint tiles;
  uint pad;
} pc;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  uint n = pc.tile_counts.v[i];
  if (n == 0) return;
  uint offset = pc.offsets.v[i];
  if (uint64_t(offset) + n > pc.capacity) return;  // overflow: the frame is re-run with larger buffers
  uvec2 rect = pc.rects.v[i];
  uvec2 lo = uvec2(rect.x & 0xffffu, rect.x >> 16);
  uvec2 hi = uvec2(rect.y & 0xffffu, rect.y >> 16);
  vec4 mdo = pc.splats.v[SPLAT_VEC4S * i];
  vec4 cov_det = pc.splats.v[SPLAT_VEC4S * i + 3];
  float tau = coverage_tau(mdo.w);
  uint end = offset + n;
  for (uint ty = lo.y; ty < hi.y; ++ty) {
    uvec2 span = row_span(mdo.xy, cov_det, tau, ty, lo, hi);
    for (uint tx = span.x; tx < span.y && offset < end; ++tx) {
      pc.keys.v[offset] = ty * pc.tiles_x + tx;
      pc.values.v[offset] = i;
      ++offset;
    }
  }
  // The projection counted with the same function and inputs, so this never runs; it keeps every
  // slot defined even if a driver's arithmetic differed: a tile id past the grid sorts last and is
  // ignored by the tile-range pass.
  for (; offset < end; ++offset) {
    pc.keys.v[offset] = pc.tiles;
    pc.values.v[offset] = i;
  }
}
