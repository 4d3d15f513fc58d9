#version 460
// Tile-local sort, step 4: each workgroup takes every gl_NumWorkGroups-th bin (a few workgroups cover
// any bin count; interleaved bins spread a frame's large tiles over them), or of the BIG variant,
// every gl_NumWorkGroups-th bin of the big-bin list the other variant made, and sorts a bin's
// elements, which the scatter left in arbitrary order, by (local key, input position). That order is
// the stable order. The last pass writes each key back whole (bin << shift | local key) and gathers
// its payload from the input values.
// Two variants. Bins of up to CAPACITY elements are sorted in shared memory by a merge sort: runs
// of 32 sorted in registers by the network of tile_local_network.glsl, then merges of sorted runs
// between two shared buffers, each invocation writing one span of the outputs from where the merge
// path puts its start. On lavapipe every pass costs its loads and stores lane by lane, and a bin of
// 512 elements takes 5 passes this way, where the bitonic network in shared memory took 12.
// Larger bins (BIG) run the bitonic network in place in the bin's own range of keys_alt and
// values_alt.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#define TS_TILE_LOCAL_SORT_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const bool WIDE_KEYS = true;   // 64-bit key buffers
layout(constant_id = 2) const bool WIDE_LOCAL = false;  // local keys wider than 32 bits
layout(constant_id = 3) const bool BIG = false;         // this variant takes the bins over CAPACITY
layout(constant_id = 4) const uint CAPACITY = 2048;     // the largest bin sorted in shared memory; 1 if BIG
layout(constant_id = 5) const uint HI_CAPACITY = 0;     // CAPACITY when WIDE_LOCAL, else 0

#include "tile_local_network.glsl"
#include "tile_local_bins.glsl"

// The BIG variant's invocations read what others of the workgroup wrote in the previous pass.
layout(buffer_reference, std430, buffer_reference_align = 8) coherent buffer CoherentUint64s { uint64_t v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) coherent buffer CoherentUints { uint v[]; };

// Two buffers of CAPACITY elements: a merge reads runs from one and writes the merged runs to the other.
// Element j of buffer b is s_w[b * CAPACITY + j], its hi part (WIDE_LOCAL) s_w[HI_BASE + b * HI_CAPACITY
// + j]: one array, as another of uints would take shared memory even when unused, and that the
// 2048-element buffers fill on lavapipe.
const uint HI_BASE = 2 * CAPACITY;
shared uint64_t s_w[2 * (CAPACITY + HI_CAPACITY)];

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
    hi = WIDE_LOCAL ? uint(s_w[HI_BASE + j]) : 0u;
    return;
  }
  uint64_t local_key = load_global_key(start + j) & ((uint64_t(1) << pc.shift) - 1u);
  w = local_key << 32 | uint64_t(CoherentUints(pc.positions).v[start + j]);
  hi = WIDE_LOCAL ? uint(local_key >> 32) : 0u;
}

void store_member(uint start, uint j, uint bin, uint where, uint64_t w, uint hi) {
  if (where == IN_SHARED) {
    s_w[j] = w;
    if (WIDE_LOCAL) s_w[HI_BASE + j] = hi;
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

// One element of a bin for the merges: w and hi as in tile_local_network.glsl.
struct Element {
  uint64_t w;
  uint hi;
};

const Element PADDING_ELEMENT = Element(~uint64_t(0), ~0u);

bool element_before(Element a, Element b) {
  if (!WIDE_LOCAL) return a.w < b.w;
  return a.hi < b.hi || (a.hi == b.hi && a.w < b.w);
}

Element load_shared(uint buf, uint j) {
  uint at = buf * CAPACITY + j;
  return Element(s_w[at], WIDE_LOCAL ? uint(s_w[HI_BASE + buf * HI_CAPACITY + j]) : 0u);
}

// The last merge writes the bin's range of the output instead.
void store_merged(uint buf, bool to_output, uint start, uint j, uint bin, Element e) {
  if (to_output) {
    store_member(start, j, bin, TO_OUTPUT, e.w, e.hi);
    return;
  }
  s_w[buf * CAPACITY + j] = e.w;
  if (WIDE_LOCAL) s_w[HI_BASE + buf * HI_CAPACITY + j] = e.hi;
}

// One merge of the sorted runs of `run` elements in buffer src into runs of 2 run. Each invocation
// writes one span of outputs, 16 at a time: the merge path search finds where in the two runs its
// first output comes from (the elements are unique, so the split is exact), and the merge then goes
// on from there, across chunks, without searching again; a new pair of runs starts at its first
// elements (a search of no steps). One span per invocation rather than chunks dealt out in turn
// keeps the searches, a load pair per step, to one per invocation and merge.
void merge_level(uint run, uint m, uint src, bool to_output, uint start, uint bin, uint span) {
  uint dst = 1u - src;
  uint first = gl_LocalInvocationIndex * span;
  uint end = min(first + span, m);
  uint ia = 0, ib = 0, a_end = 0, b_end = 0;
  Element a = PADDING_ELEMENT, b = PADDING_ELEMENT;
  for (uint out0 = first; out0 < end; out0 += GROUP) {
    uint a0 = out0 & ~(2u * run - 1u);
    uint pair_a_end = min(a0 + run, m);
    uint pair_b_end = min(a0 + 2u * run, m);
    uint diag = out0 - a0;
    bool fresh = out0 == first || diag == 0u;
    uint lo = fresh && diag > pair_b_end - pair_a_end ? diag - (pair_b_end - pair_a_end) : 0u;
    uint hi = fresh ? min(diag, pair_a_end - a0) : 0u;
    while (lo < hi) {
      uint mid = (lo + hi) >> 1;
      if (element_before(load_shared(src, a0 + mid), load_shared(src, pair_a_end + diag - 1u - mid)))
        lo = mid + 1u;
      else
        hi = mid;
    }
    if (fresh) {
      ia = a0 + lo;
      ib = pair_a_end + diag - lo;
      a_end = pair_a_end;
      b_end = pair_b_end;
      // Loads are clamped into the bin and replaced by padding past a run's end: a branch around
      // them would cost lavapipe both sides.
      a = load_shared(src, min(ia, m - 1u));
      b = load_shared(src, min(ib, m - 1u));
      if (ia >= a_end) a = PADDING_ELEMENT;
      if (ib >= b_end) b = PADDING_ELEMENT;
    }
    [[unroll]] for (uint k = 0; k < GROUP; ++k) {
      bool take_b = element_before(b, a);
      if (out0 + k < m) store_merged(dst, to_output, start, out0 + k, bin, take_b ? b : a);
      uint next = take_b ? ib + 1u : ia + 1u;
      Element v = load_shared(src, min(next, m - 1u));
      if (next >= (take_b ? b_end : a_end)) v = PADDING_ELEMENT;
      if (take_b) {
        b = v;
        ib = next;
      } else {
        a = v;
        ia = next;
      }
    }
  }
}

// The runs the merges start from: pairs of groups sorted by the network in registers, which costs
// lavapipe far less than a merge through shared memory.
const uint RUN0 = 2 * GROUP;

// Sorts the elements [32 g, 32 g + 32) of the bin into buffer 0: each half by the group network, then
// the stage of 32 (the flip pairs member e of the first half with member 15 - e of the second).
void sort_run0(uint g, uint start, uint m) {
  g_low_bit = 0;
  g_base = g * RUN0;
  g_base_upper = g_base;
  load_group(start, m, IN_GLOBAL);
  sort_group();
  Quad p0 = q0, p1 = q1, p2 = q2, p3 = q3;
  g_base += GROUP;
  g_base_upper = g_base;
  load_group(start, m, IN_GLOBAL);
  sort_group();
  Quad r0 = reversed(q3), r1 = reversed(q2), r2 = reversed(q1), r3 = reversed(q0);
  exchange(p0, r0);
  exchange(p1, r1);
  exchange(p2, r2);
  exchange(p3, r3);
  q0 = reversed(r3);
  q1 = reversed(r2);
  q2 = reversed(r1);
  q3 = reversed(r0);
  run_steps(GROUP_BITS, false);
  store_group(start, m, 0u, IN_SHARED);
  q0 = p0;
  q1 = p1;
  q2 = p2;
  q3 = p3;
  run_steps(GROUP_BITS, false);
  g_base -= GROUP;
  g_base_upper = g_base;
  store_group(start, m, 0u, IN_SHARED);
}

void merge_sort_bin(uint bin, uint start, uint m) {
  for (uint g = gl_LocalInvocationIndex; g * RUN0 < m; g += gl_WorkGroupSize.x) sort_run0(g, start, m);
  // Whole groups per invocation, as few as cover the bin.
  uint groups = (m + GROUP - 1u) / GROUP;
  uint span = (groups + gl_WorkGroupSize.x - 1u) / gl_WorkGroupSize.x * GROUP;
  // The last merge is a call of its own, so that where each merge stores is known when compiled:
  // lavapipe would run the output stores masked in every merge otherwise. A bin of one run takes
  // it too, as the copy of a single run.
  uint src = 0;
  uint run = RUN0;
  for (; 2u * run < m; run *= 2u) {
    pass_barrier();
    merge_level(run, m, src, false, start, bin, span);
    src = 1u - src;
  }
  pass_barrier();
  merge_level(run, m, src, true, start, bin, span);
}

void network_sort_bin(uint bin, uint start, uint m) {
  const uint network = IN_GLOBAL;  // only the BIG variant runs the network over a whole bin
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
    if (m > CAPACITY && gl_LocalInvocationIndex == 0u) {
      uint listed = atomicAdd(pc.bins.v[BINS_BIG], 1u);
      pc.bins.v[BINS_COUNTS + 2u * pc.bin_count + listed] = bin;
      if (listed < pc.big_workgroups) atomicAdd(pc.bins.v[BINS_BIG_ARGS], 1u);
    }
    if (m != 0u && m <= CAPACITY) break;
  }
  return bin;
}

void sort_listed_bin(uint bin) {
  uint m = pc.bins.v[BINS_COUNTS + bin];
  uint start = pc.bins.v[BINS_COUNTS + pc.bin_count + bin] - m;
  if (BIG)
    network_sort_bin(bin, start, m);
  else
    merge_sort_bin(bin, start, m);
  pass_barrier();  // the next bin reuses the shared buffers
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
