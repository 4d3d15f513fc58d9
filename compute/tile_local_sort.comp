#version 460
// Tile-local sort, step 4: each workgroup takes every gl_NumWorkGroups-th bin (a few workgroups cover
// any bin count; interleaved bins spread a frame's large tiles over them), or of the BIG variant,
// every gl_NumWorkGroups-th bin of the big-bin list the other variant made, and sorts a bin's elements, which the scatter left in arbitrary order, by (local key, input position) with the
// network of tile_local_network.glsl. That order is the stable order. The last pass writes each key
// back whole (bin << shift | local key) and gathers its payload from the input values.
// Two variants: bins of up to CAPACITY elements run the network in shared memory (the group pass
// reads the bin from global memory, the last pass writes the result there); larger bins (BIG) run it
// in place in the bin's own range of keys_alt and values_alt. The network costs the same per pass
// either way; only the memory it runs in differs.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const bool WIDE_KEYS = true;   // 64-bit key buffers
layout(constant_id = 2) const bool WIDE_LOCAL = false;  // local keys wider than 32 bits
layout(constant_id = 3) const bool BIG = false;         // this variant takes the bins over CAPACITY
layout(constant_id = 4) const uint CAPACITY = 2048;     // the largest bin sorted in shared memory
layout(constant_id = 5) const uint HI_CAPACITY = 1;     // CAPACITY when WIDE_LOCAL, else 1 (unused)

#include "tile_local_network.glsl"
#include "tile_local_bins.glsl"

// The BIG variant's invocations read what others of the workgroup wrote in the previous pass.
layout(buffer_reference, std430, buffer_reference_align = 8) coherent buffer CoherentUint64s { uint64_t v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) coherent buffer CoherentUints { uint v[]; };

layout(push_constant) uniform Push {
  uint64_t keys;       // keys_alt: the binned keys; the sorted keys at the end
  uint64_t positions;  // values_alt: each binned key's input position; the gathered payloads at the end
  UintArray values_in; // the payloads, by input position
  UintArray bins;      // see tile_local_bins.glsl
  uint bin_count;
  uint shift;          // local key bits: a key is bin << shift | local key
} pc;

shared uint64_t s_w[CAPACITY];
shared uint s_hi[HI_CAPACITY];

// Where a pass loads from and stores to.
const uint IN_SHARED = 0;
const uint IN_GLOBAL = 1;  // the bin's range of keys_alt / values_alt, keys whole
const uint TO_OUTPUT = 2;  // the same range, with payloads in place of positions (the last pass)

uint64_t load_global_key(uint i) {
  if (WIDE_KEYS) return CoherentUint64s(pc.keys).v[i];
  return uint64_t(CoherentUints(pc.keys).v[i]);
}

void store_global_key(uint i, uint64_t key) {
  if (WIDE_KEYS)
    CoherentUint64s(pc.keys).v[i] = key;
  else
    CoherentUints(pc.keys).v[i] = uint(key);
}

// Element j of the bin that starts at global index `start`; j must be below the bin's size.
void load_member(uint start, uint j, uint where, out uint64_t w, out uint hi) {
  if (where == IN_SHARED) {
    w = s_w[j];
    hi = WIDE_LOCAL ? s_hi[j] : 0u;
    return;
  }
  uint64_t local_key = load_global_key(start + j) & ((uint64_t(1) << pc.shift) - 1u);
  w = local_key << 32 | uint64_t(CoherentUints(pc.positions).v[start + j]);
  hi = WIDE_LOCAL ? uint(local_key >> 32) : 0u;
}

void store_member(uint start, uint j, uint bin, uint where, uint64_t w, uint hi) {
  if (where == IN_SHARED) {
    s_w[j] = w;
    if (WIDE_LOCAL) s_hi[j] = hi;
    return;
  }
  uint64_t key = uint64_t(bin) << pc.shift | uint64_t(hi) << 32 | w >> 32;
  uint position = uint(w & 0xffffffffu);
  store_global_key(start + j, key);
  CoherentUints(pc.positions).v[start + j] = where == TO_OUTPUT ? pc.values_in.v[position] : position;
}

// Indices past the bin are padding. Loads are clamped rather than skipped: a branch around register
// writes costs lavapipe more than the redundant load.
Quad load_quad(uint quad, uint start, uint m, uint where) {
  uvec4 j = quad_indices(quad);
  uvec4 at = min(j, uvec4(m - 1u));
  Quad q;
  load_member(start, at.x, where, q.w.x, q.hi.x);
  load_member(start, at.y, where, q.w.y, q.hi.y);
  load_member(start, at.z, where, q.w.z, q.hi.z);
  load_member(start, at.w, where, q.w.w, q.hi.w);
  return pick(PADDING, q, lessThan(j, uvec4(m)));
}

void store_quad(uint quad, Quad q, uint start, uint m, uint bin, uint where) {
  uvec4 j = quad_indices(quad);
  if (j.x < m) store_member(start, j.x, bin, where, q.w.x, q.hi.x);
  if (j.y < m) store_member(start, j.y, bin, where, q.w.y, q.hi.y);
  if (j.z < m) store_member(start, j.z, bin, where, q.w.z, q.hi.z);
  if (j.w < m) store_member(start, j.w, bin, where, q.w.w, q.hi.w);
}

void load_group(uint start, uint m, uint where) {
  q0 = load_quad(0, start, m, where);
  q1 = load_quad(1, start, m, where);
  q2 = load_quad(2, start, m, where);
  q3 = load_quad(3, start, m, where);
}

void store_group(uint start, uint m, uint bin, uint where) {
  store_quad(0, q0, start, m, bin, where);
  store_quad(1, q1, start, m, bin, where);
  store_quad(2, q2, start, m, bin, where);
  store_quad(3, q3, start, m, bin, where);
}

void pass_barrier() {
  if (BIG) memoryBarrierBuffer();
  memoryBarrierShared();
  barrier();
}

void sort_bin(uint bin, uint start, uint m) {
  const uint network = BIG ? IN_GLOBAL : IN_SHARED;
  uint padded_bits = m <= 1u ? 0u : uint(findMSB(m - 1u)) + 1u;
  uint groups = max((1u << padded_bits) >> GROUP_BITS, 1u);
  bool single_group = padded_bits <= GROUP_BITS;
  g_low_bit = 0;
  for (uint g = gl_LocalInvocationIndex; g < groups; g += gl_WorkGroupSize.x) {
    g_base = g * GROUP;
    g_base_upper = g_base;
    load_group(start, m, IN_GLOBAL);
    sort_group();
    store_group(start, m, bin, single_group ? TO_OUTPUT : network);
  }
  for (uint stage_bits = GROUP_BITS + 1; stage_bits <= padded_bits; ++stage_bits) {
    uint steps_left = stage_bits;
    while (steps_left > 0u) {
      pass_barrier();
      uint steps = (steps_left - 1u) % GROUP_BITS + 1u;
      bool flip = steps_left == stage_bits;
      bool last = stage_bits == padded_bits && steps == steps_left;
      for (uint g = gl_LocalInvocationIndex; g < groups; g += gl_WorkGroupSize.x) {
        pass_layout(g, steps_left, flip);
        if (g_base >= m) continue;  // the group's lowest index: all of it is padding
        load_group(start, m, network);
        run_steps(steps, flip);
        store_group(start, m, bin, last ? TO_OUTPUT : network);
      }
      steps_left -= steps;
    }
  }
}

// The first bin from `bin` on, in steps of the workgroup count, that has 1 to CAPACITY keys; the
// larger ones met on the way go to the big-bin list. A loop, not a branch around the sort: lavapipe
// runs both sides of a branch, so a skipped bin would still cost a masked pass of the network.
uint next_small_bin(uint bin) {
  for (; bin < pc.bin_count; bin += gl_NumWorkGroups.x) {
    uint m = pc.bins.v[BINS_COUNTS + bin];
    if (m > CAPACITY && gl_LocalInvocationIndex == 0u)
      pc.bins.v[BINS_COUNTS + 2u * pc.bin_count + atomicAdd(pc.bins.v[BINS_BIG], 1u)] = bin;
    if (m != 0u && m <= CAPACITY) break;
  }
  return bin;
}

void sort_listed_bin(uint bin) {
  uint m = pc.bins.v[BINS_COUNTS + bin];
  sort_bin(bin, pc.bins.v[BINS_COUNTS + pc.bin_count + bin] - m, m);
  pass_barrier();  // the next bin reuses the shared network
}

void main() {
  // A static assignment rather than an atomic work counter: its loop iterations per invocation are
  // bounded by the record-time workgroup count, which lavapipe needs (see tile_local_sort.cpp).
  if (BIG) {
    uint big_bins = pc.bins.v[BINS_BIG];
    for (uint i = gl_WorkGroupID.x; i < big_bins; i += gl_NumWorkGroups.x)
      sort_listed_bin(pc.bins.v[BINS_COUNTS + 2u * pc.bin_count + i]);
  } else {
    for (uint bin = next_small_bin(gl_WorkGroupID.x); bin < pc.bin_count; bin = next_small_bin(bin + gl_NumWorkGroups.x))
      sort_listed_bin(bin);
  }
}
