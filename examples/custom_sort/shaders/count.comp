#version 460
// Pass 1 of a digit: each invocation counts the digits of its chunk into its column of `counts`.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
layout(local_size_x = 64) in;

void main() {
  const uint chunk = gl_GlobalInvocationID.x;
  if (chunk >= chunks()) return;
  Words counts = Words(pc.counts);
  for (uint d = 0u; d < RADIX; ++d) counts.word[d * pc.chunk_capacity + chunk] = 0u;
  const uint end = min(pair_count(), (chunk + 1u) * CHUNK);
  for (uint i = chunk * CHUNK; i < end; ++i) counts.word[digit_of(key_at(pc.keys_in, i)) * pc.chunk_capacity + chunk] += 1u;
}
