#version 460
// Composite with per-pixel re-sorting (AccuracyModes::resort_window, in the spirit of StopThePop,
// Radl et al. 2024). The tile's splats arrive in the order of their centres' view depth, which is
// not the order along every pixel's ray: two overlapping splats swap order for the whole tile at
// once as the camera moves, and the image pops. Here each pixel keeps a window of the WINDOW
// nearest pending splats ordered by the depth of each splat's density maximum along that pixel's
// ray, and blends the nearest whenever the window overflows. Only the blending order changes: each
// splat's alpha and colour are the reference's, and so are the cut-offs.
//
// One workgroup per 16x16 tile, PIXELS_PER_INVOCATION pixels of a column per invocation (as in
// composite.comp), the tile's splats staged through shared memory in batches.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#define TS_COMPOSITE_RESORT_PUSH
#include "common.glsl"

layout(local_size_x = 16, local_size_y_id = 3) in;  // local_size_y = 16 / PIXELS_PER_INVOCATION
layout(constant_id = 0) const bool WRITE_DEPTH = true;
layout(constant_id = 1) const bool WRITE_COUNT = true;
layout(constant_id = 2) const uint PIXELS_PER_INVOCATION = 1;
layout(constant_id = 4) const float ALPHA_MIN = 1.0 / 255.0;
layout(constant_id = 6) const float T_MIN = 1e-4;
layout(constant_id = 7) const uint WINDOW = 8;  // 2 to 16
layout(constant_id = 8) const float MAX_ALPHA = 0.99;  // RenderSettings::max_alpha

// The push constants: CompositeResortPush in shader_io.h.

const uint P = PIXELS_PER_INVOCATION;
const uint BATCH = 128;
const uint TILE_PIXELS = TILE_SIZE * TILE_SIZE;

shared vec4 s_mean_ab[BATCH];     // mean relative to the tile origin, A' = -A/2, B' = -B
shared vec4 s_c_opacity[BATCH];   // C' = -C/2, opacity, view depth, unused
shared vec4 s_colour[BATCH];      // rgb, unused
shared vec4 s_ray0[BATCH];        // Q mu, Q_xx
shared vec4 s_ray1[BATCH];        // Q_xy, Q_xz, Q_yy, Q_yz
shared vec2 s_ray2[BATCH];        // Q_zz, mean depth
shared uint s_done_pixels;

// Per pixel: transmittance (negated once done, as in composite.comp), sums, and the window of
// pending splats sorted by ray depth, nearest first.
float T[P];
vec3 colour[P];
float depth_sum[P];
float weight_sum[P];
uint blended[P];
uint pending[P];
float w_t[P * WINDOW];
float w_alpha[P * WINDOW];
vec4 w_colour_depth[P * WINDOW];

// Blends one splat into pixel p by the reference's rule; returns 1 when the pixel finished.
uint blend(uint p, float alpha, vec4 colour_depth) {
  if (!(T[p] > 0.0)) return 0u;
  float next_T = T[p] * (1.0 - alpha);
  if (next_T < T_MIN) {  // done, and this splat is NOT blended (reference)
    T[p] = -T[p];
    return 1u;
  }
  float w = alpha * T[p];
  colour[p] += colour_depth.rgb * w;
  depth_sum[p] += colour_depth.w * w;
  weight_sum[p] += w;
  T[p] = next_T;
  blended[p] += 1u;
  return 0u;
}

// Offers a splat to pixel p's window. When the window is full, the nearer of the window's nearest
// and the new splat is blended. Returns 1 when the pixel finished. Every loop has a constant trip
// count and every array index is constant once unrolled, so the windows stay in registers (CPU
// drivers would otherwise gather and scatter through memory per lane).
uint offer(uint p, float t, float alpha, vec4 colour_depth) {
  uint base = p * WINDOW;
  bool full = pending[p] == WINDOW;
  bool new_first = full && t <= w_t[base];
  uint finished = 0u;
  if (full)
    finished = blend(p, new_first ? alpha : w_alpha[base], new_first ? colour_depth : w_colour_depth[base]);
  if (new_first) return finished;
  // Drop the blended front.
  [[unroll]] for (uint k = 0; k + 1 < WINDOW; ++k) {
    w_t[base + k] = full ? w_t[base + k + 1] : w_t[base + k];
    w_alpha[base + k] = full ? w_alpha[base + k + 1] : w_alpha[base + k];
    w_colour_depth[base + k] = full ? w_colour_depth[base + k + 1] : w_colour_depth[base + k];
  }
  uint n = full ? WINDOW - 1 : pending[p];
  // Insert after every pending splat at most as deep (equal depths keep arrival order).
  uint at = 0;
  [[unroll]] for (uint k = 0; k < WINDOW; ++k) at += k < n && w_t[base + k] <= t ? 1u : 0u;
  [[unroll]] for (uint k = WINDOW - 1; k > 0; --k) {
    bool shift = k > at && k <= n;
    w_t[base + k] = shift ? w_t[base + k - 1] : w_t[base + k];
    w_alpha[base + k] = shift ? w_alpha[base + k - 1] : w_alpha[base + k];
    w_colour_depth[base + k] = shift ? w_colour_depth[base + k - 1] : w_colour_depth[base + k];
  }
  [[unroll]] for (uint k = 0; k < WINDOW; ++k) {
    w_t[base + k] = k == at ? t : w_t[base + k];
    w_alpha[base + k] = k == at ? alpha : w_alpha[base + k];
    w_colour_depth[base + k] = k == at ? colour_depth : w_colour_depth[base + k];
  }
  pending[p] = n + 1u;
  return finished;
}

// Depth of splat j's density maximum along the ray through the pixel at `pixel` (image coordinates
// of its centre): t = (d . Q mu) / (d . Q d) with d = ((x - cx) / fx, (y - cy) / fy, 1). Falls back
// to the splat's mean depth where the quadratic form vanishes (or rounding made it negative).
float ray_depth(uint j, vec2 pixel) {
  vec3 d = vec3((pixel - pc.intrinsics.zw) / pc.intrinsics.xy, 1.0);
  vec4 r0 = s_ray0[j], r1 = s_ray1[j];
  vec2 r2 = s_ray2[j];
  float numerator = dot(d, r0.xyz);
  float denominator = d.x * (r0.w * d.x + 2.0 * (r1.x * d.y + r1.y)) + d.y * (r1.z * d.y + 2.0 * r1.w) + r2.x;
  float t = numerator / denominator;
  return denominator > 0.0 && !isinf(t) && !isnan(t) ? t : r2.y;
}

void main() {
  uvec2 tile = first_tile_of(pc.first_tile) + gl_WorkGroupID.xy;  // in the camera's grid
  uint thread = gl_LocalInvocationIndex;
  uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  uint local_x = gl_LocalInvocationID.x;
  uint local_y0 = gl_LocalInvocationID.y * P;
  vec2 tile_origin = vec2(tile * TILE_SIZE);
  uint px = tile.x * TILE_SIZE + local_x;  // the camera's pixel (px, py0 + p)
  uint py0 = tile.y * TILE_SIZE + local_y0;
  // and the outputs' (out_x, out_y0 + p): the whole image's, or a region's (composite.comp)
  uint out_x = gl_WorkGroupID.x * TILE_SIZE + local_x;
  uint out_y0 = gl_WorkGroupID.y * TILE_SIZE + local_y0;

  uint my_done = 0;
  for (uint p = 0; p < P; ++p) {
    bool outside = out_x >= pc.width || out_y0 + p >= pc.height;
    T[p] = outside ? -1.0 : 1.0;
    colour[p] = vec3(0.0);
    depth_sum[p] = 0.0;
    weight_sum[p] = 0.0;
    blended[p] = 0;
    pending[p] = 0;
    my_done += outside ? 1u : 0u;
  }
  if (thread == 0) s_done_pixels = 0;
  barrier();
  if (my_done > 0) atomicAdd(s_done_pixels, my_done);
  uint published_done = my_done;

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
      vec2 local_mean = vec2((mdo.x - tile_origin.x) + conic.w, (mdo.y - tile_origin.y) + colour_lo.w);
      s_mean_ab[k] = vec4(local_mean, -0.5 * conic.x, -conic.y);
      s_c_opacity[k] = vec4(-0.5 * conic.z, mdo.w, mdo.z, 0.0);
      s_colour[k] = vec4(colour_lo.rgb, 0.0);
      s_ray0[k] = pc.ray_depth.v[RAY_DEPTH_VEC4S * g + 0];
      s_ray1[k] = pc.ray_depth.v[RAY_DEPTH_VEC4S * g + 1];
      s_ray2[k] = pc.ray_depth.v[RAY_DEPTH_VEC4S * g + 2].xy;
    }
    barrier();
    for (uint j = 0; my_done < P && j < batch_size; ++j) {
      vec4 mean_ab = s_mean_ab[j];
      vec4 c_opacity = s_c_opacity[j];
      float dx = mean_ab.x - (float(local_x) + 0.5);
      [[unroll]] for (uint p = 0; p < P; ++p) {
        if (!(T[p] > 0.0)) continue;
        float dy = mean_ab.y - (float(local_y0 + p) + 0.5);
        float power = mean_ab.z * dx * dx + mean_ab.w * dx * dy + c_opacity.x * dy * dy;
        if (power > 0.0) continue;
        float alpha = min(MAX_ALPHA, c_opacity.y * exp(power));
        if (alpha < ALPHA_MIN) continue;
        vec2 pixel = vec2(px, py0 + p) + 0.5;
        my_done += offer(p, ray_depth(j, pixel), alpha, vec4(s_colour[j].rgb, c_opacity.z));
      }
    }
    if (my_done > published_done) atomicAdd(s_done_pixels, my_done - published_done);
    published_done = my_done;
  }

  // What is still pending is blended nearest first.
  for (uint p = 0; p < P; ++p)
    for (uint k = 0; k < pending[p]; ++k) blend(p, w_alpha[p * WINDOW + k], w_colour_depth[p * WINDOW + k]);

  for (uint p = 0; p < P; ++p) {
    uint out_y = out_y0 + p;
    if (out_x >= pc.width || out_y >= pc.height) continue;
    uint i = out_y * pc.width + out_x;
    float transmittance = abs(T[p]);
    pc.out_rgba.v[i] = vec4(colour[p] + transmittance * pc.background.rgb, 1.0 - transmittance);
    if (WRITE_DEPTH) pc.out_depth.v[i] = weight_sum[p] > 0.0 ? depth_sum[p] / weight_sum[p] : 0.0;
    if (WRITE_COUNT) pc.out_count.v[i] = blended[p];
  }
}
