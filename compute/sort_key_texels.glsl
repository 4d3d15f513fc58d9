// Keys and values through texel buffers: the CPU-driver variants of the sorts (TS_TEXEL_BUFFERS;
// radix_*_texel, onesweep_*_texel), which llvmpipe reads and writes with SIMD gathers and scatters where
// a load or store at a per-invocation address is a loop over the SIMD lanes (vk::texel_buffers_wanted).
// Narrow keys are R32_UINT texels, wide ones R32G32_UINT (low word first, as in memory); the same
// buffers as the push constants' addresses. The including shader declares WIDE_KEYS.
layout(set = 0, binding = 0) uniform utextureBuffer keys_in_texels;
layout(set = 0, binding = 1) uniform utextureBuffer values_in_texels;
layout(set = 0, binding = 2, r32ui) uniform writeonly uimageBuffer narrow_keys_out_texels;
layout(set = 0, binding = 3, rg32ui) uniform writeonly uimageBuffer wide_keys_out_texels;
layout(set = 0, binding = 4, r32ui) uniform writeonly uimageBuffer values_out_texels;

uint64_t texel_load_key(uint i) {
  uvec2 words = texelFetch(keys_in_texels, int(i)).xy;
  return WIDE_KEYS ? pack64(words) : uint64_t(words.x);
}

uint texel_load_value(uint i) { return texelFetch(values_in_texels, int(i)).x; }

void texel_store_pair(uint i, uint64_t key, uint value) {
  if (WIDE_KEYS)
    imageStore(wide_keys_out_texels, int(i), uvec4(unpack32(key), 0u, 0u));
  else
    imageStore(narrow_keys_out_texels, int(i), uvec4(uint(key)));
  imageStore(values_out_texels, int(i), uvec4(value));
}
