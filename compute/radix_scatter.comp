#version 460
// Radix sort, step 3 of a pass (scatter): each subgroup walks its block in order and writes every key
// to digit_base[digit] + (its block's offset for that digit) + (its rank among equal digits so far).
// The rank among the subgroup's lanes comes from 8 ballots (a "multi-split"), so the pass is stable.
// CPU drivers walk the block differently (scatter_lane_runs), with the same result.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#define TS_RADIX_PASS_PUSH  // its push constants (shader_io.h)
#include "common.glsl"
#include "radix_common.glsl"

shared uint s_digit_base[RADIX];

#ifdef TS_TEXEL_BUFFERS
// The CPU-driver variant: each lane owns a contiguous run of the block (block_keys() / subgroup size
// keys) and walks it in order with its own 256 offsets in a private array, starting where the runs of
// the lanes before it end (the block's offset + an exclusive subgroup sum of the lanes' digit counts,
// which it counts first). The pass stays stable without the ballots, the shared-memory offsets and
// their per-lane loads and stores, which llvmpipe runs one SIMD lane at a time (2^22 32-bit keys:
// about 10% faster; docs/benchmarks.md).
void scatter_lane_runs(uint block, uint blocks, uint n) {
  uint start = block * block_keys();
  uint end = min(start + block_keys(), n);
  uint per_lane = block_keys() / gl_SubgroupSize;
  uint run_start = min(start + gl_SubgroupInvocationID * per_lane, end);
  uint run_end = min(run_start + per_lane, end);
  uint offsets[RADIX];
  for (uint d = 0; d < RADIX; ++d) offsets[d] = 0u;
  for (uint k = run_start; k < run_end; ++k) ++offsets[digit_of(radix_load_key(k))];
  for (uint d = 0; d < RADIX; ++d)
    offsets[d] = s_digit_base[d] + pc.histogram.v[d * blocks + block] + subgroupExclusiveAdd(offsets[d]);
  for (uint k = run_start; k < run_end; ++k) {
    uint64_t key = radix_load_key(k);
    uint digit = digit_of(key);
    uint dst = offsets[digit];
    offsets[digit] = dst + 1u;
    radix_store(dst, key, radix_load_value(k));
  }
}
#else
// GPUs: the subgroup walks the block 8 keys a step, ranking each step's equal digits with 8 ballots;
// its running offsets per digit are in shared memory. Every subgroup of the workgroup takes the same
// number of steps, the last block's and those past the last block (`has_block` false) included, storing
// nothing there: Mesa 25's lavapipe synchronises subgroupBarrier() across the whole workgroup, and
// with uneven step counts the barriers mismatched and no key was scattered (the pass then wrote nothing).
shared uint s_offsets[SUBGROUPS_PER_WORKGROUP * RADIX];
void scatter_multisplit(uint block, uint blocks, uint n, bool has_block) {
  uint my = gl_SubgroupID * RADIX;
  if (has_block)
    for (uint d = gl_SubgroupInvocationID; d < RADIX; d += gl_SubgroupSize)
      s_offsets[my + d] = s_digit_base[d] + pc.histogram.v[d * blocks + block];
  subgroupMemoryBarrierShared();
  subgroupBarrier();

  uint keys_per_block = block_keys();  // read once: the loop's stores could alias it
  uint start = block * keys_per_block;
  uint end = has_block ? min(start + keys_per_block, n) : start;
  for (uint step = 0; step < keys_per_block; step += gl_SubgroupSize) {
    uint k = start + step + gl_SubgroupInvocationID;
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
#endif

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
#ifdef TS_TEXEL_BUFFERS
  if (block < blocks) scatter_lane_runs(block, blocks, n);
#else
  scatter_multisplit(block, blocks, n, block < blocks);
#endif
}
