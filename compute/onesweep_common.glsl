// Shared by the onesweep sort kernels (engine/src/sort/onesweep_sort.h). Must match the constants there.
const uint RADIX = 256;
const uint MAX_PASSES = 8;  // 8-bit digits of keys up to 64 bits

// The control block (one small buffer, cleared by onesweep_setup every sort).
const uint CTRL_BASES = 0;                           // MAX_PASSES * RADIX: digit counts, then exclusive bases
const uint CTRL_TICKETS = CTRL_BASES + MAX_PASSES * RADIX;  // MAX_PASSES: partition tickets handed out per pass
const uint CTRL_HISTOGRAM_DONE = CTRL_TICKETS + MAX_PASSES;  // histogram workgroups that have added their counts
const uint CTRL_UINTS = CTRL_HISTOGRAM_DONE + 1;

// A partition's status per digit: one word, so a (flag, count) pair is always read whole and relaxed
// atomics suffice (no other data hangs off the flag). The flags grow AGGREGATE < INCLUSIVE, so a
// helper publishes with atomicMax and can never hide a later, more complete state. Counts < 2^30.
const uint STATUS_EMPTY = 0u;
const uint STATUS_AGGREGATE = 1u << 30;  // the count of this partition's keys with the digit
const uint STATUS_INCLUSIVE = 2u << 30;  // the count of those keys in this and every earlier partition
const uint STATUS_COUNT = STATUS_AGGREGATE - 1u;

uint digit_at(uint64_t key, uint shift) { return uint(key >> shift) & (RADIX - 1u); }

// The lanes of the subgroup whose (valid) digit equals this lane's: 8 ballots, one per digit bit
// (the multi-split of radix_scatter.comp).
uvec4 digit_peers(uint digit, bool valid) {
  uvec4 peers = subgroupBallot(valid);
  for (uint b = 0; b < 8; ++b) {
    bool bit = ((digit >> b) & 1u) != 0u;
    uvec4 ones = subgroupBallot(bit);
    peers &= bit ? ones : ~ones;
  }
  return peers;
}

uint load_status(UintArray status, uint i) {
  return atomicLoad(status.v[i], gl_ScopeDevice, gl_StorageSemanticsBuffer, gl_SemanticsRelaxed);
}

void store_status(UintArray status, uint i, uint value) {
  atomicStore(status.v[i], value, gl_ScopeDevice, gl_StorageSemanticsBuffer, gl_SemanticsRelaxed);
}
