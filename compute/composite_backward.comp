#version 460
// Composite backward: one workgroup per 16x16 tile (docs/gradients.md). Each pixel first walks its tile's
// list front to back as composite.comp blends it, to find where it stopped, its final transmittance and
// its depth sums; then it walks back from its last blended splat to the first, recovering each splat's
// transmittance by division (T_i = T_{i+1} / (1 - alpha_i), as the 3DGS trainer and gsplat do) and
// forming the splat's screen-space gradient.
//
// As in composite.comp, an invocation owns a column of PIXELS_PER_INVOCATION pixels: 1 on GPUs, 16 on CPU
// drivers, where each staged splat is then read once per column and its gradient summed over the column
// in registers. The tile's splats are staged through shared memory in batches, and every invocation visits
// the same staged splat at once, so a subgroup sums its columns' gradients before one invocation adds them
// to the splat's (a float atomic add, or a compare-and-swap loop where the device has none:
// TS_CAS_FLOAT_ADD).
//
// llvmpipe ends an invocation after 65535 loop iterations in all (tile_composite_layout.cpp): the loops over
// a column's pixels are unrolled, so that a splat costs two iterations (one per walk) and a tile list within
// the forward's one dispatch (8192 splats on CPU drivers) stays within the limit; Renderer::backward refuses
// a frame with a longer list there.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_vote : require
#ifndef TS_CAS_FLOAT_ADD
#extension GL_EXT_shader_atomic_float : require
#endif
#define TS_COMPOSITE_BACKWARD_PUSH
#include "common.glsl"

layout(local_size_x = 16, local_size_y_id = 3) in;  // local_size_y = 16 / PIXELS_PER_INVOCATION
// The forward's cut-offs, as composite.comp's (the reference's: the backward covers no other mode).
layout(constant_id = 0) const float ALPHA_MIN = 1.0 / 255.0;
layout(constant_id = 1) const float T_MIN = 1e-4;
layout(constant_id = 2) const float MAX_ALPHA = 0.99;
layout(constant_id = 4) const uint PIXELS_PER_INVOCATION = 1;  // 1 or 16

const uint P = PIXELS_PER_INVOCATION;
const uint BATCH = 256;
const uint TILE_PIXELS = TILE_SIZE * TILE_SIZE;
shared vec4 s_mean_a_b[BATCH];         // mean relative to the tile origin, A' = -A/2, B' = -B
shared vec4 s_c_opacity_depth[BATCH];  // C' = -C/2, opacity, view depth, record index (as float bits)
shared vec4 s_colour[BATCH];
shared uint s_done;  // the tile's pixels done (or outside the image)
shared uint s_last;  // one past the furthest list position any pixel of the tile blended

#ifdef TS_CAS_FLOAT_ADD
void add_gradient(uint k, float value) {
  UintArray bits = UintArray(uint64_t(pc.splat_gradients));
  uint seen = bits.v[k];
  for (;;) {
    uint wanted = floatBitsToUint(uintBitsToFloat(seen) + value);
    uint found = atomicCompSwap(bits.v[k], seen, wanted);
    if (found == seen) break;
    seen = found;
  }
}
#else
void add_gradient(uint k, float value) { atomicAdd(pc.splat_gradients.v[k], value); }
#endif

// List entries [batch_start, batch_start + BATCH) of the tile staged, as composite.comp reads a record.
// Returns the tile's pixels done before the batch: read between the barriers, where no invocation adds
// to it, so that every invocation sees the same count and leaves the loop together.
uint stage(uint batch_start, uint list_end, vec2 tile_origin) {
  barrier();
  uint done_before = s_done;
  for (uint k = gl_LocalInvocationIndex; k < BATCH; k += gl_WorkGroupSize.x * gl_WorkGroupSize.y) {
    if (batch_start + k >= list_end) break;
    uint g = pc.sorted_indices.v[batch_start + k];
    vec4 mdo = pc.splats.v[SPLAT_VEC4S * g];
    vec4 conic = pc.splats.v[SPLAT_VEC4S * g + 1];
    vec4 colour_lo = pc.splats.v[SPLAT_VEC4S * g + 2];
    vec2 local_mean = vec2((mdo.x - tile_origin.x) + conic.w, (mdo.y - tile_origin.y) + colour_lo.w);
    s_mean_a_b[k] = vec4(local_mean, -0.5 * conic.x, -conic.y);
    s_c_opacity_depth[k] = vec4(-0.5 * conic.z, mdo.w, mdo.z, uintBitsToFloat(g));
    s_colour[k] = vec4(colour_lo.rgb, 0.0);
  }
  barrier();
  return done_before;
}

// The invocation's pixels' state. Front to back: T, the depth sums, where each stopped.
float T[P];
float depth_sum[P];
float weight_sum[P];
uint last[P];  // one past the list position of the pixel's last blended splat (0: none)
bool done[P];
// Back to front: the loss's gradients of the pixel's outputs and the sums behind the current splat.
vec4 g_rgba[P];
float g_depth[P];   // of D = sum w z (the expected depth's share included)
float g_weight[P];  // of W = sum w (the expected depth's)
float final_T[P];
vec3 behind_rgb[P];
float behind_depth[P];
float behind_weight[P];

void main() {
  uvec2 tile = gl_WorkGroupID.xy;
  uint local_x = gl_LocalInvocationID.x;
  uint local_y0 = gl_LocalInvocationID.y * P;  // first row of this invocation in the tile
  vec2 tile_origin = vec2(tile * TILE_SIZE);
  uint image_x = tile.x * TILE_SIZE + local_x;
  uvec2 range = pc.ranges.v[tile.y * pc.tiles_x + tile.x];

  if (gl_LocalInvocationIndex == 0) {
    s_done = 0;
    s_last = 0;
  }
  uint my_done = 0;
  [[unroll]] for (uint p = 0; p < P; ++p) {
    uint image_y = tile.y * TILE_SIZE + local_y0 + p;
    T[p] = 1.0;
    depth_sum[p] = 0.0;
    weight_sum[p] = 0.0;
    last[p] = 0;
    done[p] = image_x >= pc.width || image_y >= pc.height;
    my_done += done[p] ? 1u : 0u;
  }
  barrier();
  if (my_done > 0) atomicAdd(s_done, my_done);

  // Front to back, in composite.comp's operations: where each pixel stops.
  for (uint batch_start = range.x; batch_start < range.y; batch_start += BATCH) {
    if (stage(batch_start, range.y, tile_origin) == TILE_PIXELS) break;
    uint batch_count = min(BATCH, range.y - batch_start);
    uint finished = 0;
    for (uint j = 0; j < batch_count; ++j) {
      vec4 mab = s_mean_a_b[j];
      vec4 cod = s_c_opacity_depth[j];
      float dx = mab.x - (float(local_x) + 0.5);
      float k0 = mab.z * dx * dx;
      float k1 = mab.w * dx;
      [[unroll]] for (uint p = 0; p < P; ++p) {
        float dy = mab.y - (float(local_y0 + p) + 0.5);
        float power = k0 + dy * (k1 + cod.x * dy);
        float alpha = min(MAX_ALPHA, cod.y * exp(power));
        bool hit = !done[p] && alpha >= ALPHA_MIN;
        float next_T = T[p] * (1.0 - alpha);
        bool finish = hit && next_T < T_MIN;  // done, and this splat is NOT blended (reference)
        bool blend = hit && !finish;
        float w = blend ? alpha * T[p] : 0.0;
        depth_sum[p] += cod.z * w;
        weight_sum[p] += w;
        T[p] = blend ? next_T : T[p];
        last[p] = blend ? batch_start + j + 1 : last[p];
        done[p] = done[p] || finish;
        finished += finish ? 1u : 0u;
      }
    }
    if (finished > 0) atomicAdd(s_done, finished);
  }

  uint my_last = 0;
  [[unroll]] for (uint p = 0; p < P; ++p) {
    uint image_y = tile.y * TILE_SIZE + local_y0 + p;
    bool inside = image_x < pc.width && image_y < pc.height;
    uint pixel_index = image_y * pc.width + image_x;
    g_rgba[p] = inside ? pc.pixel_rgba_gradients.v[pixel_index] : vec4(0.0);
    vec2 g_depths = inside ? uintBitsToFloat(pc.pixel_depth_gradients.v[pixel_index]) : vec2(0.0);
    // The expected depth E = D / W passes its gradient to D = sum w z and W = sum w.
    g_depth[p] = g_depths.y + (weight_sum[p] > 0.0 ? g_depths.x / weight_sum[p] : 0.0);
    g_weight[p] = weight_sum[p] > 0.0 ? -g_depths.x * depth_sum[p] / (weight_sum[p] * weight_sum[p]) : 0.0;
    final_T[p] = T[p];
    behind_rgb[p] = pc.background.rgb * T[p];
    behind_depth[p] = 0.0;
    behind_weight[p] = 0.0;
    my_last = max(my_last, last[p]);
  }
  if (my_last > 0) atomicMax(s_last, my_last);
  barrier();
  uint tile_last = s_last;
  if (tile_last == 0) return;

  // Back to front, batch by batch, from the batch of the tile's last blended splat.
  uint first_batch = range.x + ((tile_last - 1 - range.x) / BATCH) * BATCH;
  for (int batch_start = int(first_batch); batch_start >= int(range.x); batch_start -= int(BATCH)) {
    stage(uint(batch_start), range.y, tile_origin);
    uint batch_count = min(BATCH, range.y - uint(batch_start));
    for (int j = int(batch_count) - 1; j >= 0; --j) {
      uint position = uint(batch_start + j);
      vec4 mab = s_mean_a_b[j];
      vec4 cod = s_c_opacity_depth[j];
      vec3 rgb = s_colour[j].rgb;
      float A = -2.0 * mab.z, B = -mab.w, C = -2.0 * cod.x;
      float opacity = cod.y, z = cod.z;
      float dx = mab.x - (float(local_x) + 0.5);
      float k0 = mab.z * dx * dx;
      float k1 = mab.w * dx;
      // The splat's gradients summed over the invocation's pixels.
      vec2 g_mean = vec2(0.0), g_mean_abs = vec2(0.0);
      vec3 g_conic = vec3(0.0), g_colour = vec3(0.0);
      float g_opacity = 0.0, g_z = 0.0;
      bool any_blended = false;
      [[unroll]] for (uint p = 0; p < P; ++p) {
        float dy = mab.y - (float(local_y0 + p) + 0.5);
        float power = k0 + dy * (k1 + cod.x * dy);
        float gaussian = exp(power);
        float alpha = min(MAX_ALPHA, opacity * gaussian);
        bool blended = position < last[p] && alpha >= ALPHA_MIN;
        any_blended = any_blended || blended;
        float inverse = 1.0 / (1.0 - alpha);  // one division: CPU drivers pay for each
        float T_before = T[p] * inverse;
        float w = blended ? alpha * T_before : 0.0;
        g_colour += g_rgba[p].rgb * w;
        g_z += g_depth[p] * w;
        float g_alpha = g_rgba[p].a * final_T[p] * inverse +
                        dot(g_rgba[p].rgb, T_before * rgb - behind_rgb[p] * inverse) +
                        g_depth[p] * (T_before * z - behind_depth[p] * inverse) +
                        g_weight[p] * (T_before - behind_weight[p] * inverse);
        behind_rgb[p] += rgb * w;
        behind_depth[p] += z * w;
        behind_weight[p] += w;
        T[p] = blended ? T_before : T[p];
        // alpha = min(MAX_ALPHA, opacity G): a capped alpha passes nothing further.
        float g_power = blended && opacity * gaussian <= MAX_ALPHA ? g_alpha * alpha : 0.0;
        g_opacity += blended && opacity * gaussian <= MAX_ALPHA ? g_alpha * gaussian : 0.0;
        // power = -A dx^2 / 2 - B dx dy - C dy^2 / 2.
        g_conic += vec3(-0.5 * dx * dx, -dx * dy, -0.5 * dy * dy) * g_power;
        vec2 pixel_mean = -vec2(A * dx + B * dy, C * dy + B * dx) * g_power;
        g_mean += pixel_mean;
        g_mean_abs += abs(pixel_mean);
      }
      // One add per subgroup and value: the subgroup's columns visit the same splat together.
      if (!subgroupAny(any_blended)) continue;
      g_mean = subgroupAdd(g_mean);
      g_mean_abs = subgroupAdd(g_mean_abs);
      g_conic = subgroupAdd(g_conic);
      g_opacity = subgroupAdd(g_opacity);
      g_colour = subgroupAdd(g_colour);
      g_z = subgroupAdd(g_z);
      if (subgroupElect()) {
        uint base = SPLAT_GRADIENT_FLOATS * floatBitsToUint(cod.w);
        add_gradient(base + 0, g_mean.x);
        add_gradient(base + 1, g_mean.y);
        add_gradient(base + 2, g_conic.x);
        add_gradient(base + 3, g_conic.y);
        add_gradient(base + 4, g_conic.z);
        add_gradient(base + 5, g_opacity);
        add_gradient(base + 6, g_colour.r);
        add_gradient(base + 7, g_colour.g);
        add_gradient(base + 8, g_colour.b);
        add_gradient(base + 9, g_z);
        add_gradient(base + 10, g_mean_abs.x);
        add_gradient(base + 11, g_mean_abs.y);
      }
    }
  }
}
