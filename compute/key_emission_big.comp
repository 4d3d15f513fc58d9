#version 460
// Key emission for big splats: one workgroup per splat that touches more than BIG_SPLAT_PAIRS tiles
// (listed by key_emission.comp). The workgroup takes 256 tile rows at a time, scans their ellipse
// spans to find where each row's pairs start, and every invocation writes its row. No invocation
// loops over more than a row of tiles (at most 16384 on a CPU driver, see check_camera), which
// keeps llvmpipe's 65535-iteration loop limit out of reach and spreads a screen-sized splat's
// thousands of pairs over 256 invocations instead of one.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#define TS_KEY_EMISSION_PUSH  // its push constants (shader_io.h)
#include "common.glsl"
#include "tile_coverage.glsl"
#include "workgroup_scan.glsl"

layout(constant_id = 0) const bool WIDE_KEYS = false;
layout(constant_id = 1) const bool SQUARE_TILES = false;  // every tile of the rect (projection.comp)
layout(constant_id = 2) const float ALPHA_INV = 255.0;     // 1 / the alpha cut-off
#include "sort_keys.glsl"

// The same push constants as key_emission.comp.

void main() {
  uint i = pc.big_splats.v[gl_WorkGroupID.x];
  uint n = pc.tile_counts.v[i];
  uint offset = pc.offsets.v[i];  // key_emission.comp listed it only when its pairs fit the buffers
  uint end = offset + n;
  uvec2 rect = pc.rects.v[i];
  uvec2 lo = uvec2(rect.x & 0xffffu, rect.x >> 16);
  uvec2 hi = uvec2(rect.y & 0xffffu, rect.y >> 16);
  vec4 mdo = pc.splats.v[SPLAT_VEC4S * i];
  vec4 cov_det = pc.splats.v[SPLAT_VEC4S * i + 3];
  float tau = coverage_tau(mdo.w, ALPHA_INV);
  uint64_t depth_bits = WIDE_KEYS ? uint64_t(pc.depth_keys.v[i]) : uint64_t(0);
  uvec2 first = first_tile_of(pc.first_tile);
  // Rows follow the scan's (subgroup, lane) order, so each row's pairs start where the scan says.
  uint linear = gl_SubgroupID * gl_SubgroupSize + gl_SubgroupInvocationID;
  uint row_base = offset;  // where this round's first row starts
  for (uint first_row = lo.y; first_row < hi.y; first_row += SCAN_THREADS) {
    uint ty = first_row + linear;
    uvec2 span = ty >= hi.y ? uvec2(0) : SQUARE_TILES ? uvec2(lo.x, hi.x) : row_span(mdo.xy, cov_det, tau, ty, lo, hi);
    uint round_pairs;
    uint at = row_base + workgroup_exclusive_scan(span.y - span.x, round_pairs);
    for (uint tx = span.x; tx < span.y && at < end; ++tx, ++at) {
      uint tile = (ty - first.y) * pc.tiles_x + (tx - first.x);  // as key_emission.comp
      store_key(pc.keys, at, uint64_t(tile) << (WIDE_KEYS ? 32 : 0) | depth_bits);
      pc.values.v[at] = i;
    }
    row_base += round_pairs;
    barrier();  // the scan's shared memory is reused by the next round
  }
  // As in key_emission.comp: never runs, keeps every slot defined if the counts ever disagreed.
  for (uint at = row_base + gl_LocalInvocationIndex; at < end; at += SCAN_THREADS) {
    store_key(pc.keys, at, uint64_t(pc.tiles) << (WIDE_KEYS ? 32 : 0));
    pc.values.v[at] = i;
  }
}
