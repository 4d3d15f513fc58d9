#version 460
// Composite backward: one workgroup per 16x16 tile, one invocation per pixel (docs/gradients.md). Each
// pixel first walks its tile's list front to back as composite.comp blends it, to find where it stopped,
// its final transmittance and its depth sums; then it walks back from its last blended splat to the first,
// recovering each splat's transmittance by division (T_i = T_{i+1} / (1 - alpha_i), as the 3DGS trainer
// and gsplat do) and forming the splat's screen-space gradient. The tile's splats are staged through
// shared memory in batches; every invocation of a subgroup visits the same splat at once, so a
// subgroup sums its pixels' gradients before one invocation adds them to the splat's (a float atomic
// add, or a compare-and-swap loop where the device has none: TS_CAS_FLOAT_ADD).
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_vote : require
#ifndef TS_CAS_FLOAT_ADD
#extension GL_EXT_shader_atomic_float : require
#endif
#define TS_COMPOSITE_BACKWARD_PUSH
#include "common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;
// The forward's cut-offs, as composite.comp's (the reference's: the backward covers no other mode).
layout(constant_id = 0) const float ALPHA_MIN = 1.0 / 255.0;
layout(constant_id = 1) const float T_MIN = 1e-4;
layout(constant_id = 2) const float MAX_ALPHA = 0.99;

const uint BATCH = 256;
shared vec4 s_mean_a_b[BATCH];       // mean relative to the tile origin, A' = -A/2, B' = -B
shared vec4 s_c_opacity_depth[BATCH];  // C' = -C/2, opacity, view depth, record index (as float bits)
shared vec4 s_colour[BATCH];
shared uint s_done;
shared uint s_last;  // the furthest list position any pixel of the tile blended

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
  uint k = gl_LocalInvocationIndex;
  barrier();
  uint done_before = s_done;
  if (batch_start + k < list_end) {
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

// The staged splat's alpha at the pixel, in composite.comp's operations; dx, dy and G = exp(power) out.
float alpha_at(uint j, vec2 pixel, out float dx, out float dy, out float gaussian) {
  vec4 mab = s_mean_a_b[j];
  vec4 cod = s_c_opacity_depth[j];
  dx = mab.x - pixel.x;
  dy = mab.y - pixel.y;
  float k0 = mab.z * dx * dx;
  float k1 = mab.w * dx;
  float power = k0 + dy * (k1 + cod.x * dy);
  gaussian = exp(power);
  return min(MAX_ALPHA, cod.y * gaussian);
}

void main() {
  uvec2 tile = gl_WorkGroupID.xy;
  uvec2 local = gl_LocalInvocationID.xy;
  vec2 tile_origin = vec2(tile * TILE_SIZE);
  vec2 pixel = vec2(local) + 0.5;  // relative to the tile origin, as the staged means are
  uvec2 image_pixel = tile * TILE_SIZE + local;
  bool inside = image_pixel.x < pc.width && image_pixel.y < pc.height;
  uint pixel_index = image_pixel.y * pc.width + image_pixel.x;
  uvec2 range = pc.ranges.v[tile.y * pc.tiles_x + tile.x];

  // Front to back: where the pixel stops, as the forward blended it.
  float T = 1.0;
  float depth_sum = 0.0, weight_sum = 0.0;
  bool done = !inside;
  uint last = 0;  // one past the list position of the last splat blended (0: none)
  if (gl_LocalInvocationIndex == 0) {
    s_done = 0;
    s_last = 0;
  }
  barrier();
  if (done) atomicAdd(s_done, 1u);
  for (uint batch_start = range.x; batch_start < range.y; batch_start += BATCH) {
    if (stage(batch_start, range.y, tile_origin) == BATCH) break;
    uint batch_count = min(BATCH, range.y - batch_start);
    for (uint j = 0; j < batch_count && !done; ++j) {
      float dx, dy, gaussian;
      float alpha = alpha_at(j, pixel, dx, dy, gaussian);
      if (alpha < ALPHA_MIN) continue;
      float next_T = T * (1.0 - alpha);
      if (next_T < T_MIN) {
        done = true;
        atomicAdd(s_done, 1u);
        break;
      }
      float w = alpha * T;
      depth_sum += s_c_opacity_depth[j].z * w;
      weight_sum += w;
      T = next_T;
      last = batch_start + j + 1;
    }
  }
  if (last > 0) atomicMax(s_last, last);

  vec4 g_rgba = inside ? pc.pixel_rgba_gradients.v[pixel_index] : vec4(0.0);
  vec2 g_depths = inside ? uintBitsToFloat(pc.pixel_depth_gradients.v[pixel_index]) : vec2(0.0);
  // The expected depth E = D / W passes its gradient to D = sum w z and W = sum w.
  float g_depth = g_depths.y + (weight_sum > 0.0 ? g_depths.x / weight_sum : 0.0);
  float g_weight = weight_sum > 0.0 ? -g_depths.x * depth_sum / (weight_sum * weight_sum) : 0.0;
  vec3 behind_rgb = pc.background.rgb * T;
  float behind_depth = 0.0, behind_weight = 0.0;
  float final_T = T;

  // Back to front, batch by batch, from the batch of the tile's last blended splat.
  barrier();
  uint tile_last = s_last;
  if (tile_last == 0) return;
  uint first_batch = range.x + ((tile_last - 1 - range.x) / BATCH) * BATCH;
  for (int batch_start = int(first_batch); batch_start >= int(range.x); batch_start -= int(BATCH)) {
    stage(uint(batch_start), range.y, tile_origin);
    uint batch_count = min(BATCH, range.y - uint(batch_start));
    for (int j = int(batch_count) - 1; j >= 0; --j) {
      uint position = uint(batch_start + j);
      float dx, dy, gaussian;
      float alpha = alpha_at(uint(j), pixel, dx, dy, gaussian);
      bool blended = position < last && alpha >= ALPHA_MIN;
      // Every gradient of this splat at this pixel: zero where it was not blended here.
      vec2 g_mean = vec2(0.0);
      vec3 g_conic = vec3(0.0);
      float g_opacity = 0.0, g_depth_out = 0.0;
      vec3 g_colour = vec3(0.0);
      if (blended) {
        float one_minus = 1.0 - alpha;
        float T_before = T / one_minus;
        float w = alpha * T_before;
        vec3 rgb = s_colour[j].rgb;
        float z = s_c_opacity_depth[j].z;
        g_colour = g_rgba.rgb * w;
        g_depth_out = g_depth * w;
        float g_alpha = g_rgba.a * final_T / one_minus + dot(g_rgba.rgb, T_before * rgb - behind_rgb / one_minus) +
                        g_depth * (T_before * z - behind_depth / one_minus) +
                        g_weight * (T_before - behind_weight / one_minus);
        behind_rgb += rgb * w;
        behind_depth += z * w;
        behind_weight += w;
        T = T_before;
        // alpha = min(MAX_ALPHA, opacity G): a capped alpha passes nothing further.
        float opacity = s_c_opacity_depth[j].y;
        if (opacity * gaussian <= MAX_ALPHA) {
          g_opacity = g_alpha * gaussian;
          float g_power = g_alpha * alpha;
          // power = -A dx^2 / 2 - B dx dy - C dy^2 / 2 with A = -2 A', B = -B', C = -2 C'.
          g_conic = vec3(-0.5 * dx * dx, -dx * dy, -0.5 * dy * dy) * g_power;
          float A = -2.0 * s_mean_a_b[j].z, B = -s_mean_a_b[j].w, C = -2.0 * s_c_opacity_depth[j].x;
          g_mean = -vec2(A * dx + B * dy, C * dy + B * dx) * g_power;
        }
      }
      // The subgroup's pixels visit the same splat together: one add per subgroup and value.
      if (!subgroupAny(blended)) continue;
      vec2 s_mean = subgroupAdd(g_mean);
      vec2 s_abs = subgroupAdd(abs(g_mean));
      vec3 s_conic = subgroupAdd(g_conic);
      float s_opacity = subgroupAdd(g_opacity);
      vec3 s_rgb = subgroupAdd(g_colour);
      float s_depth = subgroupAdd(g_depth_out);
      if (subgroupElect()) {
        uint base = SPLAT_GRADIENT_FLOATS * floatBitsToUint(s_c_opacity_depth[j].w);
        add_gradient(base + 0, s_mean.x);
        add_gradient(base + 1, s_mean.y);
        add_gradient(base + 2, s_conic.x);
        add_gradient(base + 3, s_conic.y);
        add_gradient(base + 4, s_conic.z);
        add_gradient(base + 5, s_opacity);
        add_gradient(base + 6, s_rgb.r);
        add_gradient(base + 7, s_rgb.g);
        add_gradient(base + 8, s_rgb.b);
        add_gradient(base + 9, s_depth);
        add_gradient(base + 10, s_abs.x);
        add_gradient(base + 11, s_abs.y);
      }
    }
  }
}
