#version 460
// Radix sort, step 3 of a pass (scatter): each subgroup walks its block in order and writes every key
// to digit_base[digit] + (its block's offset for that digit) + (its rank among equal digits so far).
// The rank among the subgroup's lanes comes from 8 ballots (a "multi-split"), so the pass is stable.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "common.glsl"
#include "radix_common.glsl"

shared uint s_digit_base[RADIX];
shared uint s_offsets[SUBGROUPS_PER_WORKGROUP * RADIX];

void main() {
  uint n = pc.state.v[SORT_COUNT];
  uint blocks = pc.state.v[SORT_BLOCKS];
  if (gl_LocalInvocationIndex == 0) {
    uint running = 0;
    for (uint d = 0; d < RADIX; ++d) {
      s_digit_base[d] = running;
      running += pc.digit_totals.v[d];
    }
  }
  barrier();

  uint block = gl_WorkGroupID.x * SUBGROUPS_PER_WORKGROUP + gl_SubgroupID;
  if (block >= blocks) return;
  uint my = gl_SubgroupID * RADIX;
  for (uint d = gl_SubgroupInvocationID; d < RADIX; d += gl_SubgroupSize)
    s_offsets[my + d] = s_digit_base[d] + pc.histogram.v[d * blocks + block];
  subgroupMemoryBarrierShared();
  subgroupBarrier();

  uint start = block * block_keys();
  uint end = min(start + block_keys(), n);
  for (uint base = start; base < end; base += gl_SubgroupSize) {
    uint k = base + gl_SubgroupInvocationID;
    bool valid = k < end;
    uint64_t key = valid ? radix_load_key(k) : uint64_t(0);
    uint digit = digit_of(key);
    uvec4 peers = subgroupBallot(valid);
    for (uint b = 0; b < 8; ++b) {
      bool bit = ((digit >> b) & 1u) != 0u;
      uvec4 ones = subgroupBallot(bit);
      peers &= bit ? ones : ~ones;
    }
    uint rank = ballot_count(peers & gl_SubgroupLtMask);
    uint group = ballot_count(peers);
    uint dst = s_offsets[my + digit] + rank;
    subgroupMemoryBarrierShared();
    subgroupBarrier();  // every lane has read its offset before the last lane of each group bumps it
    if (valid) {
      radix_store(dst, key, radix_load_value(k));
      if (rank == group - 1) s_offsets[my + digit] += group;
    }
    subgroupMemoryBarrierShared();
    subgroupBarrier();
  }
}
