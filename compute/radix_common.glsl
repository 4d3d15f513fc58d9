// Shared by the radix sort kernels. The keys are split into blocks (of block_keys(), set by the setup
// from the count: fewer, larger blocks for large counts, because a CPU driver pays for every
// workgroup; more, smaller ones for small counts, to keep every core busy); each block is owned by
// ONE subgroup from start to end, so the histogram and scatter need no workgroup-wide synchronisation
// and stay stable (a subgroup walks its block in order). Works for subgroup sizes 4 to 128.
layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint SUBGROUPS_PER_WORKGROUP = 8;
layout(constant_id = 3) const bool WIDE_KEYS = true;

const uint RADIX = 256;

#include "sort_keys.glsl"

const uint RADIX_BLOCK_KEYS = SORT_OWN;  // written by radix_setup.comp
uint block_keys() { return pc.state.v[RADIX_BLOCK_KEYS]; }

uint digit_of(uint64_t key) { return uint(key >> pc.shift) & (RADIX - 1); }

#ifdef TS_TEXEL_BUFFERS
#include "sort_key_texels.glsl"
uint64_t radix_load_key(uint i) { return texel_load_key(i); }
uint radix_load_value(uint i) { return texel_load_value(i); }
void radix_store(uint i, uint64_t key, uint value) { texel_store_pair(i, key, value); }
#else
uint64_t radix_load_key(uint i) { return load_key(pc.keys_in, i); }
uint radix_load_value(uint i) { return pc.values_in.v[i]; }
void radix_store(uint i, uint64_t key, uint value) {
  store_key(pc.keys_out, i, key);
  pc.values_out.v[i] = value;
}
#endif
