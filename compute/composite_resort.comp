#version 460
// Composite with per-pixel re-sorting (AccuracyModes::resort_window, in the spirit of StopThePop,
// Radl et al. 2024). The tile's splats arrive in the order of their centres' view depth, which is
// not the order along every pixel's ray: two overlapping splats swap order for the whole tile at
// once as the camera moves, and the image pops. Here each pixel keeps a window of the WINDOW
// nearest pending splats ordered by the depth of each splat's density maximum along that pixel's
// ray, and blends the nearest whenever the window overflows. Only the blending order changes: each
// splat's alpha and colour are the reference's, and so are the cut-offs.
//
// One workgroup per 16x16 tile, the tile's splats staged through shared memory in batches, as in
// composite.comp and with its two layouts: GPUs run one pixel an invocation and branch on each
// splat's reach; CPU drivers run a 16-pixel column an invocation, read each staged splat once per
// column (a shared-memory read is a scalar load per SIMD lane there) and loop only over the splats
// that reach the column's rows 0-7 and 8-15 (composite_reach.glsl).
//
// The windows are named slots, not arrays: CPU drivers kept the window arrays in memory and gathered
// and scattered them per SIMD lane (on lavapipe the window's work took 6x as long that way: 1.97
// against 0.34 s of resort4's composite on playbot_lod3 at 960x540, one pixel an invocation). Offering
// a splat is one pass of compare-exchanges over the slots, each a select, with no index and no branch.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#define TS_COMPOSITE_RESORT_PUSH
#include "common.glsl"
#include "tile_coverage.glsl"
#include "composite_reach.glsl"

layout(local_size_x = 16, local_size_y_id = 3) in;  // local_size_y = 16 / PIXELS_PER_INVOCATION
layout(constant_id = 0) const bool WRITE_DEPTH = true;
layout(constant_id = 1) const bool WRITE_COUNT = true;
layout(constant_id = 2) const uint PIXELS_PER_INVOCATION = 1;  // 1 (GPUs) or 16 (CPU drivers)
layout(constant_id = 4) const float ALPHA_MIN = 1.0 / 255.0;
layout(constant_id = 5) const float ALPHA_INV = 255.0;  // 1 / ALPHA_MIN, as the tile coverage uses it
layout(constant_id = 6) const float T_MIN = 1e-4;
layout(constant_id = 7) const uint WINDOW = 8;  // 2 to 16
layout(constant_id = 8) const float MAX_ALPHA = 0.99;  // RenderSettings::max_alpha

// The push constants: CompositeResortPush in shader_io.h.

const uint P = PIXELS_PER_INVOCATION;
const uint BATCH = 256;
const uint TILE_PIXELS = TILE_SIZE * TILE_SIZE;

// A staged splat, packed in 64-bit words (CPU drivers pay per read): (mean x, mean y) relative to
// the tile origin, (A', B'), (C', opacity), (view depth, red) with A' = -A/2, B' = -B, C' = -C/2 of
// its conic; (green, blue), then its ray-depth quadric: (Q mu x, Q mu y), (Q mu z, Q_xx), (Q_xy,
// Q_xz), (Q_yy, Q_yz), (Q_zz, mean depth).
shared u64vec4 s_splat_a[BATCH];
shared u64vec4 s_splat_b[BATCH];
shared u64vec2 s_splat_c[BATCH];
// Bit 16 h + x of splat j's reach, s_reach[j / 4][j % 4]: it reaches column x in rows [8 h, 8 h + 7].
shared uvec4 s_reach[BATCH / 4];
shared uint s_done_pixels;

// Per pixel: transmittance (negated once done, as in composite.comp) and sums.
float T[P];
vec3 colour[P];
float depth_sum[P];
float weight_sum[P];
uint blended[P];

// Per pixel, the window: slot k holds (ray depth, alpha) in w_ta<k> and (rgb, view depth) in
// w_cd<k>, nearest first. An empty slot has ray depth -inf and alpha 0: it sorts first, and blending
// it changes nothing.
#define TS_WINDOW_SLOT(k) \
  vec2 w_ta##k[P];        \
  vec4 w_cd##k[P];
TS_WINDOW_SLOT(0) TS_WINDOW_SLOT(1) TS_WINDOW_SLOT(2) TS_WINDOW_SLOT(3)
TS_WINDOW_SLOT(4) TS_WINDOW_SLOT(5) TS_WINDOW_SLOT(6) TS_WINDOW_SLOT(7)
TS_WINDOW_SLOT(8) TS_WINDOW_SLOT(9) TS_WINDOW_SLOT(10) TS_WINDOW_SLOT(11)
TS_WINDOW_SLOT(12) TS_WINDOW_SLOT(13) TS_WINDOW_SLOT(14) TS_WINDOW_SLOT(15)
#undef TS_WINDOW_SLOT

// Blends a splat into pixel p by the reference's rule, branch-free: alpha 0 or a finished pixel is a
// no-op (w = 0 leaves every sum bit-identical). Returns 1 when the pixel finishes.
uint blend(uint p, float alpha, vec4 colour_depth) {
  bool live = T[p] > 0.0 && alpha > 0.0;
  float next_T = T[p] * (1.0 - alpha);
  bool finish = live && next_T < T_MIN;  // done, and this splat is NOT blended (reference)
  bool blend = live && !finish;
  float w = blend ? alpha * T[p] : 0.0;
  colour[p] += colour_depth.rgb * w;
  depth_sum[p] += colour_depth.w * w;
  weight_sum[p] += w;
  T[p] = blend ? next_T : (finish ? -T[p] : T[p]);
  blended[p] += blend ? 1u : 0u;
  return finish ? 1u : 0u;
}

// Offers a splat (when `hit`) to pixel p's window, whose nearest then goes: the nearer of the new
// splat and the slot-0 splat is blended, the new one on a tie (reference::DepthQueue). Otherwise the
// new splat goes in after every pending splat at most as deep: carried from the far slot towards
// slot 0, it settles in the first slot whose splat is at most as deep, and each nearer splat moves
// one slot forward. Returns 1 when the pixel finishes.
uint offer(uint p, bool hit, float t, float alpha, vec4 colour_depth) {
  bool new_first = hit && t <= w_ta0[p].x;  // an empty window's slot 0 is -inf: never
  bool insert = hit && !new_first;
  vec2 carried_ta = vec2(t, alpha);
  vec4 carried_cd = colour_depth;
#define TS_EXCHANGE(k)                                     \
  if (k < WINDOW) {                                        \
    bool here = insert && carried_ta.x >= w_ta##k[p].x;    \
    vec2 slot_ta = w_ta##k[p];                             \
    vec4 slot_cd = w_cd##k[p];                             \
    w_ta##k[p] = here ? carried_ta : slot_ta;              \
    w_cd##k[p] = here ? carried_cd : slot_cd;              \
    carried_ta = here ? slot_ta : carried_ta;              \
    carried_cd = here ? slot_cd : carried_cd;              \
  }
  TS_EXCHANGE(15) TS_EXCHANGE(14) TS_EXCHANGE(13) TS_EXCHANGE(12)
  TS_EXCHANGE(11) TS_EXCHANGE(10) TS_EXCHANGE(9) TS_EXCHANGE(8)
  TS_EXCHANGE(7) TS_EXCHANGE(6) TS_EXCHANGE(5) TS_EXCHANGE(4)
  TS_EXCHANGE(3) TS_EXCHANGE(2) TS_EXCHANGE(1)
#undef TS_EXCHANGE
  // Slot 0's splat is blended and the carried one takes its place (when inserting).
  float out_alpha = new_first ? alpha : (insert ? w_ta0[p].y : 0.0);
  vec4 out_cd = new_first ? colour_depth : w_cd0[p];
  w_ta0[p] = insert ? carried_ta : w_ta0[p];
  w_cd0[p] = insert ? carried_cd : w_cd0[p];
  return blend(p, out_alpha, out_cd);
}

// The ray d = ((x - cx) / fx, (y - cy) / fy, 1) through the pixel at image point `pixel`: (dx, dy).
vec2 pixel_ray(vec2 pixel) { return (pixel - pc.intrinsics.zw) / pc.intrinsics.xy; }

// Depth of a splat's density maximum along the ray d = (dxy, 1): t = (d . Q mu) / (d . Q d). Falls
// back to the splat's mean depth where the quadratic form vanishes (or rounding made it negative).
// q0 = (Q mu, Q_xx), q1 = (Q_xy, Q_xz, Q_yy, Q_yz), q2 = (Q_zz, mean depth).
float ray_depth(vec4 q0, vec4 q1, vec2 q2, vec2 dxy) {
  vec3 d = vec3(dxy, 1.0);
  float numerator = dot(d, q0.xyz);
  float denominator = d.x * (q0.w * d.x + 2.0 * (q1.x * d.y + q1.y)) + d.y * (q1.z * d.y + 2.0 * q1.w) + q2.x;
  float t = numerator / denominator;
  return denominator > 0.0 && !isinf(t) && !isnan(t) ? t : q2.y;
}

// Offers staged splat j to the invocation's pixels first .. first + count - 1 (indices into its
// column; the call sites pass constants, so the window slots stay statically indexed) and returns
// how many of them finished.
uint offer_splat(uint j, uint local_x, uint local_y0, uvec2 pixel0, uint first, uint count) {
  u64vec4 a = s_splat_a[j], b = s_splat_b[j];
  u64vec2 c = s_splat_c[j];
  vec4 mean_a_b = vec4(uintBitsToFloat(unpack32(a.x)), uintBitsToFloat(unpack32(a.y)));
  vec4 c_opacity_depth_r = vec4(uintBitsToFloat(unpack32(a.z)), uintBitsToFloat(unpack32(a.w)));
  vec4 gb_qmu_xy = vec4(uintBitsToFloat(unpack32(b.x)), uintBitsToFloat(unpack32(b.y)));
  vec4 q0 = vec4(gb_qmu_xy.zw, uintBitsToFloat(unpack32(b.z)));
  vec4 q1 = vec4(uintBitsToFloat(unpack32(b.w)), uintBitsToFloat(unpack32(c.x)));
  vec2 q2 = uintBitsToFloat(unpack32(c.y));
  vec4 colour_depth = vec4(c_opacity_depth_r.w, gb_qmu_xy.xy, c_opacity_depth_r.z);
  float dx = mean_a_b.x - (float(local_x) + 0.5);
  // power = k0 + dy (k1 + C' dy): the dx terms are the same for the whole column.
  float k0 = mean_a_b.z * dx * dx;
  float k1 = mean_a_b.w * dx;
  uint finished = 0;
  [[unroll]] for (uint p = first; p < first + count; ++p) {
    float dy = mean_a_b.y - (float(local_y0 + p) + 0.5);
    float power = k0 + dy * (k1 + c_opacity_depth_r.x * dy);
    float alpha = min(MAX_ALPHA, c_opacity_depth_r.y * exp(power));
    bool hit = T[p] > 0.0 && power <= 0.0 && alpha >= ALPHA_MIN;
    float t = ray_depth(q0, q1, q2, pixel_ray(vec2(pixel0.x, pixel0.y + p) + 0.5));
    finished += offer(p, hit, t, alpha, colour_depth);
  }
  return finished;
}

void main() {
  uvec2 tile = first_tile_of(pc.first_tile) + gl_WorkGroupID.xy;  // in the camera's grid
  uint thread = gl_LocalInvocationIndex;
  uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  uint local_x = gl_LocalInvocationID.x;
  uint local_y0 = gl_LocalInvocationID.y * P;
  vec2 tile_origin = vec2(tile * TILE_SIZE);
  uvec2 pixel0 = tile * TILE_SIZE + uvec2(local_x, local_y0);  // the camera's pixel of p = 0
  // and the outputs' (out_x, out_y0 + p): the whole image's, or a region's (composite.comp)
  uint out_x = gl_WorkGroupID.x * TILE_SIZE + local_x;
  uint out_y0 = gl_WorkGroupID.y * TILE_SIZE + local_y0;

  uint my_done = 0;
  uint top_done = 0, bottom_done = 0;  // P == 16: done pixels among rows 0-7 and rows 8-15
  [[unroll]] for (uint p = 0; p < P; ++p) {
    bool outside = out_x >= pc.width || out_y0 + p >= pc.height;
    T[p] = outside ? -1.0 : 1.0;
    colour[p] = vec3(0.0);
    depth_sum[p] = 0.0;
    weight_sum[p] = 0.0;
    blended[p] = 0;
#define TS_EMPTY_SLOT(k)                    \
  w_ta##k[p] = vec2(-1.0 / 0.0, 0.0); \
  w_cd##k[p] = vec4(0.0);
    TS_EMPTY_SLOT(0) TS_EMPTY_SLOT(1) TS_EMPTY_SLOT(2) TS_EMPTY_SLOT(3)
    TS_EMPTY_SLOT(4) TS_EMPTY_SLOT(5) TS_EMPTY_SLOT(6) TS_EMPTY_SLOT(7)
    TS_EMPTY_SLOT(8) TS_EMPTY_SLOT(9) TS_EMPTY_SLOT(10) TS_EMPTY_SLOT(11)
    TS_EMPTY_SLOT(12) TS_EMPTY_SLOT(13) TS_EMPTY_SLOT(14) TS_EMPTY_SLOT(15)
#undef TS_EMPTY_SLOT
    my_done += outside ? 1u : 0u;
    if (p < 8) top_done += outside ? 1u : 0u;
    else bottom_done += outside ? 1u : 0u;
  }
  if (thread == 0) s_done_pixels = 0;
  barrier();
  if (my_done > 0) atomicAdd(s_done_pixels, my_done);
  uint published_done = my_done;
  uint my_bits = my_reach_bits(local_x, local_y0, P);

  uvec2 range = pc.ranges.v[gl_WorkGroupID.y * pc.tiles_x + gl_WorkGroupID.x];
  if (range.y - range.x > pc.max_splats && thread == 0) atomicMax(pc.counters.v[COUNTER_MAX_TILE_PAIRS], range.y - range.x);
  for (uint batch_start = range.x; batch_start < range.y; batch_start += BATCH) {
    barrier();
    if (s_done_pixels == TILE_PIXELS) break;
    uint batch_size = min(BATCH, range.y - batch_start);
    for (uint k = thread; k < batch_size; k += threads) {
      uint g = pc.sorted_indices.v[batch_start + k];
      vec4 mdo = pc.splats.v[SPLAT_VEC4S * g + 0];
      vec4 conic = pc.splats.v[SPLAT_VEC4S * g + 1];
      vec4 colour_lo = pc.splats.v[SPLAT_VEC4S * g + 2];
      vec4 q0 = pc.ray_depth.v[RAY_DEPTH_VEC4S * g + 0];
      vec4 q1 = pc.ray_depth.v[RAY_DEPTH_VEC4S * g + 1];
      vec2 q2 = pc.ray_depth.v[RAY_DEPTH_VEC4S * g + 2].xy;
      vec2 local_mean = vec2((mdo.x - tile_origin.x) + conic.w, (mdo.y - tile_origin.y) + colour_lo.w);
      s_splat_a[k] = u64vec4(pack64(floatBitsToUint(local_mean)), pack64(floatBitsToUint(vec2(-0.5 * conic.x, -conic.y))),
                             pack64(floatBitsToUint(vec2(-0.5 * conic.z, mdo.w))),
                             pack64(floatBitsToUint(vec2(mdo.z, colour_lo.r))));
      s_splat_b[k] = u64vec4(pack64(floatBitsToUint(colour_lo.gb)), pack64(floatBitsToUint(q0.xy)),
                             pack64(floatBitsToUint(q0.zw)), pack64(floatBitsToUint(q1.xy)));
      s_splat_c[k] = u64vec2(pack64(floatBitsToUint(q1.zw)), pack64(floatBitsToUint(q2)));
      s_reach[k / 4][k % 4] = splat_reach(local_mean, mdo.w, pc.splats.v[SPLAT_VEC4S * g + 3], ALPHA_INV);
    }
    barrier();
    if (P == 1) {
      for (uint j = 0; my_done < P && j < batch_size; ++j)
        if ((s_reach[j / 4][j % 4] & my_bits) != 0) my_done += offer_splat(j, local_x, local_y0, pixel0, 0, P);
    } else {
      // A column of 16 spans both row bands of the reach mask: one list per band, so that a splat
      // reaching only rows 0-7 (or 8-15) of this column is offered to those 8 pixels alone, and the
      // loops (which CPU drivers leave for real, unlike branches) run over just the listed splats.
      uint top[BATCH], bottom[BATCH];
      uint n_top = 0, n_bottom = 0;
      for (uint j0 = 0; j0 < batch_size; j0 += 8) {
        uvec4 reach_lo = s_reach[j0 / 4], reach_hi = s_reach[j0 / 4 + 1];
        [[unroll]] for (uint i = 0; i < 8; ++i) {
          uint reach = (i < 4 ? reach_lo[i] : reach_hi[i - 4]) >> local_x;
          reach = j0 + i < batch_size ? reach : 0u;  // entries past batch_size are stale
          top[n_top] = j0 + i;
          bottom[n_bottom] = j0 + i;
          n_top += reach & 1u;
          n_bottom += (reach >> 16) & 1u;
        }
      }
      for (uint k = 0; top_done < 8 && k < n_top; ++k)
        top_done += offer_splat(top[k], local_x, local_y0, pixel0, 0, 8);
      for (uint k = 0; bottom_done < 8 && k < n_bottom; ++k)
        bottom_done += offer_splat(bottom[k], local_x, local_y0, pixel0, 8, 8);
      my_done = top_done + bottom_done;
    }
    if (my_done > published_done) atomicAdd(s_done_pixels, my_done - published_done);
    published_done = my_done;
  }

  // What is still pending is blended nearest first (empty slots change nothing).
  [[unroll]] for (uint p = 0; p < P; ++p) {
#define TS_FLUSH(k) \
  if (k < WINDOW) blend(p, w_ta##k[p].y, w_cd##k[p]);
    TS_FLUSH(0) TS_FLUSH(1) TS_FLUSH(2) TS_FLUSH(3) TS_FLUSH(4) TS_FLUSH(5) TS_FLUSH(6) TS_FLUSH(7)
    TS_FLUSH(8) TS_FLUSH(9) TS_FLUSH(10) TS_FLUSH(11) TS_FLUSH(12) TS_FLUSH(13) TS_FLUSH(14) TS_FLUSH(15)
#undef TS_FLUSH
  }

  [[unroll]] for (uint p = 0; p < P; ++p) {
    uint out_y = out_y0 + p;
    if (out_x >= pc.width || out_y >= pc.height) continue;
    uint i = out_y * pc.width + out_x;
    float transmittance = abs(T[p]);
    pc.out_rgba.v[i] = vec4(colour[p] + transmittance * pc.background.rgb, 1.0 - transmittance);
    if (WRITE_DEPTH) pc.out_depth.v[i] = weight_sum[p] > 0.0 ? depth_sum[p] / weight_sum[p] : 0.0;
    if (WRITE_COUNT) pc.out_count.v[i] = blended[p];
  }
}
