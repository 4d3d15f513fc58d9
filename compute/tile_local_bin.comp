#version 460
// Tile-local sort, steps 1 and 3: the bin of a key is its bits from `shift` up. The count pass
// counts each bin's keys; after the scan, the scatter pass moves each key into its bin's range
// through the bin's atomic cursor and records its input position beside it. The order inside a bin
// is whatever the atomics gave: the sort of the bin orders by (local key, position), which restores
// the stable order. On a CPU driver global atomics cost no more than shared ones, and the bins
// (up to 2^16) are too many for a shared histogram per workgroup.
#extension GL_GOOGLE_include_directive : require
#define TS_TILE_LOCAL_BIN_PUSH  // its push constants (shader_io.h)
#include "common.glsl"
#include "tile_local_bins.glsl"

layout(local_size_x = 256) in;
layout(constant_id = 0) const bool WIDE_KEYS = true;
layout(constant_id = 1) const bool SCATTER = false;

#include "sort_keys.glsl"

void main() {
  uint n = min(pc.state.v[SORT_COUNT], pc.capacity);
  uint invocations = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  for (uint k = gl_GlobalInvocationID.x; k < n; k += invocations) {
    uint64_t key = load_key(pc.keys_in, k);
    // Keys have no bits above the sort's key bits; the mask only keeps a key that broke that
    // contract from writing outside the table.
    uint bin = uint(key >> pc.shift) & (pc.bin_count - 1u);
    if (!SCATTER) {
      atomicAdd(pc.bins.v[BINS_COUNTS + bin], 1u);
    } else {
      uint dst = atomicAdd(pc.bins.v[BINS_COUNTS + pc.bin_count + bin], 1u);
      store_key(pc.keys_out, dst, key);
      pc.positions_out.v[dst] = k;
    }
  }
}
