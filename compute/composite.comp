#version 460
// Composite: one workgroup per 16x16 tile. The tile's depth-sorted splats are staged through shared
// memory in batches of 256; each pixel blends them front to back, stops at T < 1e-4 (the reference's
// cut-off; a mode), and the whole tile stops once every pixel has.
//
// Each invocation owns a column of PIXELS_PER_INVOCATION pixels. GPUs use 1 (256 invocations, one
// per pixel). CPU drivers such as lavapipe use 16: there a shared-memory read costs a scalar load per
// SIMD lane, so reading each splat once and blending it into 16 pixels held in registers is 5-10x
// faster, and the workgroup has 2 SIMD groups instead of 32 to switch between at each barrier. Their
// variant composite_texel (TS_TEXEL_BUFFERS) also reads the records and writes the outputs through
// texel buffers and stages only the splats' indices (see there).
//
// Each staged splat also carries its reach: the columns its alpha >= 1/255 ellipse meets in rows
// 0-7 and in rows 8-15. Pixels outside would be no-ops (the reference skips them too). GPUs simply
// branch on it. CPU drivers execute both sides of every branch under a lane mask and only leave a
// loop for real, so there each invocation first lists the splats that reach its column and then
// loops over just those.
//
// A tile's list is blended in chunks of at most `chunk_size` splats, one dispatch per chunk, with the
// pixels' state carried through a buffer between them. llvmpipe silently cuts a shader short after
// 65535 loop iterations, which a tile of ~60k faint splats reaches: there the host sets a chunk size
// that stays within the limit (GPUs use one chunk). Chunk 0 records the longest list that did not
// fit, and the host re-renders the frame with enough chunks.
//
// A scene rendered in depth-ordered parts (Renderer::render with a memory budget) composites each part's
// lists in turn: COMPOSITE_CARRY_IN starts each pixel from the state the previous part left, and
// COMPOSITE_CARRY_OUT leaves the state for the next part instead of writing the outputs. The state
// buffer then has two halves, read from one and written to the other (COMPOSITE_STATE_HIGH says which
// is written), so that a part whose composite re-runs (more chunks) starts again from intact state.
//
// A host's depth (HOST_DEPTH): a splat blends into a pixel only in front of the surface the host drew
// there (its view depth in host_z, +inf where none), which is opaque. SURFACE_DEPTH writes the view
// depth of the splat at which a pixel's alpha first reaches surface_alpha (0 where it never does),
// which the host turns into its own depth convention. Both off, the pipeline is the one without them.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#define TS_COMPOSITE_PUSH
#include "common.glsl"
#include "tile_coverage.glsl"
#include "composite_reach.glsl"

layout(local_size_x = 16, local_size_y_id = 3) in;  // local_size_y = 16 / PIXELS_PER_INVOCATION
layout(constant_id = 0) const bool WRITE_DEPTH = true;
layout(constant_id = 1) const bool WRITE_COUNT = true;
layout(constant_id = 2) const uint PIXELS_PER_INVOCATION = 1;  // 1, 2, 4, 8 or 16
// The cut-offs (AccuracyModes); the defaults are the reference's.
layout(constant_id = 4) const float ALPHA_MIN = 1.0 / 255.0;
layout(constant_id = 5) const float ALPHA_INV = 255.0;  // 1 / ALPHA_MIN, as the tile coverage uses it
layout(constant_id = 6) const float T_MIN = 1e-4;
layout(constant_id = 7) const bool HOST_DEPTH = false;
layout(constant_id = 8) const bool SURFACE_DEPTH = false;
// The lists are in exact depth order (32-bit depth keys): a pixel is done at the first splat behind its
// host surface, as every later one is behind it too. Same image, less work behind the host's walls.
layout(constant_id = 9) const bool HOST_DEPTH_SORTED = false;
// The tiles' lists are blended in more than one dispatch (see above). Off, the state loads and stores
// compile away: CPU drivers run both sides of a branch, so even skipped they cost loops over the lanes.
layout(constant_id = 10) const bool CHUNKED = true;
// The cap on one splat's alpha (RenderSettings::max_alpha): 0.99 as the 3DGS trainer renders.
layout(constant_id = 11) const float MAX_ALPHA = 0.99;

// The push constants: CompositePush in shader_io.h.

#ifdef TS_TEXEL_BUFFERS
// The CPU-driver variant (composite_texel): the splat records, the sorted list and the outputs go
// through texel buffers, which llvmpipe reads and writes with SIMD gathers and scatters, where a load
// or store at a per-invocation address is a loop over the SIMD lanes per component (vk::
// texel_buffers_wanted). The same buffers as the push constants' addresses; nothing else differs.
layout(set = 0, binding = 0) uniform textureBuffer splat_texels;
layout(set = 0, binding = 1) uniform utextureBuffer sorted_index_texels;
layout(set = 0, binding = 2, rgba32f) uniform writeonly imageBuffer rgba_texels;
layout(set = 0, binding = 3, r32f) uniform writeonly imageBuffer depth_texels;
layout(set = 0, binding = 4, r32ui) uniform writeonly uimageBuffer count_texels;
vec4 splat_vec4(uint g, uint k) { return texelFetch(splat_texels, int(SPLAT_VEC4S * g + k)); }
uint sorted_index(uint i) { return texelFetch(sorted_index_texels, int(i)).x; }
void write_rgba(uint i, vec4 rgba) { imageStore(rgba_texels, int(i), rgba); }
void write_depth(uint i, float depth) { imageStore(depth_texels, int(i), vec4(depth)); }
void write_count(uint i, uint count) { imageStore(count_texels, int(i), uvec4(count)); }
#else
vec4 splat_vec4(uint g, uint k) { return pc.splats.v[SPLAT_VEC4S * g + k]; }
uint sorted_index(uint i) { return pc.sorted_indices.v[i]; }
void write_rgba(uint i, vec4 rgba) { pc.out_rgba.v[i] = rgba; }
void write_depth(uint i, float depth) { pc.out_depth.v[i] = depth; }
void write_count(uint i, uint count) { pc.out_count.v[i] = count; }
#endif

const uint P = PIXELS_PER_INVOCATION;
const uint BATCH = 256;
const uint TILE_PIXELS = TILE_SIZE * TILE_SIZE;

// A splat ready to evaluate: its mean relative to the tile origin, A' = -A/2, B' = -B, C' = -C/2 of
// its conic (exact scalings, so power = A' dx^2 + B' dx dy + C' dy^2), opacity, view depth and colour.
void splat_params(vec4 mdo, vec4 conic, vec4 colour_lo, vec2 tile_origin, out vec4 mean_a_b,
                  out vec4 c_opacity_depth_r, out vec3 rgb) {
  vec2 local_mean = vec2((mdo.x - tile_origin.x) + conic.w, (mdo.y - tile_origin.y) + colour_lo.w);
  mean_a_b = vec4(local_mean, -0.5 * conic.x, -conic.y);
  c_opacity_depth_r = vec4(-0.5 * conic.z, mdo.w, mdo.z, colour_lo.r);
  rgb = colour_lo.rgb;
}

#ifdef TS_TEXEL_BUFFERS
// The lists hold the splats' indices, staged four to an element (read eight per pair of loads), and
// a blend reads the splat's record through the texel buffer: a SIMD gather, where a shared-memory
// read at a per-invocation index is a loop over the SIMD lanes.
shared uvec4 s_index[BATCH / 4];
void stage_splat(uint k, uint g, vec4 mdo, vec4 conic, vec4 colour_lo, vec2 tile_origin) { s_index[k / 4][k % 4] = g; }
uvec4 staged_entries(uint j4) { return s_index[j4]; }  // the list entries of staged splats 4 j4 .. 4 j4 + 3
void entry_params(uint g, vec2 tile_origin, out vec4 mean_a_b, out vec4 c_opacity_depth_r, out vec3 rgb) {
  splat_params(splat_vec4(g, 0), splat_vec4(g, 1), splat_vec4(g, 2), tile_origin, mean_a_b, c_opacity_depth_r, rgb);
}
#else
// The lists hold positions in the batch; the staged splats are packed in two 64-bit reads, where
// CPU drivers pay per read.
shared u64vec4 s_packed_a[BATCH];  // (mean x, mean y), (A', B'), (C', opacity), (depth, red)
shared uint64_t s_packed_b[BATCH];  // (green, blue)
void stage_splat(uint k, uint g, vec4 mdo, vec4 conic, vec4 colour_lo, vec2 tile_origin) {
  vec4 mean_a_b, c_opacity_depth_r;
  vec3 rgb;
  splat_params(mdo, conic, colour_lo, tile_origin, mean_a_b, c_opacity_depth_r, rgb);
  s_packed_a[k] = u64vec4(pack64(floatBitsToUint(mean_a_b.xy)), pack64(floatBitsToUint(mean_a_b.zw)),
                          pack64(floatBitsToUint(c_opacity_depth_r.xy)), pack64(floatBitsToUint(c_opacity_depth_r.zw)));
  s_packed_b[k] = pack64(floatBitsToUint(rgb.gb));
}
uvec4 staged_entries(uint j4) { return uvec4(4 * j4) + uvec4(0, 1, 2, 3); }
void entry_params(uint j, vec2 tile_origin, out vec4 mean_a_b, out vec4 c_opacity_depth_r, out vec3 rgb) {
  u64vec4 a = s_packed_a[j];
  uint64_t b = s_packed_b[j];
  mean_a_b = vec4(uintBitsToFloat(unpack32(a.x)), uintBitsToFloat(unpack32(a.y)));
  c_opacity_depth_r = vec4(uintBitsToFloat(unpack32(a.z)), uintBitsToFloat(unpack32(a.w)));
  rgb = vec3(c_opacity_depth_r.w, uintBitsToFloat(unpack32(b)));
}
#endif
uint staged_entry(uint j) { return staged_entries(j / 4)[j % 4]; }
// Bit 16 h + x of splat j's reach, s_reach[j / 4][j % 4]: the splat reaches column x in rows
// [8 h, 8 h + 7] (composite_reach.glsl). Four to an element, so that the CPU layout reads eight per
// pair of loads.
shared uvec4 s_reach[BATCH / 4];
shared uint s_done_pixels;

// The invocation's pixels, front to back state. A pixel that is done keeps its final transmittance
// negated, so `T > 0` is the "still blending" test without another register per pixel.
float T[P];
vec3 colour[P];
float depth_sum[P];
float weight_sum[P];
uint blended[P];
float host_z[P];   // HOST_DEPTH
float surface[P];  // SURFACE_DEPTH: 0 until the pixel's alpha reaches surface_alpha
uint my_done = 0;  // pixels of this invocation that are done

// Blends the staged splat of list entry `entry` (staged_entry) into the invocation's pixels first ..
// first + count - 1 (indices into its column; the call sites pass constants, so the register arrays
// stay statically indexed) and returns how many of them finished. Branch-free: a no-op (w = 0, T
// unchanged) leaves every sum bit-identical, and selects are cheaper than the lane-mask bookkeeping a
// CPU driver does for a divergent branch.
uint blend_splat(uint entry, vec2 tile_origin, uint local_x, uint local_y0, uint first, uint count) {
  vec4 mean_a_b, c_opacity_depth_r;
  vec3 rgb;
  entry_params(entry, tile_origin, mean_a_b, c_opacity_depth_r, rgb);
  float dx = mean_a_b.x - (float(local_x) + 0.5);
  // power = k0 + dy (k1 + C' dy): the dx terms are the same for the whole column.
  float k0 = mean_a_b.z * dx * dx;
  float k1 = mean_a_b.w * dx;
  uint finished = 0;
  for (uint p = first; p < first + count; ++p) {
    float dy = mean_a_b.y - (float(local_y0 + p) + 0.5);
    float power = k0 + dy * (k1 + c_opacity_depth_r.x * dy);
    float alpha = min(MAX_ALPHA, c_opacity_depth_r.y * exp(power));
    bool behind = HOST_DEPTH && !(c_opacity_depth_r.z < host_z[p]);
    bool hit = T[p] > 0.0 && alpha >= ALPHA_MIN && !behind;
    float next_T = T[p] * (1.0 - alpha);
    bool finish = (hit && next_T < T_MIN)  // done, and this splat is NOT blended (reference)
                  || (HOST_DEPTH_SORTED && T[p] > 0.0 && behind);
    bool blend = hit && !finish;
    float w = blend ? alpha * T[p] : 0.0;
    colour[p] += rgb * w;
    depth_sum[p] += c_opacity_depth_r.z * w;
    weight_sum[p] += w;
    if (SURFACE_DEPTH)
      surface[p] = blend && surface[p] == 0.0 && 1.0 - next_T >= pc.surface_alpha ? c_opacity_depth_r.z : surface[p];
    T[p] = blend ? next_T : (finish ? -T[p] : T[p]);
    blended[p] += blend ? 1u : 0u;
    finished += finish ? 1u : 0u;
  }
  return finished;
}

void main() {
  uvec2 tile = first_tile_of(pc.first_tile) + gl_WorkGroupID.xy;  // in the camera's grid
  uint thread = gl_LocalInvocationIndex;
  uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  uint local_x = gl_LocalInvocationID.x;
  uint local_y0 = gl_LocalInvocationID.y * P;  // first row of this invocation in the tile
  vec2 tile_origin = vec2(tile * TILE_SIZE);
  // The outputs' pixel (out_x, out_y0 + p), counted from their first tile's corner: the whole image's,
  // or a region's. Splats are evaluated at the camera's pixel (tile_origin + local), as in the whole frame.
  uint out_x = gl_WorkGroupID.x * TILE_SIZE + local_x;
  uint out_y0 = gl_WorkGroupID.y * TILE_SIZE + local_y0;

  uvec2 range = pc.ranges.v[gl_WorkGroupID.y * pc.tiles_x + gl_WorkGroupID.x];
  uint list_length = range.y - range.x;
  if (CHUNKED && pc.chunk_start > 0 && list_length <= pc.chunk_start) return;  // an earlier chunk finished this tile
  if (pc.chunk_start == 0 && list_length > pc.chunk_size && thread == 0)
    atomicMax(pc.counters.v[COUNTER_MAX_TILE_PAIRS], list_length);
  uint list_begin = range.x + pc.chunk_start;
  uint list_end = list_length - pc.chunk_start <= pc.chunk_size ? range.y : list_begin + pc.chunk_size;
  // The state this dispatch reads: the previous chunk's, or at chunk 0 the previous part's (the other
  // half of the buffer); it writes its own half. Without parts, one half (COMPOSITE_STATE_HIGH off).
  uint half_vec4s = 2 * pc.width * pc.height;
  uint state_out = (pc.flags & COMPOSITE_STATE_HIGH) != 0 ? half_vec4s : 0u;
  bool carry_in = CHUNKED && (pc.flags & COMPOSITE_CARRY_IN) != 0;
  bool resume = CHUNKED && (pc.chunk_start > 0 || carry_in);
  uint state_in = pc.chunk_start > 0 ? state_out : half_vec4s - state_out;
  bool tile_done = list_end == range.y || (pc.flags & COMPOSITE_LAST_CHUNK) != 0;
  bool write_outputs = !CHUNKED || ((pc.flags & COMPOSITE_CARRY_OUT) == 0 && tile_done);

  for (uint p = 0; p < P; ++p) {
    bool outside = out_x >= pc.width || out_y0 + p >= pc.height;
    T[p] = outside ? -1.0 : 1.0;
    colour[p] = vec3(0.0);
    depth_sum[p] = 0.0;
    weight_sum[p] = 0.0;
    blended[p] = 0;
    surface[p] = 0.0;
    if (HOST_DEPTH) host_z[p] = outside ? 0.0 : pc.host_z.v[(out_y0 + p) * pc.width + out_x];
    if (resume && !outside) {
      uint i = (out_y0 + p) * pc.width + out_x;
      vec4 colour_T = pc.state.v[state_in + 2 * i];
      vec4 sums = pc.state.v[state_in + 2 * i + 1];
      colour[p] = colour_T.rgb;
      T[p] = colour_T.a;
      depth_sum[p] = sums.x;
      weight_sum[p] = sums.y;
      blended[p] = floatBitsToUint(sums.z);
      surface[p] = sums.w;
    }
    my_done += T[p] < 0.0 ? 1u : 0u;
  }

  if (thread == 0) s_done_pixels = 0;
  barrier();
  if (my_done > 0) atomicAdd(s_done_pixels, my_done);
  uint published_done = my_done;  // pixels finishing in a batch are added to s_done_pixels after it
  uint my_bits = my_reach_bits(local_x, local_y0, P);
  uint top_done = 0, bottom_done = 0;  // P == 16: done pixels among rows 0-7 and rows 8-15
  for (uint p = 0; p < P; ++p) {
    if (p < 8) top_done += T[p] < 0.0 ? 1u : 0u;
    else bottom_done += T[p] < 0.0 ? 1u : 0u;
  }

  for (uint batch_start = list_begin; batch_start < list_end; batch_start += BATCH) {
    barrier();  // previous batch fully consumed; s_done_pixels up to date
    if (s_done_pixels == TILE_PIXELS) break;
    uint batch_size = min(BATCH, list_end - batch_start);
    for (uint k = thread; k < batch_size; k += threads) {
      uint g = sorted_index(batch_start + k);
      vec4 mdo = splat_vec4(g, 0);
      vec4 conic = splat_vec4(g, 1);
      vec4 colour_lo = splat_vec4(g, 2);
      stage_splat(k, g, mdo, conic, colour_lo, tile_origin);
      vec2 local_mean = vec2((mdo.x - tile_origin.x) + conic.w, (mdo.y - tile_origin.y) + colour_lo.w);
      s_reach[k / 4][k % 4] = splat_reach(local_mean, mdo.w, splat_vec4(g, 3), ALPHA_INV);
    }
    barrier();
    if (P == 1) {
      for (uint j = 0; my_done < P && j < batch_size; ++j) {
        if ((s_reach[j / 4][j % 4] & my_bits) != 0)
          my_done += blend_splat(staged_entry(j), tile_origin, local_x, local_y0, 0, P);
      }
    } else if (P < 16) {
      // CPU drivers run both sides of every branch, so skipping a splat is only real when the
      // loop never gets to it: each invocation first lists the splats whose reach includes its
      // pixels, then blends just those.
      uint list[BATCH];
      uint n = 0;
      for (uint j = 0; j < batch_size; ++j) {
        list[n] = staged_entry(j);
        n += (s_reach[j / 4][j % 4] & my_bits) != 0 ? 1u : 0u;
      }
      for (uint k = 0; my_done < P && k < n; ++k) my_done += blend_splat(list[k], tile_origin, local_x, local_y0, 0, P);
    } else {
      // A column of 16 spans both row bands of the reach mask: one list per band, so that a splat
      // reaching only rows 0-7 (or 8-15) of this column is evaluated on those 8 pixels alone.
      uint top[BATCH], bottom[BATCH];
      uint n_top = 0, n_bottom = 0;
      // Eight reaches per step: on CPU drivers each shared-memory read is a loop over the SIMD lanes.
      // Entries past batch_size are stale but never counted.
      for (uint j0 = 0; j0 < batch_size; j0 += 8) {
        uvec4 reach_lo = s_reach[j0 / 4], reach_hi = s_reach[j0 / 4 + 1];
        uvec4 entry_lo = staged_entries(j0 / 4), entry_hi = staged_entries(j0 / 4 + 1);
        [[unroll]] for (uint i = 0; i < 8; ++i) {
          uint reach = (i < 4 ? reach_lo[i] : reach_hi[i - 4]) >> local_x;
          uint entry = i < 4 ? entry_lo[i] : entry_hi[i - 4];
          reach = j0 + i < batch_size ? reach : 0u;
          top[n_top] = entry;
          bottom[n_bottom] = entry;
          n_top += reach & 1u;
          n_bottom += (reach >> 16) & 1u;
        }
      }
      for (uint k = 0; top_done < 8 && k < n_top; ++k)
        top_done += blend_splat(top[k], tile_origin, local_x, local_y0, 0, 8);
      for (uint k = 0; bottom_done < 8 && k < n_bottom; ++k)
        bottom_done += blend_splat(bottom[k], tile_origin, local_x, local_y0, 8, 8);
      my_done = top_done + bottom_done;
    }
    if (my_done > published_done) atomicAdd(s_done_pixels, my_done - published_done);
    published_done = my_done;
  }

  for (uint p = 0; p < P; ++p) {
    uint out_y = out_y0 + p;
    if (out_x >= pc.width || out_y >= pc.height) continue;
    uint i = out_y * pc.width + out_x;
    if (!write_outputs) {
      pc.state.v[state_out + 2 * i] = vec4(colour[p], T[p]);
      pc.state.v[state_out + 2 * i + 1] = vec4(depth_sum[p], weight_sum[p], uintBitsToFloat(blended[p]), surface[p]);
      continue;
    }
    float transmittance = abs(T[p]);
    write_rgba(i, vec4(colour[p] + transmittance * pc.background.rgb, 1.0 - transmittance));
    if (WRITE_DEPTH) write_depth(i, weight_sum[p] > 0.0 ? depth_sum[p] / weight_sum[p] : 0.0);
    if (WRITE_COUNT) write_count(i, blended[p]);
    if (SURFACE_DEPTH) pc.surface_z.v[i] = surface[p];
  }
}
