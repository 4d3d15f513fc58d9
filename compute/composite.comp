#version 460
// Composite: one 16x16 workgroup per tile, one invocation per pixel. The tile's depth-sorted splats
// are staged through shared memory in batches of 256; each pixel blends front to back and stops at
// T < 1e-4, and the whole tile stops once every pixel has.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;
layout(constant_id = 0) const bool WRITE_DEPTH = true;
layout(constant_id = 1) const bool WRITE_COUNT = true;

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
shared vec4 s_mean_depth_opacity[BATCH];
shared vec4 s_conic[BATCH];
shared vec4 s_colour[BATCH];
shared uint s_done_pixels;

void main() {
  uvec2 tile = gl_WorkGroupID.xy;
  uvec2 pixel = tile * TILE_SIZE + gl_LocalInvocationID.xy;
  uint thread = gl_LocalInvocationIndex;
  bool inside = pixel.x < pc.width && pixel.y < pc.height;
  vec2 centre = vec2(pixel) + 0.5;

  uvec2 range = pc.ranges.v[tile.y * pc.tiles_x + tile.x];
  float T = 1.0;
  vec3 colour = vec3(0.0);
  float depth_sum = 0.0;
  float weight_sum = 0.0;
  uint blended = 0;
  bool done = !inside;

  if (thread == 0) s_done_pixels = 0;
  barrier();
  if (done) atomicAdd(s_done_pixels, 1u);

  for (uint batch_start = range.x; batch_start < range.y; batch_start += BATCH) {
    barrier();  // previous batch fully consumed; s_done_pixels up to date
    if (s_done_pixels == BATCH) break;
    uint k = batch_start + thread;
    if (k < range.y) {
      uint g = pc.sorted_indices.v[k];
      s_mean_depth_opacity[thread] = pc.splats.v[SPLAT_VEC4S * g + 0];
      s_conic[thread] = pc.splats.v[SPLAT_VEC4S * g + 1];
      s_colour[thread] = pc.splats.v[SPLAT_VEC4S * g + 2];
    }
    barrier();
    uint batch_size = min(BATCH, range.y - batch_start);
    for (uint j = 0; !done && j < batch_size; ++j) {
      vec4 mdo = s_mean_depth_opacity[j];
      vec4 conic = s_conic[j];
      // mean = hi + lo (see projection.comp): hi - centre is exact for nearby pixels.
      vec2 d = (mdo.xy - centre) + vec2(conic.w, s_colour[j].w);
      float power = -0.5 * (conic.x * d.x * d.x + conic.z * d.y * d.y) - conic.y * d.x * d.y;
      if (power > 0.0) continue;
      float alpha = min(0.99, mdo.w * exp(power));
      if (alpha < 1.0 / 255.0) continue;
      float next_T = T * (1.0 - alpha);
      if (next_T < 1e-4) {
        done = true;
        atomicAdd(s_done_pixels, 1u);
        break;
      }
      float w = alpha * T;
      colour += s_colour[j].rgb * w;
      depth_sum += mdo.z * w;
      weight_sum += w;
      T = next_T;
      ++blended;
    }
  }

  if (!inside) return;
  uint p = pixel.y * pc.width + pixel.x;
  pc.out_rgba.v[p] = vec4(colour + T * pc.background.rgb, 1.0 - T);
  if (WRITE_DEPTH) pc.out_depth.v[p] = weight_sum > 0.0 ? depth_sum / weight_sum : 0.0;
  if (WRITE_COUNT) pc.out_count.v[p] = blended;
}
