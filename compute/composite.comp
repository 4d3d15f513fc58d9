#version 460
// Composite: one workgroup per 16x16 tile. The tile's depth-sorted splats are staged through shared
// memory in batches of 256; each pixel blends them front to back, stops at T < 1e-4, and the whole
// tile stops once every pixel has.
//
// Each invocation owns a column of PIXELS_PER_INVOCATION pixels. GPUs use 1 (256 invocations, one
// per pixel). CPU drivers such as lavapipe use 16: there a shared-memory read costs a scalar load per
// SIMD lane, so reading each splat once and blending it into 16 pixels held in registers is 5-10x
// faster, and the workgroup has 2 SIMD groups instead of 32 to switch between at each barrier.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 16, local_size_y_id = 3) in;  // local_size_y = 16 / PIXELS_PER_INVOCATION
layout(constant_id = 0) const bool WRITE_DEPTH = true;
layout(constant_id = 1) const bool WRITE_COUNT = true;
layout(constant_id = 2) const uint PIXELS_PER_INVOCATION = 1;

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

const uint BATCH = 256;
const uint TILE_PIXELS = TILE_SIZE * TILE_SIZE;
shared vec4 s_mean_depth_opacity[BATCH];
shared vec4 s_conic[BATCH];
shared vec4 s_colour[BATCH];
shared uint s_done_pixels;

void main() {
  const uint P = PIXELS_PER_INVOCATION;
  uvec2 tile = gl_WorkGroupID.xy;
  uint thread = gl_LocalInvocationIndex;
  uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  uint px = tile.x * TILE_SIZE + gl_LocalInvocationID.x;
  uint py0 = tile.y * TILE_SIZE + gl_LocalInvocationID.y * P;

  float T[P];
  vec3 colour[P];
  float depth_sum[P];
  float weight_sum[P];
  uint blended[P];
  bool done[P];
  uint my_done = 0;
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
        s_mean_depth_opacity[k] = pc.splats.v[SPLAT_VEC4S * g + 0];
        s_conic[k] = pc.splats.v[SPLAT_VEC4S * g + 1];
        s_colour[k] = pc.splats.v[SPLAT_VEC4S * g + 2];
      }
    }
    barrier();
    uint batch_size = min(BATCH, range.y - batch_start);
    for (uint j = 0; my_done < P && j < batch_size; ++j) {
      vec4 mdo = s_mean_depth_opacity[j];
      vec4 conic = s_conic[j];
      vec4 colour_lo = s_colour[j];
      // mean = hi + lo (see projection.comp): hi - centre is exact for nearby pixels.
      float dx = (mdo.x - (float(px) + 0.5)) + conic.w;
      for (uint p = 0; p < P; ++p) {
        if (done[p]) continue;
        float dy = (mdo.y - (float(py0 + p) + 0.5)) + colour_lo.w;
        float power = -0.5 * (conic.x * dx * dx + conic.z * dy * dy) - conic.y * dx * dy;
        if (power > 0.0) continue;
        float alpha = min(0.99, mdo.w * exp(power));
        if (alpha < 1.0 / 255.0) continue;
        float next_T = T[p] * (1.0 - alpha);
        if (next_T < 1e-4) {  // done, and this splat is NOT blended (reference semantics)
          done[p] = true;
          ++my_done;
          atomicAdd(s_done_pixels, 1u);
          continue;
        }
        float w = alpha * T[p];
        colour[p] += colour_lo.rgb * w;
        depth_sum[p] += mdo.z * w;
        weight_sum[p] += w;
        T[p] = next_T;
        ++blended[p];
      }
    }
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
