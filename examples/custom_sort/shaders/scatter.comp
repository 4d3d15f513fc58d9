#version 460
// Pass 3 of a digit: each invocation moves its chunk's pairs, in order, to their positions.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
layout(local_size_x = 64) in;

void main() {
  const uint chunk = gl_GlobalInvocationID.x;
  if (chunk >= chunks()) return;
  Words counts = Words(pc.counts);
  Words values_in = Words(pc.values_in);
  Words values_out = Words(pc.values_out);
  const uint end = min(pair_count(), (chunk + 1u) * CHUNK);
  for (uint i = chunk * CHUNK; i < end; ++i) {
    const uint64_t key = key_at(pc.keys_in, i);
    const uint slot = digit_of(key) * pc.chunk_capacity + chunk;
    const uint at = counts.word[slot];
    counts.word[slot] = at + 1u;
    if (pc.wide != 0u) Keys64(pc.keys_out).key[at] = key;
    else Words(pc.keys_out).word[at] = uint(key);
    values_out.word[at] = values_in.word[i];
  }
}
