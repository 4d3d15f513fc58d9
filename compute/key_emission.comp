#version 460
// Key emission, step 2: one invocation per Gaussian writes, for every tile its ellipse covers, the
// tile id as the key and the Gaussian's index as the value, at the offset the prefix sum gave it.
// The offsets were taken in depth order, so the pairs lie front to back in memory, equal depths by
// Gaussian index, and the stable tile sort that follows leaves each tile's run in exactly the
// (tile, depth, index) order of the reference, with only the tile bits to sort.
// With 64-bit keys (a strategy that sorts (tile, depth) pairs itself, FrameSortPlan::kTileDepthPairs)
// the offsets are in Gaussian order and the key is tile << 32 | the Gaussian's depth key (the view
// depth's float bits, or fewer bits in an accuracy mode).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "tile_coverage.glsl"

layout(constant_id = 0) const bool WIDE_KEYS = false;
layout(constant_id = 1) const bool SQUARE_TILES = false;  // every tile of the rect (projection.comp)
layout(constant_id = 2) const float ALPHA_INV = 255.0;     // 1 / the alpha cut-off
#include "sort_keys.glsl"

layout(local_size_x = 256) in;

layout(push_constant) uniform Push {
  Vec4Array splats;
  Uvec2Array rects;
  UintArray tile_counts;
  UintArray offsets;  // per Gaussian: where its pairs start (scatter_offsets.comp)
  uint64_t keys;  // see sort_keys.glsl
  UintArray values;
  UintArray depth_keys;  // WIDE_KEYS: per Gaussian, written by the projection
  UintArray big_splats;  // Gaussians with more than BIG_SPLAT_PAIRS pairs, for key_emission_big.comp
  UintArray counters;
  uint count;
  uint tiles_x;
  uint capacity;
  uint tiles;
} pc;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  uint n = pc.tile_counts.v[i];
  if (n == 0) return;
  uint offset = pc.offsets.v[i];
  if (uint64_t(offset) + n > pc.capacity) return;  // overflow: the frame is re-run with larger buffers
  // A splat over thousands of tiles would keep one invocation busy while its neighbours idle, and
  // on llvmpipe a loop past 65535 iterations is silently cut short: such splats are handed to a
  // workgroup each (key_emission_big.comp). The count is that pass's indirect dispatch size.
  if (n > BIG_SPLAT_PAIRS) {
    pc.big_splats.v[atomicAdd(pc.counters.v[COUNTER_BIG_SPLATS], 1u)] = i;
    return;
  }
  uvec2 rect = pc.rects.v[i];
  uvec2 lo = uvec2(rect.x & 0xffffu, rect.x >> 16);
  uvec2 hi = uvec2(rect.y & 0xffffu, rect.y >> 16);
  vec4 mdo = pc.splats.v[SPLAT_VEC4S * i];
  vec4 cov_det = pc.splats.v[SPLAT_VEC4S * i + 3];
  float tau = coverage_tau(mdo.w, ALPHA_INV);
  uint end = offset + n;
  uint64_t depth_bits = WIDE_KEYS ? uint64_t(pc.depth_keys.v[i]) : uint64_t(0);
  for (uint ty = lo.y; ty < hi.y; ++ty) {
    uvec2 span = SQUARE_TILES ? uvec2(lo.x, hi.x) : row_span(mdo.xy, cov_det, tau, ty, lo, hi);
    for (uint tx = span.x; tx < span.y && offset < end; ++tx) {
      store_key(pc.keys, offset, uint64_t(ty * pc.tiles_x + tx) << (WIDE_KEYS ? 32 : 0) | depth_bits);
      pc.values.v[offset] = i;
      ++offset;
    }
  }
  // The projection counted with the same function and inputs, so this never runs; it keeps every
  // slot defined even if a driver's arithmetic differed: a tile id past the grid sorts last and is
  // ignored by the tile-range pass.
  for (; offset < end; ++offset) {
    store_key(pc.keys, offset, uint64_t(pc.tiles) << (WIDE_KEYS ? 32 : 0));
    pc.values.v[offset] = i;
  }
}
