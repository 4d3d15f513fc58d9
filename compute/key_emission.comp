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
#define TS_KEY_EMISSION_PUSH  // its push constants (shader_io.h)
#include "common.glsl"
#include "tile_coverage.glsl"

layout(constant_id = 0) const bool WIDE_KEYS = false;
layout(constant_id = 1) const bool SQUARE_TILES = false;  // every tile of the rect (projection.comp)
layout(constant_id = 2) const float ALPHA_INV = 255.0;     // 1 / the alpha cut-off
#include "sort_keys.glsl"

layout(local_size_x = 256) in;

#ifdef TS_TEXEL_BUFFERS
// The CPU-driver variant (key_emission_texel): the per-Gaussian inputs and the pairs through texel
// buffers, which llvmpipe reads and writes with SIMD gathers and scatters, where a load or store at a
// per-invocation address is a loop over the SIMD lanes (vk::texel_buffers_wanted). Narrow keys are
// R32_UINT texels, wide ones R32G32_UINT (low word first); the same buffers as the addresses.
layout(set = 0, binding = 0) uniform textureBuffer splat_texels;
layout(set = 0, binding = 1) uniform utextureBuffer rect_texels;
layout(set = 0, binding = 2) uniform utextureBuffer tile_count_texels;
layout(set = 0, binding = 3) uniform utextureBuffer offset_texels;
layout(set = 0, binding = 4, r32ui) uniform writeonly uimageBuffer narrow_key_texels;
layout(set = 0, binding = 5, rg32ui) uniform writeonly uimageBuffer wide_key_texels;
layout(set = 0, binding = 6, r32ui) uniform writeonly uimageBuffer value_texels;
vec4 splat_vec4(uint i, uint k) { return texelFetch(splat_texels, int(SPLAT_VEC4S * i + k)); }
uvec2 rect_of(uint i) { return texelFetch(rect_texels, int(i)).xy; }
uint tile_count_of(uint i) { return texelFetch(tile_count_texels, int(i)).x; }
uint offset_of(uint i) { return texelFetch(offset_texels, int(i)).x; }
void write_pair(uint slot, uint64_t key, uint value) {
  if (WIDE_KEYS)
    imageStore(wide_key_texels, int(slot), uvec4(unpack32(key), 0u, 0u));
  else
    imageStore(narrow_key_texels, int(slot), uvec4(uint(key)));
  imageStore(value_texels, int(slot), uvec4(value));
}
#else
vec4 splat_vec4(uint i, uint k) { return pc.splats.v[SPLAT_VEC4S * i + k]; }
uvec2 rect_of(uint i) { return pc.rects.v[i]; }
uint tile_count_of(uint i) { return pc.tile_counts.v[i]; }
uint offset_of(uint i) { return pc.offsets.v[i]; }
void write_pair(uint slot, uint64_t key, uint value) {
  store_key(pc.keys, slot, key);
  pc.values.v[slot] = value;
}
#endif

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  uint n = tile_count_of(i);
  if (n == 0) return;
  uint offset = offset_of(i);
  if (uint64_t(offset) + n > pc.capacity) return;  // overflow: the frame is re-run with larger buffers
  // A splat over thousands of tiles would keep one invocation busy while its neighbours idle, and
  // on llvmpipe a loop past 65535 iterations is silently cut short: such splats are handed to a
  // workgroup each (key_emission_big.comp). The count is that pass's indirect dispatch size.
  if (n > BIG_SPLAT_PAIRS) {
    pc.big_splats.v[atomicAdd(pc.counters.v[COUNTER_BIG_SPLATS], 1u)] = i;
    return;
  }
  uvec2 rect = rect_of(i);
  uvec2 lo = uvec2(rect.x & 0xffffu, rect.x >> 16);
  uvec2 hi = uvec2(rect.y & 0xffffu, rect.y >> 16);
  vec4 mdo = splat_vec4(i, 0);
  vec4 cov_det = splat_vec4(i, 3);
  float tau = coverage_tau(mdo.w, ALPHA_INV);
  uint end = offset + n;
  uint64_t depth_bits = WIDE_KEYS ? uint64_t(pc.depth_keys.v[i]) : uint64_t(0);
  uvec2 first = first_tile_of(pc.first_tile);  // the rect is in the camera's grid, tile ids the frame's
  for (uint ty = lo.y; ty < hi.y; ++ty) {
    uvec2 span = SQUARE_TILES ? uvec2(lo.x, hi.x) : row_span(mdo.xy, cov_det, tau, ty, lo, hi);
    for (uint tx = span.x; tx < span.y && offset < end; ++tx) {
      uint tile = (ty - first.y) * pc.tiles_x + (tx - first.x);
      write_pair(offset, uint64_t(tile) << (WIDE_KEYS ? 32 : 0) | depth_bits, i);
      ++offset;
    }
  }
  // The projection counted with the same function and inputs, so this never runs; it keeps every
  // slot defined even if a driver's arithmetic differed: a tile id past the grid sorts last and is
  // ignored by the tile-range pass.
  for (; offset < end; ++offset) {
    write_pair(offset, uint64_t(pc.tiles) << (WIDE_KEYS ? 32 : 0), i);
  }
}
