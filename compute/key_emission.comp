#version 460
// Key emission: one invocation per Gaussian writes a (tile << 32 | depth bits) key and its index for
// every tile its rectangle covers, at the offset the prefix sum gave it. Keys are emitted in Gaussian
// index order, so a stable sort leaves equal keys ordered by index: every strategy agrees.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "tile_coverage.glsl"

layout(local_size_x = 256) in;

layout(push_constant) uniform Push {
  Vec4Array splats;
  Uvec2Array rects;
  UintArray tile_counts;
  UintArray offsets;
  Uint64Array keys;
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
  // View depth > near > 0, so its IEEE bits order like unsigned integers.
  uint64_t depth_bits = uint64_t(floatBitsToUint(pc.splats.v[SPLAT_VEC4S * i].z));
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
      uint64_t tile = uint64_t(ty * pc.tiles_x + tx);
      pc.keys.v[offset] = (tile << 32) | depth_bits;
      pc.values.v[offset] = i;
      ++offset;
    }
  }
  // The projection counted with the same function and inputs, so this never runs; it keeps every
  // slot defined even if a driver's arithmetic differed: a tile id past the grid sorts last and is
  // ignored by the tile-range pass.
  for (; offset < end; ++offset) {
    pc.keys.v[offset] = uint64_t(pc.tiles) << 32;
    pc.values.v[offset] = i;
  }
}
