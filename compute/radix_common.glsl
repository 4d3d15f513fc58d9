// Shared by the radix sort kernels. The keys are split into blocks (of block_keys(), set by the setup
// from the count: fewer, larger blocks for large counts, because a CPU driver pays for every
// workgroup; more, smaller ones for small counts, to keep every core busy); each block is owned by
// ONE subgroup from start to end, so the histogram and scatter need no workgroup-wide synchronisation
// and stay stable (a subgroup walks its block in order). Works for subgroup sizes 4 to 128.
layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint SUBGROUPS_PER_WORKGROUP = 8;
layout(constant_id = 3) const bool WIDE_KEYS = true;

const uint RADIX = 256;

layout(push_constant) uniform Push {
  uint64_t keys_in;  // see sort_keys.glsl
  UintArray values_in;
  uint64_t keys_out;
  UintArray values_out;
  UintArray histogram;     // RADIX * blocks, digit-major: histogram[digit * blocks + block]
  UintArray digit_totals;  // RADIX
  UintArray state;         // the sort's state block (SORT_COUNT, SORT_BLOCKS)
  uint shift;              // which 8-bit digit this pass sorts on
} pc;

#include "sort_keys.glsl"

const uint RADIX_BLOCK_KEYS = SORT_OWN;  // written by radix_setup.comp
uint block_keys() { return pc.state.v[RADIX_BLOCK_KEYS]; }

uint digit_of(uint64_t key) { return uint(key >> pc.shift) & (RADIX - 1); }

#ifdef TS_TEXEL_BUFFERS
// The CPU-driver variants (radix_histogram_texel, radix_scatter_texel): keys and values through texel
// buffers, which llvmpipe reads and writes with SIMD gathers and scatters, where a load or store at
// a per-invocation address is a loop over the SIMD lanes (vk::texel_buffers_wanted). Narrow keys are
// R32_UINT texels, wide ones R32G32_UINT (low word first, as in memory); the same buffers as the
// push constants' addresses.
layout(set = 0, binding = 0) uniform usamplerBuffer keys_in_texels;
layout(set = 0, binding = 1) uniform usamplerBuffer values_in_texels;
layout(set = 0, binding = 2, r32ui) uniform writeonly uimageBuffer narrow_keys_out_texels;
layout(set = 0, binding = 3, rg32ui) uniform writeonly uimageBuffer wide_keys_out_texels;
layout(set = 0, binding = 4, r32ui) uniform writeonly uimageBuffer values_out_texels;
uint64_t radix_load_key(uint i) {
  uvec2 words = texelFetch(keys_in_texels, int(i)).xy;
  return WIDE_KEYS ? pack64(words) : uint64_t(words.x);
}
uint radix_load_value(uint i) { return texelFetch(values_in_texels, int(i)).x; }
void radix_store(uint i, uint64_t key, uint value) {
  if (WIDE_KEYS)
    imageStore(wide_keys_out_texels, int(i), uvec4(unpack32(key), 0u, 0u));
  else
    imageStore(narrow_keys_out_texels, int(i), uvec4(uint(key)));
  imageStore(values_out_texels, int(i), uvec4(value));
}
#else
uint64_t radix_load_key(uint i) { return load_key(pc.keys_in, i); }
uint radix_load_value(uint i) { return pc.values_in.v[i]; }
void radix_store(uint i, uint64_t key, uint value) {
  store_key(pc.keys_out, i, key);
  pc.values_out.v[i] = value;
}
#endif
