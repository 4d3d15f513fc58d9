#version 460
// One invocation between the prefix sum and the key emission: decides how many keys this frame
// sorts (never more than the buffers hold) and writes the indirect dispatch sizes that depend on
// it, so the frame needs no CPU round trip. An overflow is flagged for the host to grow and retry.
#extension GL_GOOGLE_include_directive : require
#define TS_FRAME_SETUP_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x = 1) in;

void main() {
  uint total = pc.counters.v[COUNTER_INTERSECTIONS];
  bool overflow = total > pc.capacity || pc.counters.v[COUNTER_PAIRS_HIGH] != 0;  // 2^32 pairs or more
  // An overflowing frame is thrown away and re-rendered with larger buffers, so it sorts and
  // composites nothing: the key emission leaves the slots of the Gaussian that straddles the
  // capacity unwritten, and sorting them would feed stale tile ids and indices to the composite.
  uint sorted = overflow ? 0u : total;
  pc.counters.v[COUNTER_SORT_COUNT] = sorted;
  pc.counters.v[COUNTER_OVERFLOW] = overflow ? 1u : 0u;
  pc.counters.v[COUNTER_RANGES_ARGS + 0] = (sorted + 255) / 256;
  pc.counters.v[COUNTER_RANGES_ARGS + 1] = 1;
  pc.counters.v[COUNTER_RANGES_ARGS + 2] = 1;
}
