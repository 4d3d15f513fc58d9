#version 460
// Bitonic sort, first pass: each invocation sorts 16 consecutive keys in registers (the stages up to
// 16) and tags each with its input position. When the count fits one group this is the whole sort,
// and the pass gathers the payloads itself.
#extension GL_GOOGLE_include_directive : require
#define TS_BITONIC_PASS_PUSH  // its push constants (shader_io.h)
#include "common.glsl"
#include "bitonic_common.glsl"

void main() {
  uint n = sort_count();
  bool last_pass = padded_count(n) <= GROUP;
  uint invocations = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  g_low_bit = 0;
  for (uint base = gl_GlobalInvocationID.x * GROUP; base < n; base += invocations * GROUP) {
    g_base = base;
    g_base_upper = base;  // a flip inside the group pairs members directly: no mirrored half
    load_group(n, true);
    // Stages 2, 4, 8 and 16, each its flip and then its plain steps down to stride 1.
    step0();
    step1(true);
    step0();
    step2(true);
    step1(false);
    step0();
    step3(true);
    step2(false);
    step1(false);
    step0();
    store_group(n, last_pass);
  }
}
