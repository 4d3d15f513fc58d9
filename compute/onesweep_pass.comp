#version 460
// Onesweep sort, one digit pass in one kernel. Each workgroup takes a partition ticket (partitions are
// processed in ticket order, whatever order the device starts workgroups in), ranks its partition's
// keys stably, publishes its digit counts, looks back over the earlier partitions for its prefix
// (decoupled look-back), publishes that, and scatters. A look-back that waits too long on a
// predecessor that has published nothing counts that predecessor's keys itself (onesweep_sort.h
// explains why this makes the pass safe without a forward-progress guarantee).
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_memory_scope_semantics : require
#define TS_ONESWEEP_PASS_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint SUBGROUPS_PER_WORKGROUP = 8;
layout(constant_id = 2) const uint KEYS_PER_LANE = 128;  // partition = workgroup size * KEYS_PER_LANE keys
layout(constant_id = 3) const bool WIDE_KEYS = true;

#include "sort_keys.glsl"
#include "onesweep_common.glsl"

#ifdef TS_TEXEL_BUFFERS
#include "sort_key_texels.glsl"  // onesweep_pass_texel
uint64_t pass_load_key(uint i) { return texel_load_key(i); }
void pass_store(uint dst, uint k) { texel_store_pair(dst, texel_load_key(k), texel_load_value(k)); }
#else
uint64_t pass_load_key(uint i) { return load_key(pc.keys_in, i); }
void pass_store(uint dst, uint k) {
  store_key(pc.keys_out, dst, load_key(pc.keys_in, k));
  pc.values_out.v[dst] = pc.values_in.v[k];
}
#endif

const uint WG = gl_WorkGroupSize.x;
const uint PARTITION_KEYS = WG * KEYS_PER_LANE;
const uint DIGITS_PER_LANE = (RADIX + WG - 1) / WG;  // digits each lane owns in the look-back
const uint NO_KEY = 0xffffffffu;

// Per subgroup and digit: the subgroup's count, then the output position of its first key of the digit.
shared uint s_counts[SUBGROUPS_PER_WORKGROUP * RADIX];
// Per key (in input order): digit << 16 | rank among the subgroup's keys of that digit, or NO_KEY. In
// shared memory rather than registers: lavapipe keeps a large register array in memory it indexes
// lane by lane, which made the pass twice as slow.
shared uint s_ranks[PARTITION_KEYS];
shared uint s_fallback[RADIX];  // a stalled predecessor's digit counts
shared uint s_ticket;
shared uint s_vote[3];

uint g_vote_round = 0;

// Whether any lane's v is true; every invocation must call it in uniform control flow. One barrier:
// the three vote words rotate, and the one cleared here was last read two rounds ago.
bool workgroup_any(bool v) {
  uint slot = g_vote_round % 3;
  if (gl_LocalInvocationIndex == 0) s_vote[(slot + 1) % 3] = 0;
  if (subgroupAny(v) && subgroupElect()) atomicOr(s_vote[slot], 1u);
  barrier();
  ++g_vote_round;
  return s_vote[slot] != 0;
}

// The digit counts of partition q's keys into s_fallback, from the keys (which nobody writes in this
// pass), so no cooperation of the workgroup that owns q is needed.
void count_partition(uint q, uint n) {
  for (uint d = gl_LocalInvocationIndex; d < RADIX; d += WG) s_fallback[d] = 0;
  barrier();
  uint start = q * PARTITION_KEYS;
  uint end = min(start + PARTITION_KEYS, n);
  for (uint k = start + gl_LocalInvocationIndex; k < end; k += WG)
    atomicAdd(s_fallback[digit_at(pass_load_key(k), pc.shift)], 1u);
  barrier();
}

void main() {
  const uint lid = gl_LocalInvocationIndex;
  uint n = pc.state.v[SORT_COUNT];
  if (lid == 0) {
    s_ticket = atomicAdd(pc.control.v[CTRL_TICKETS + pc.pass], 1u);
    s_vote[0] = 0;
  }
  for (uint i = lid; i < SUBGROUPS_PER_WORKGROUP * RADIX; i += WG) s_counts[i] = 0;
  barrier();
  uint part = s_ticket;

  // Rank: each subgroup walks its contiguous share of the partition in order, so the order within a
  // digit is the input order.
  uint my = gl_SubgroupID * RADIX;
  uint local = gl_SubgroupID * gl_SubgroupSize * KEYS_PER_LANE + gl_SubgroupInvocationID;
  uint first = part * PARTITION_KEYS + local;
  for (uint j = 0; j < KEYS_PER_LANE; ++j) {
    uint k = first + j * gl_SubgroupSize;
    bool valid = k < n;
    uint64_t key = valid ? pass_load_key(k) : uint64_t(0);
    uint digit = digit_at(key, pc.shift);
    uvec4 peers = digit_peers(digit, valid);
    uint rank = ballot_count(peers & gl_SubgroupLtMask);
    uint group = ballot_count(peers);
    uint before = s_counts[my + digit];
    subgroupMemoryBarrierShared();
    subgroupBarrier();  // every lane has read its count before the last lane of each group bumps it
    if (valid && rank == group - 1) s_counts[my + digit] = before + group;
    subgroupMemoryBarrierShared();
    subgroupBarrier();
    s_ranks[local + j * gl_SubgroupSize] = valid ? digit << 16 | (before + rank) : NO_KEY;
  }
  barrier();

  // Publish the partition's count of each digit: already INCLUSIVE for the first partition.
  uint row = part * RADIX;
  uint total[DIGITS_PER_LANE];
  for (uint i = 0; i < DIGITS_PER_LANE; ++i) {
    uint d = lid + i * WG;
    total[i] = 0;
    if (d >= RADIX) continue;
    for (uint s = 0; s < SUBGROUPS_PER_WORKGROUP; ++s) total[i] += s_counts[s * RADIX + d];
    store_status(pc.status, row + d, (part == 0 ? STATUS_INCLUSIVE : STATUS_AGGREGATE) | total[i]);
  }

  // Decoupled look-back, one predecessor at a time for the whole workgroup (a fallback needs all its
  // lanes); each lane stops adding to its digits at their first INCLUSIVE status.
  uint prefix[DIGITS_PER_LANE];
  uint pending = 0;  // bit i: digit lid + i * WG still needs earlier partitions
  for (uint i = 0; i < DIGITS_PER_LANE; ++i) {
    prefix[i] = 0;
    if (part > 0 && lid + i * WG < RADIX) pending |= 1u << i;
  }
  if (part > 0) {
    // Spin limit 0 forces the fallback: the immediate predecessor is treated as stalled, unread.
    bool force = pc.spin_limit == 0;
    for (uint q = part - 1;; --q) {
      uint seen[DIGITS_PER_LANE];
      bool read = !(force && q == part - 1);
      bool empty = false;
      for (uint i = 0; i < DIGITS_PER_LANE; ++i) {
        seen[i] = read && (pending & (1u << i)) != 0 ? load_status(pc.status, q * RADIX + lid + i * WG) : STATUS_EMPTY;
        empty = empty || ((pending & (1u << i)) != 0 && seen[i] == STATUS_EMPTY);
      }
      // Wait in rounds that the whole workgroup takes together, never in a loop of one lane: a lane
      // spinning alone ran out of lavapipe's loop budget (65535 iterations per invocation, over all
      // loops; the host caps spin_limit there), after which its later loops, barriers' partners
      // included, ended early and the order came out corrupted.
      bool stalled = workgroup_any(empty);
      for (uint round = 0; stalled && read && round < pc.spin_limit; ++round) {
        empty = false;
        for (uint i = 0; i < DIGITS_PER_LANE; ++i) {
          if ((pending & (1u << i)) == 0 || seen[i] != STATUS_EMPTY) continue;
          seen[i] = load_status(pc.status, q * RADIX + lid + i * WG);
          empty = empty || seen[i] == STATUS_EMPTY;
        }
        stalled = workgroup_any(empty);
      }
      if (stalled) {
        count_partition(q, n);
        for (uint i = 0; i < DIGITS_PER_LANE; ++i) {
          if ((pending & (1u << i)) == 0 || seen[i] != STATUS_EMPTY) continue;
          // Partition 0's own count is its inclusive prefix. Publishing it (unless the owner has since)
          // spares later look-backs the same fallback; the owner later publishes the same count.
          seen[i] = (q == 0 ? STATUS_INCLUSIVE : STATUS_AGGREGATE) | s_fallback[lid + i * WG];
          atomicCompSwap(pc.status.v[q * RADIX + lid + i * WG], STATUS_EMPTY, seen[i]);
        }
        if (lid == 0) atomicAdd(pc.fallbacks.v[0], 1u);
      }
      for (uint i = 0; i < DIGITS_PER_LANE; ++i) {
        if ((pending & (1u << i)) == 0) continue;
        prefix[i] += seen[i] & STATUS_COUNT;
        if (seen[i] >= STATUS_INCLUSIVE) pending &= ~(1u << i);
      }
      if (!workgroup_any(pending != 0)) break;
    }
  }

  for (uint i = 0; i < DIGITS_PER_LANE; ++i) {
    uint d = lid + i * WG;
    if (d >= RADIX) continue;
    if (part > 0) store_status(pc.status, row + d, STATUS_INCLUSIVE | (prefix[i] + total[i]));
    if (pc.clear_next != 0) pc.status_next.v[row + d] = STATUS_EMPTY;
    // The subgroups' counts become their first output positions (in subgroup order), so that the
    // scatter reads one word per key.
    uint running = pc.control.v[CTRL_BASES + pc.pass * RADIX + d] + prefix[i];
    for (uint s = 0; s < SUBGROUPS_PER_WORKGROUP; ++s) {
      uint c = s_counts[s * RADIX + d];
      s_counts[s * RADIX + d] = running;
      running += c;
    }
  }
  barrier();

  // Scatter. The keys are read again rather than kept in registers (see s_ranks).
  for (uint j = 0; j < KEYS_PER_LANE; ++j) {
    uint r = s_ranks[local + j * gl_SubgroupSize];
    if (r == NO_KEY) continue;
    uint k = first + j * gl_SubgroupSize;
    uint dst = s_counts[my + (r >> 16)] + (r & 0xffffu);
    pass_store(dst, k);
  }
}
