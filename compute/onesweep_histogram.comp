#version 460
// Onesweep sort, before the digit passes: one workgroup per partition counts the digits of every pass
// the key width needs (the keys are read once for all passes), adds them to the global counts, and the
// last workgroup to finish turns them into each pass's exclusive digit bases. It also clears the
// partition's status row for the first digit pass.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_memory_scope_semantics : require
#define TS_ONESWEEP_HISTOGRAM_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint PARTITION_KEYS = 2048;
layout(constant_id = 2) const bool WIDE_KEYS = true;

#include "sort_keys.glsl"
#include "onesweep_common.glsl"

#ifdef TS_TEXEL_BUFFERS
#include "sort_key_texels.glsl"  // onesweep_histogram_texel: the keys through binding 0
uint64_t histogram_load_key(uint i) { return texel_load_key(i); }
#else
uint64_t histogram_load_key(uint i) { return load_key(pc.keys, i); }
#endif

shared uint s_counts[MAX_PASSES * RADIX];
shared bool s_last;

void main() {
  const uint lid = gl_LocalInvocationIndex;
  const uint wg = gl_WorkGroupSize.x;
  uint n = pc.state.v[SORT_COUNT];
  uint part = gl_WorkGroupID.x;
  uint bins = pc.passes * RADIX;
  for (uint i = lid; i < bins; i += wg) s_counts[i] = 0;
  for (uint d = lid; d < RADIX; d += wg) pc.status.v[part * RADIX + d] = STATUS_EMPTY;
  barrier();

  uint start = part * PARTITION_KEYS;
  uint end = min(start + PARTITION_KEYS, n);
  for (uint k = start + lid; k < end; k += wg) {
    uint64_t key = histogram_load_key(k);
    for (uint p = 0; p < pc.passes; ++p) atomicAdd(s_counts[p * RADIX + digit_at(key, 8 * p)], 1u);
  }
  barrier();

  for (uint i = lid; i < bins; i += wg) {
    uint c = s_counts[i];
    if (c != 0) atomicAdd(pc.control.v[CTRL_BASES + i], c);
  }
  // The last workgroup to arrive must see every other workgroup's counts: each one's adds are ordered
  // before its arrival by the fence. Nobody waits here, so this needs no forward-progress guarantee.
  memoryBarrierBuffer();
  barrier();
  if (lid == 0) s_last = atomicAdd(pc.control.v[CTRL_HISTOGRAM_DONE], 1u) == gl_NumWorkGroups.x - 1;
  barrier();
  if (!s_last) return;
  memoryBarrierBuffer();
  // Once per sort: a lane per pass scans its 256 counts serially.
  if (lid < pc.passes) {
    uint running = 0;
    for (uint d = 0; d < RADIX; ++d) {
      uint i = CTRL_BASES + lid * RADIX + d;
      uint c = atomicLoad(pc.control.v[i], gl_ScopeDevice, gl_StorageSemanticsBuffer, gl_SemanticsRelaxed);
      pc.control.v[i] = running;
      running += c;
    }
  }
}
