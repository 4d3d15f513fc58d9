#version 460
// Bitonic sort, the stages longer than a group: one pass runs up to four consecutive steps of a stage.
// Its invocations each take the 16 keys whose indices differ only in the bits of those strides, so
// the steps never leave the invocation's registers. The last pass of the network's last stage
// (strides down to 1) gathers the payloads.
#extension GL_GOOGLE_include_directive : require
#define TS_BITONIC_PASS_PUSH  // its push constants (shader_io.h)
#include "common.glsl"
#include "bitonic_common.glsl"

void main() {
  uint n = sort_count();
  uint padded = padded_count(n);
  if (pc.stage > padded) return;
  // The group's bits are the network index bits [low_bit, low_bit + 4), ending at this pass's largest
  // stride. A stage's first pass may run fewer than four steps: it leaves the lowest group bits
  // alone, which only splits the group into independent parts.
  g_low_bit = uint(findMSB(pc.stride)) + 1u - GROUP_BITS;
  // A pass that starts with the stage's flip takes the upper half of its group mirrored: its indices
  // come from base ^ (2^low_bit - 1), which puts the network's mirror of member e at member e ^ 15,
  // the pairing of a flip inside a group, with both halves ascending.
  bool flip = pc.stride == pc.stage >> 1;
  uint mirror_mask = flip ? (1u << g_low_bit) - 1u : 0u;
  bool last_pass = pc.stage == padded && g_low_bit == 0u;
  uint groups = padded >> GROUP_BITS;
  uint invocations = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  for (uint g = gl_GlobalInvocationID.x; g < groups; g += invocations) {
    g_base = ((g >> g_low_bit) << (g_low_bit + GROUP_BITS)) | (g & ((1u << g_low_bit) - 1u));
    if (g_base >= n) continue;  // the group's lowest index: all of it is padding
    g_base_upper = g_base ^ mirror_mask;
    load_group(n, false);
    if (flip)
      step3(true);
    else
      step3(false);
    if (pc.steps >= 2) step2(false);
    if (pc.steps >= 3) step1(false);
    if (pc.steps >= 4) step0();
    store_group(n, last_pass);
  }
}
