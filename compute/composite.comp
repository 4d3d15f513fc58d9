#version 460
// Composite: one workgroup per 16x16 tile. The tile's depth-sorted splats are staged through shared
// memory in batches of 256; each pixel blends them front to back, stops at T < 1e-4, and the whole
// tile stops once every pixel has.
//
// Each invocation owns a column of PIXELS_PER_INVOCATION pixels. GPUs use 1 (256 invocations, one
// per pixel). CPU drivers such as lavapipe use 16: there a shared-memory read costs a scalar load per
// SIMD lane, so reading each splat once and blending it into 16 pixels held in registers is 5-10x
// faster, and the workgroup has 2 SIMD groups instead of 32 to switch between at each barrier.
//
// Each staged splat also carries the tile-local pixel box of its alpha >= 1/255 ellipse. Pixels
// outside it would be no-ops (the reference skips them too), so a group of up to 8 rows whose
// pixels all lie outside it is skipped. The skip is written as a loop that runs at most once: CPU
// drivers execute both sides of an `if` under a lane mask, but leave a loop for real once no lane
// is left in it, so only a loop saves the work when a whole SIMD group can skip.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "tile_coverage.glsl"

layout(local_size_x = 16, local_size_y_id = 3) in;  // local_size_y = 16 / PIXELS_PER_INVOCATION
layout(constant_id = 0) const bool WRITE_DEPTH = true;
layout(constant_id = 1) const bool WRITE_COUNT = true;
layout(constant_id = 2) const uint PIXELS_PER_INVOCATION = 1;  // 1, 2, 4, 8 or 16

layout(push_constant) uniform Push {
  Vec4Array splats;
  UintArray sorted_indices;
  Uvec2Array ranges;
  Vec4Array out_rgba;
  FloatArray out_depth;
  UintArray out_count;
  vec4 background;
  uint width;
  uint height;
  uint tiles_x;
} pc;

const uint P = PIXELS_PER_INVOCATION;
const uint ROW_GROUP = P < 8 ? P : 8;  // rows skipped together; P > 8 makes two groups
const uint BATCH = 256;
const uint TILE_PIXELS = TILE_SIZE * TILE_SIZE;
const uint EMPTY_BOX = 0x000Fu;  // x from 15 to 0: no column is inside

shared vec4 s_mean_depth_opacity[BATCH];
shared vec4 s_conic[BATCH];
shared vec4 s_colour[BATCH];
shared uint s_box[BATCH];  // tile-local pixel box: x0 | x1 << 4 | y0 << 8 | y1 << 12, inclusive
shared uint s_done_pixels;

// The invocation's pixels, front to back state.
float T[P];
vec3 colour[P];
float depth_sum[P];
float weight_sum[P];
uint blended[P];
bool done[P];
uint my_done = 0;     // pixels of this invocation that are done
uint newly_done = 0;  // of those, the ones not yet added to s_done_pixels

// Inclusive range of tile-local pixel indices i whose centres i + 0.5 lie in [lo, hi] (relative to
// the tile origin), clamped to the tile; x > y when there is none. 1e-3 px of slack on top of
// coverage_tau's margin: the range may only ever be too large.
ivec2 pixel_span(float lo, float hi) {
  float first = ceil(lo - 0.5 - 1e-3);
  float last = floor(hi - 0.5 + 1e-3);
  if (!(last >= 0.0 && first <= float(TILE_SIZE - 1) && first <= last)) return ivec2(1, 0);
  return ivec2(clamp(first, 0.0, float(TILE_SIZE - 1)), clamp(last, 0.0, float(TILE_SIZE - 1)));
}

// The tile-local pixel box of a splat's alpha >= 1/255 ellipse: its columns are where the ellipse
// crosses the tile's band of rows, its rows the ellipse's full height.
uint splat_box(vec4 mdo, vec4 conic, vec4 colour_lo, vec4 cov_det, vec2 tile_origin) {
  float tau = coverage_tau(mdo.w);
  vec2 centre = vec2((mdo.x - tile_origin.x) + conic.w, (mdo.y - tile_origin.y) + colour_lo.w);
  vec2 x = ellipse_x_range(cov_det, tau, 0.5 - centre.y, float(TILE_SIZE) - 0.5 - centre.y);
  if (!(x.x <= x.y)) return EMPTY_BOX;
  float y_extent = sqrt(tau * cov_det.z);
  ivec2 xs = pixel_span(centre.x + x.x, centre.x + x.y);
  ivec2 ys = pixel_span(centre.y - y_extent, centre.y + y_extent);
  if (xs.x > xs.y || ys.x > ys.y) return EMPTY_BOX;
  return uint(xs.x) | (uint(xs.y) << 4) | (uint(ys.x) << 8) | (uint(ys.y) << 12);
}

// Blends one splat into rows [first, first + ROW_GROUP) of the invocation's column. Branch-free:
// a no-op (w = 0, T unchanged) leaves every sum bit-identical, and selects are cheaper than
// the lane-mask bookkeeping a CPU driver does for a divergent branch.
void blend_rows(uint first, float dx, float py_first, vec4 mdo, vec4 conic, vec4 colour_lo) {
  for (uint q = 0; q < ROW_GROUP; ++q) {
    uint p = min(first + q, P - 1);  // clamp only keeps a never-taken group in bounds
    // mean = hi + lo (see projection.comp): hi - centre is exact for nearby pixels.
    float dy = (mdo.y - (py_first + float(q) + 0.5)) + colour_lo.w;
    float power = -0.5 * (conic.x * dx * dx + conic.z * dy * dy) - conic.y * dx * dy;
    float alpha = min(0.99, mdo.w * exp(power));
    bool hit = !done[p] && power <= 0.0 && alpha >= 1.0 / 255.0;
    float next_T = T[p] * (1.0 - alpha);
    bool finish = hit && next_T < 1e-4;  // done, and this splat is NOT blended (reference)
    bool blend = hit && !finish;
    float w = blend ? alpha * T[p] : 0.0;
    colour[p] += colour_lo.rgb * w;
    depth_sum[p] += mdo.z * w;
    weight_sum[p] += w;
    T[p] = blend ? next_T : T[p];
    blended[p] += blend ? 1u : 0u;
    done[p] = done[p] || finish;
    my_done += finish ? 1u : 0u;
    newly_done += finish ? 1u : 0u;
  }
}

bool reaches_me(uint box, uint local_x, uint local_y0) {
  uvec4 b = uvec4(box & 15u, (box >> 4) & 15u, (box >> 8) & 15u, (box >> 12) & 15u);
  return local_x >= b.x && local_x <= b.y && local_y0 <= b.w && local_y0 + P - 1 >= b.z;
}

void blend_splat(uint j, uint px, uint py0) {
  vec4 mdo = s_mean_depth_opacity[j];
  vec4 conic = s_conic[j];
  vec4 colour_lo = s_colour[j];
  float dx = (mdo.x - (float(px) + 0.5)) + conic.w;
  blend_rows(0, dx, float(py0), mdo, conic, colour_lo);
  if (P > ROW_GROUP) blend_rows(ROW_GROUP, dx, float(py0 + ROW_GROUP), mdo, conic, colour_lo);
}

void main() {
  uvec2 tile = gl_WorkGroupID.xy;
  uint thread = gl_LocalInvocationIndex;
  uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  uint local_x = gl_LocalInvocationID.x;
  uint local_y0 = gl_LocalInvocationID.y * P;  // first row of this invocation in the tile
  vec2 tile_origin = vec2(tile * TILE_SIZE);
  uint px = tile.x * TILE_SIZE + local_x;
  uint py0 = tile.y * TILE_SIZE + local_y0;

  for (uint p = 0; p < P; ++p) {
    T[p] = 1.0;
    colour[p] = vec3(0.0);
    depth_sum[p] = 0.0;
    weight_sum[p] = 0.0;
    blended[p] = 0;
    done[p] = px >= pc.width || py0 + p >= pc.height;
    my_done += done[p] ? 1u : 0u;
  }

  if (thread == 0) s_done_pixels = 0;
  barrier();
  if (my_done > 0) atomicAdd(s_done_pixels, my_done);

  uvec2 range = pc.ranges.v[tile.y * pc.tiles_x + tile.x];
  for (uint batch_start = range.x; batch_start < range.y; batch_start += BATCH) {
    barrier();  // previous batch fully consumed; s_done_pixels up to date
    if (s_done_pixels == TILE_PIXELS) break;
    for (uint k = thread; k < BATCH; k += threads) {
      if (batch_start + k < range.y) {
        uint g = pc.sorted_indices.v[batch_start + k];
        vec4 mdo = pc.splats.v[SPLAT_VEC4S * g + 0];
        vec4 conic = pc.splats.v[SPLAT_VEC4S * g + 1];
        vec4 colour_lo = pc.splats.v[SPLAT_VEC4S * g + 2];
        s_mean_depth_opacity[k] = mdo;
        s_conic[k] = conic;
        s_colour[k] = colour_lo;
        s_box[k] = splat_box(mdo, conic, colour_lo, pc.splats.v[SPLAT_VEC4S * g + 3], tile_origin);
      }
    }
    barrier();
    uint batch_size = min(BATCH, range.y - batch_start);
    if (P == 1) {
      for (uint j = 0; my_done < P && j < batch_size; ++j) {
        if (reaches_me(s_box[j], local_x, local_y0)) blend_splat(j, px, py0);
      }
    } else {
      // CPU drivers run both sides of every branch, so skipping a splat is only real when the
      // loop never gets to it: each invocation first lists the splats whose pixel box meets its
      // column, then blends just those.
      uint list[BATCH];
      uint n = 0;
      for (uint j = 0; j < batch_size; ++j) {
        list[n] = j;
        n += reaches_me(s_box[j], local_x, local_y0) ? 1u : 0u;
      }
      for (uint k = 0; my_done < P && k < n; ++k) blend_splat(list[k], px, py0);
    }
    if (newly_done > 0) atomicAdd(s_done_pixels, newly_done);
    newly_done = 0;
  }

  for (uint p = 0; p < P; ++p) {
    uint py = py0 + p;
    if (px >= pc.width || py >= pc.height) continue;
    uint i = py * pc.width + px;
    pc.out_rgba.v[i] = vec4(colour[p] + T[p] * pc.background.rgb, 1.0 - T[p]);
    if (WRITE_DEPTH) pc.out_depth.v[i] = weight_sum[p] > 0.0 ? depth_sum[p] / weight_sum[p] : 0.0;
    if (WRITE_COUNT) pc.out_count.v[i] = blended[p];
  }
}
