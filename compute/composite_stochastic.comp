#version 460
// Stochastic composite (Compositor::kStochastic): sort-free transparency. Each tile's list comes in
// no particular order (the frame bins the pairs by tile but never sorts by depth). For one sample,
// each pixel keeps every splat of its tile's list whose alpha reaches the cut-off with probability
// alpha, deciding with a threshold u(pixel, splat, sample, seed) < alpha (a hash, or with STRATIFIED
// a stratum per sample: see threshold()), and the kept splat
// nearest by (view depth, Gaussian index) -- the sorted order and its tie break -- gives the sample
// its colour; no kept splat gives the background. The chance that splat i wins is
// alpha_i * prod over the splats j before it of (1 - alpha_j): exactly its weight in the sorted
// front-to-back blend without the transmittance early-out, so the mean over samples converges to the
// sorted image (the early-out's T < 1e-4 leaves a difference below 1e-4 of a colour). The mean is over
// the display values the blend is defined on, not over linear light: it estimates the sorted frame, and
// a mean of decoded samples would converge to a brighter image (docs/colour.md, "Averages").
//
// One dispatch per sample: the host runs the samples back to back and this shader keeps the running
// sums per pixel in `state`; the last sample writes the means. Alpha is the fraction of samples that
// kept a splat, depth the mean of the winners' depths over those samples, and the count output is
// the number of splats each pixel tested (its tile's list length).
//
// The layout is composite.comp's: one workgroup per tile, splats staged through shared memory in
// batches of 256, PIXELS_PER_INVOCATION pixels of a column per invocation (16 on CPU drivers, 1 on
// GPUs), per-invocation lists of the splats that reach its column (composite_reach.glsl), and long
// lists split into chunks of `chunk_size` splats, one dispatch each, for llvmpipe's loop limit; the
// nearest kept splat so far is carried through `state` between chunks.
#extension GL_GOOGLE_include_directive : require
#define TS_STOCHASTIC_COMPOSITE_PUSH
#include "common.glsl"
#include "tile_coverage.glsl"
#include "composite_reach.glsl"

layout(local_size_x = 16, local_size_y_id = 3) in;  // local_size_y = 16 / PIXELS_PER_INVOCATION
layout(constant_id = 0) const bool WRITE_DEPTH = true;
layout(constant_id = 1) const bool WRITE_COUNT = true;
layout(constant_id = 2) const uint PIXELS_PER_INVOCATION = 1;  // 1, 2, 4, 8 or 16
layout(constant_id = 4) const float ALPHA_MIN = 1.0 / 255.0;   // the alpha cut-off (AccuracyModes)
layout(constant_id = 5) const float ALPHA_INV = 255.0;         // 1 / ALPHA_MIN, as the tile coverage uses it
layout(constant_id = 6) const float MAX_ALPHA = 0.99;          // RenderSettings::max_alpha
layout(constant_id = 7) const bool STRATIFIED = false;         // StochasticSampler::kStratified
layout(constant_id = 8) const bool KEEP_SUMS = false;          // StochasticSettings::accumulate
layout(constant_id = 9) const bool SOBOL = false;              // StochasticSampler::kSobol

// The push constants: StochasticCompositePush in shader_io.h.

#ifdef TS_TEXEL_BUFFERS
// The CPU-driver variant (composite_stochastic_texel): the splat records, the binned list and the
// outputs through texel buffers, as composite.comp's (vk::texel_buffers_wanted).
layout(set = 0, binding = 0) uniform textureBuffer splat_texels;
layout(set = 0, binding = 1) uniform utextureBuffer index_texels;
layout(set = 0, binding = 2, rgba32f) uniform writeonly imageBuffer rgba_texels;
layout(set = 0, binding = 3, r32f) uniform writeonly imageBuffer depth_texels;
layout(set = 0, binding = 4, r32ui) uniform writeonly uimageBuffer count_texels;
vec4 splat_vec4(uint g, uint k) { return texelFetch(splat_texels, int(SPLAT_VEC4S * g + k)); }
uint binned_index(uint i) { return texelFetch(index_texels, int(i)).x; }
void write_rgba(uint i, vec4 rgba) { imageStore(rgba_texels, int(i), rgba); }
void write_depth(uint i, float depth) { imageStore(depth_texels, int(i), vec4(depth)); }
void write_count(uint i, uint count) { imageStore(count_texels, int(i), uvec4(count)); }
#else
vec4 splat_vec4(uint g, uint k) { return pc.splats.v[SPLAT_VEC4S * g + k]; }
uint binned_index(uint i) { return pc.indices.v[i]; }
void write_rgba(uint i, vec4 rgba) { pc.out_rgba.v[i] = rgba; }
void write_depth(uint i, float depth) { pc.out_depth.v[i] = depth; }
void write_count(uint i, uint count) { pc.out_count.v[i] = count; }
#endif

const uint P = PIXELS_PER_INVOCATION;
const uint BATCH = 256;
const uint64_t NONE = 0xffffffffffffffffUL;  // no splat kept (above every (depth, index) key)

// A staged splat: its mean relative to the tile origin, A' = -A/2, B' = -B, C' = -C/2 of its conic
// (exact scalings, as composite.comp), opacity, and its order key: view depth bits << 32 | index
// (depths are > 0, so their bits order like the floats).
shared u64vec4 s_splat[BATCH];  // (mean x, mean y), (A', B'), (C', opacity), order key
shared uint s_hash[BATCH];      // hash of the Gaussian index, the splat's half of the threshold hash
shared uint s_reach[BATCH];     // composite_reach.glsl

uint64_t best[P];    // the nearest kept splat of each pixel: its order key, NONE if none
uint pixel_hash[P];  // each pixel's half of the threshold hash (pixel, sample, seed)
uint pixel_key[P];   // STRATIFIED, SOBOL: each pixel's half of the permutation key (pixel, seed)

// lowbias32 (Chris Wellons' hash prospector): a bijection on 32 bits with near-ideal avalanche.
uint hash32(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// STRATIFIED: the strata are the next power of two at or above pc.samples, M = stratum_mask + 1, set
// once per invocation (main), with the xor-shift of mix_bits and 1 / M.
uint stratum_mask = 1u;
uint stratum_shift = 1u;
float stratum_scale = 0.5;

// A bijection of [0, M) keyed by `key`: multiplications by odd constants and additions modulo M, and an
// xor-shift of the masked value, each invertible on those bits. Sample k takes stratum mix_bits(k, key):
// the pc.samples samples take distinct strata, all of them when pc.samples is a power of two. (A
// cycle-walk onto exactly pc.samples strata costs llvmpipe a data-dependent loop in the innermost test,
// twice the composite; distinct strata of at most twice as many keep most of the gain.)
uint mix_bits(uint x, uint key) {
  x = ((x ^ key) * 0x9e3779b1u + (key >> 16)) & stratum_mask;
  x ^= x >> stratum_shift;
  x = (x * 0x85ebca6bu + (key >> 8)) & stratum_mask;
  x ^= x >> stratum_shift;
  x = (x * 0xc2b2ae35u + (key >> 24)) & stratum_mask;
  x ^= x >> stratum_shift;
  return x;
}

// u in [0, 1) for splat (hash splat_hash) at pixel p of this sample. The hash: one value per (pixel,
// splat, sample, seed) on a 2^-24 grid. STRATIFIED: the stratum this sample takes of the pixel's and
// splat's permutation, plus a hashed jitter within it: (stratum + jitter) / M. Each sample's u is
// uniform on [0, 1) (the permutation's key is random per pixel and splat), so the mean stays unbiased.
// SOBOL: the effects' sequence in one dimension (engine/src/camera/effect_samples.cpp), padded across the
// splats as Burley's "Practical Hash-based Owen Scrambling" pads dimensions: the sample index shuffled by a
// nested scramble, its base-2 radical inverse taken, and that Owen-scrambled, both keyed per (pixel, splat,
// seed). Each scramble is Laine and Karras's permutation on bit-reversed values (each bit changes only the
// bits above it), so any 2^m consecutive samples still take the 2^m strata of [0, 1) once each, whatever
// the count (progressive: StochasticSettings::accumulate continues it), while the shuffle keeps two splats'
// thresholds from running in step from frame to frame.
uint laine_karras(uint x, uint seed) {
  x += seed;
  x ^= x * LAINE_KARRAS_MULTIPLIER_0;
  x ^= x * LAINE_KARRAS_MULTIPLIER_1;
  x ^= x * LAINE_KARRAS_MULTIPLIER_2;
  x ^= x * LAINE_KARRAS_MULTIPLIER_3;
  return x;
}
float threshold(uint p, uint splat_hash) {
  if (SOBOL) {
    uint key = hash32(pixel_key[p] ^ splat_hash);
    uint radical_inverse = laine_karras(bitfieldReverse(pc.sample_index), hash32(key ^ 0x68e31da4u));
    uint scrambled = bitfieldReverse(laine_karras(bitfieldReverse(radical_inverse), key));
    return float(scrambled >> 8) * (1.0 / 16777216.0);
  }
  uint h = hash32(pixel_hash[p] ^ splat_hash);
  float jitter = float(h >> 8) * (1.0 / 16777216.0);
  if (!STRATIFIED) return jitter;
  uint stratum = mix_bits(pc.sample_index, hash32(pixel_key[p] ^ splat_hash));
  return (float(stratum) + jitter) * stratum_scale;
}

// Tests staged splat j against the invocation's pixels first .. first + count - 1 (constants at the
// call sites, so the register arrays stay statically indexed). alpha is composite.comp's, bit for
// bit: the same staged values, the same arithmetic. Branch-free, like composite.comp's blend.
void test_splat(uint j, uint local_x, uint local_y0, uint first, uint count) {
  u64vec4 a = s_splat[j];
  vec4 mean_a_b = vec4(uintBitsToFloat(unpack32(a.x)), uintBitsToFloat(unpack32(a.y)));
  vec2 c_opacity = uintBitsToFloat(unpack32(a.z));
  uint splat_hash = s_hash[j];
  float dx = mean_a_b.x - (float(local_x) + 0.5);
  float k0 = mean_a_b.z * dx * dx;
  float k1 = mean_a_b.w * dx;
  for (uint p = first; p < first + count; ++p) {
    float dy = mean_a_b.y - (float(local_y0 + p) + 0.5);
    float power = k0 + dy * (k1 + c_opacity.x * dy);
    float alpha = min(MAX_ALPHA, c_opacity.y * exp(power));
    // u in [0, 1): kept with probability alpha (rounded up to u's grid).
    float u = threshold(p, splat_hash);
    bool keep = alpha >= ALPHA_MIN && u < alpha;
    best[p] = keep ? min(best[p], a.w) : best[p];
  }
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

  uvec2 range = pc.ranges.v[gl_WorkGroupID.y * pc.tiles_x + gl_WorkGroupID.x];
  uint list_length = range.y - range.x;
  bool resume = pc.chunk_start > 0;
  if (resume && list_length <= pc.chunk_start) return;  // an earlier chunk finished this tile's sample
  if (!resume && list_length > pc.chunk_size && thread == 0)
    atomicMax(pc.counters.v[COUNTER_MAX_TILE_PAIRS], list_length);
  uint list_begin = range.x + pc.chunk_start;
  uint list_end = list_length - pc.chunk_start <= pc.chunk_size ? range.y : list_begin + pc.chunk_size;
  bool finish_sample = list_end == range.y || pc.last_chunk != 0;

  Uint64Array carried = Uint64Array(uint64_t(pc.state));  // the order keys in the state (see above)
  uint sample_hash = hash32(hash32(pc.seed) ^ pc.sample_index);
  uint seed_key = hash32(pc.seed ^ 0x5bd1e995u);  // STRATIFIED: the permutations' seed
  if (STRATIFIED) {
    uint bits = uint(findMSB(max(pc.samples, 2u) - 1u)) + 1u;
    stratum_mask = (1u << bits) - 1u;  // samples <= 4096: bits <= 12
    stratum_shift = max(1u, (bits + 1u) / 2u);
    stratum_scale = 1.0 / float(stratum_mask + 1u);  // exact: a power of two
  }
  for (uint p = 0; p < P; ++p) {
    pixel_hash[p] = hash32(hash32(sample_hash ^ px) ^ (py0 + p));
    if (STRATIFIED || SOBOL) pixel_key[p] = hash32(hash32(seed_key ^ px) ^ (py0 + p));
    best[p] = NONE;
    if (resume && out_x < pc.width && out_y0 + p < pc.height)
      best[p] = carried.v[4 * ((out_y0 + p) * pc.width + out_x) + 3];
  }

  uint my_bits = my_reach_bits(local_x, local_y0, P);
  for (uint batch_start = list_begin; batch_start < list_end; batch_start += BATCH) {
    barrier();  // the previous batch is fully consumed
    uint batch_size = min(BATCH, list_end - batch_start);
    for (uint k = thread; k < batch_size; k += threads) {
      uint g = binned_index(batch_start + k);
      vec4 mdo = splat_vec4(g, 0);
      vec4 conic = splat_vec4(g, 1);
      float mean_y_lo = splat_vec4(g, 2).w;
      vec2 local_mean = vec2((mdo.x - tile_origin.x) + conic.w, (mdo.y - tile_origin.y) + mean_y_lo);
      s_splat[k] = u64vec4(pack64(floatBitsToUint(local_mean)),
                           pack64(floatBitsToUint(vec2(-0.5 * conic.x, -conic.y))),
                           pack64(floatBitsToUint(vec2(-0.5 * conic.z, mdo.w))),
                           pack64(uvec2(g, floatBitsToUint(mdo.z))));  // depth bits << 32 | index
      s_hash[k] = hash32(g);
      s_reach[k] = splat_reach(local_mean, mdo.w, splat_vec4(g, 3), ALPHA_INV);
    }
    barrier();
    if (P == 1) {
      for (uint j = 0; j < batch_size; ++j)
        if ((s_reach[j] & my_bits) != 0) test_splat(j, local_x, local_y0, 0, P);
    } else if (P < 16) {
      uint list[BATCH];  // see composite.comp: only a loop that never reaches a splat skips it
      uint n = 0;
      for (uint j = 0; j < batch_size; ++j) {
        list[n] = j;
        n += (s_reach[j] & my_bits) != 0 ? 1u : 0u;
      }
      for (uint k = 0; k < n; ++k) test_splat(list[k], local_x, local_y0, 0, P);
    } else {
      uint top[BATCH], bottom[BATCH];  // one list per row band of the column, as composite.comp
      uint n_top = 0, n_bottom = 0;
      for (uint j = 0; j < batch_size; ++j) {
        uint reach = s_reach[j] >> local_x;
        top[n_top] = j;
        bottom[n_bottom] = j;
        n_top += reach & 1u;
        n_bottom += (reach >> 16) & 1u;
      }
      for (uint k = 0; k < n_top; ++k) test_splat(top[k], local_x, local_y0, 0, 8);
      for (uint k = 0; k < n_bottom; ++k) test_splat(bottom[k], local_x, local_y0, 8, 8);
    }
  }

  bool first_sample = pc.sample_index == 0;
  bool last_sample = pc.sample_index + 1 >= pc.samples;
  for (uint p = 0; p < P; ++p) {
    uint out_y = out_y0 + p;
    if (out_x >= pc.width || out_y >= pc.height) continue;
    uint i = out_y * pc.width + out_x;
    if (!finish_sample) {  // a later chunk goes on with this sample
      carried.v[4 * i + 3] = best[p];
      continue;
    }
    vec4 sums = first_sample ? vec4(0.0) : pc.state.v[2 * i];
    float depth_sum = first_sample ? 0.0 : pc.state.v[2 * i + 1].x;
    if (best[p] != NONE) {
      uint g = uint(best[p]);
      sums += vec4(splat_vec4(g, 2).rgb, 1.0);
      depth_sum += uintBitsToFloat(uint(best[p] >> 32));
    }
    // The sums stay in the state for the next sample, and after the last for the next frame's when
    // it accumulates (its first sample is then pc.sample_index > 0 and reads them).
    if (!last_sample || KEEP_SUMS) {
      pc.state.v[2 * i] = sums;
      pc.state.v[2 * i + 1].x = depth_sum;
    }
    if (!last_sample) continue;
    float n = float(pc.samples);
    write_rgba(i, vec4((sums.rgb + (n - sums.w) * pc.background.rgb) / n, sums.w / n));
    if (WRITE_DEPTH) write_depth(i, sums.w > 0.0 ? depth_sum / sums.w : 0.0);
    if (WRITE_COUNT) write_count(i, list_length);
  }
}
