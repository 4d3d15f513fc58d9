#version 460
// Pass 2 of a digit: one workgroup turns the counts into each chunk's first output position per
// digit. In digit-major order (all chunks of digit 0, then of digit 1, ...) an exclusive prefix sum
// of the counts is exactly that: smaller digits first, and within a digit the chunks in input order.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
layout(local_size_x = 256) in;  // one invocation per digit row

shared uint row_base[RADIX];

void main() {
  const uint digit = gl_LocalInvocationID.x;
  const uint n = chunks();
  Words counts = Words(pc.counts);
  const uint row = digit * pc.chunk_capacity;
  uint sum = 0u;
  for (uint c = 0u; c < n; ++c) {
    const uint count = counts.word[row + c];
    counts.word[row + c] = sum;
    sum += count;
  }
  row_base[digit] = sum;
  barrier();
  if (digit == 0u) {
    uint total = 0u;
    for (uint d = 0u; d < RADIX; ++d) {
      const uint row_total = row_base[d];
      row_base[d] = total;
      total += row_total;
    }
  }
  barrier();
  for (uint c = 0u; c < n; ++c) counts.word[row + c] += row_base[digit];
}
