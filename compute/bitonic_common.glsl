// Shared by the bitonic sort kernels. The network sorts (key, input position) pairs: the position
// breaks ties, which makes the sort stable although a sorting network is not, and the payloads are
// gathered through it only at the end (they are not positions, so they cannot break ties).
//
// The network is the all-ascending ("flip") form: stage k makes every run of k keys ascending; its
// first step compares mirrored pairs across a run (i and i ^ (k - 1)), the later ones i and i + stride
// (strides k/4 ... 1); every compare-exchange moves the smaller pair to the lower index. That lets
// it sort any count without padded buffers: the keys from the count up to the next power of two act
// as +infinity, and an infinity sits at the higher index of every pair it is in, so it never moves
// and never needs storing. The kernels load it as a sentinel above every real pair.
//
// Each invocation holds a group of 16 keys in registers and runs up to four steps on it per pass (the
// group is closed under those steps), so the keys cross memory once per four steps. That takes the
// place of the usual shared-memory block kernel: lavapipe reads and writes shared memory one lane at
// a time, and a step through it cost 7 ms on 2^20 keys, where a pass of four steps on register
// groups costs 3 ms. The group is four named vectors rather than an array: lavapipe does not unroll
// nested loops over a 16-key array, keeps the array in memory, and each pass was three times slower.
layout(local_size_x = 256) in;
// When the key and position fit one 64-bit word together (key << position_bits | position), the
// network moves 8 bytes a key instead of 12 and compares with one min/max instead of two compares.
// Packed network words are 64-bit whatever the key layout; with 32-bit keys they live in a scratch
// buffer of the strategy's own.
layout(constant_id = 0) const bool PACKED = false;
layout(constant_id = 1) const bool WIDE_KEYS = true;
#include "sort_keys.glsl"

const uint GROUP_BITS = 4;
const uint GROUP = 16;

uint sort_count() { return min(pc.state.v[SORT_COUNT], pc.capacity); }

// The network's length for this frame's count. A pass recorded for a longer network finds its stage
// beyond it and returns at once: the recording covers the capacity, the GPU runs what the count needs.
uint padded_count(uint n) { return n <= 1u ? 1u : 1u << uint(findMSB(n - 1u) + 1); }

// Four members of a group (x, y, z, w) with their input positions (unused when PACKED).
struct Quad {
  u64vec4 key;
  uvec4 position;
};

// The group: member e is component e % 4 of quad e / 4. Its network index is
// (e < 8 ? g_base : g_base_upper) + (e << g_low_bit); the layouts of both kernels fit that form.
Quad q0, q1, q2, q3;
uint g_base, g_base_upper, g_low_bit;

uvec4 quad_indices(uint quad) {
  return (quad < 2 ? g_base : g_base_upper) + ((quad * 4 + uvec4(0, 1, 2, 3)) << g_low_bit);
}

uint64_t load_network_key(uint i) { return PACKED ? Uint64Array(pc.keys).v[i] : load_key(pc.keys, i); }

// Members past the count are padding: +infinity, and a position above every real one so that no
// real pair equals it. Loads are clamped rather than skipped: a branch around register writes costs
// lavapipe more than the redundant load.
Quad load_quad(uint quad, uint n, bool from_input) {
  uvec4 i = quad_indices(quad);
  bvec4 real = lessThan(i, uvec4(n));
  uvec4 at = min(i, uvec4(n - 1));
  u64vec4 key;
  if (from_input)
    key = u64vec4(load_key(pc.keys_in, at.x), load_key(pc.keys_in, at.y), load_key(pc.keys_in, at.z),
                  load_key(pc.keys_in, at.w));
  else
    key = u64vec4(load_network_key(at.x), load_network_key(at.y), load_network_key(at.z), load_network_key(at.w));
  uvec4 position = i;
  if (from_input && PACKED) key = key << pc.position_bits | u64vec4(i);
  if (!from_input && !PACKED)
    position = uvec4(pc.positions.v[at.x], pc.positions.v[at.y], pc.positions.v[at.z], pc.positions.v[at.w]);
  return Quad(mix(u64vec4(~uint64_t(0)), key, real), mix(uvec4(~0u), position, real));
}

// The pass that completes the network writes the keys as they came in and gathers the payloads in
// their sorted order; every other pass stores the network's state.
void store_member(uint i, uint64_t key, uint position, bool last_pass) {
  if (!last_pass) {
    if (PACKED)
      Uint64Array(pc.keys).v[i] = key;
    else
      store_key(pc.keys, i, key);
    if (!PACKED) pc.positions.v[i] = position;
  } else if (PACKED) {
    store_key(pc.keys_out, i, key >> pc.position_bits);
    pc.values_out.v[i] = pc.values_in.v[uint(key & ((uint64_t(1) << pc.position_bits) - 1))];
  } else {
    store_key(pc.keys_out, i, key);
    pc.values_out.v[i] = pc.values_in.v[position];
  }
}

void store_quad(uint quad, Quad q, uint n, bool last_pass) {
  uvec4 i = quad_indices(quad);
  if (i.x < n) store_member(i.x, q.key.x, q.position.x, last_pass);
  if (i.y < n) store_member(i.y, q.key.y, q.position.y, last_pass);
  if (i.z < n) store_member(i.z, q.key.z, q.position.z, last_pass);
  if (i.w < n) store_member(i.w, q.key.w, q.position.w, last_pass);
}

void load_group(uint n, bool from_input) {
  q0 = load_quad(0, n, from_input);
  q1 = load_quad(1, n, from_input);
  q2 = load_quad(2, n, from_input);
  q3 = load_quad(3, n, from_input);
}

void store_group(uint n, bool last_pass) {
  store_quad(0, q0, n, last_pass);
  store_quad(1, q1, n, last_pass);
  store_quad(2, q2, n, last_pass);
  store_quad(3, q3, n, last_pass);
}

// Per component: does pair a go before pair b? Positions are unique, so only padding ties.
bvec4 goes_before(Quad a, Quad b) {
  if (PACKED) return lessThan(a.key, b.key);
  return bvec4(uvec4(lessThan(a.key, b.key)) | (uvec4(equal(a.key, b.key)) & uvec4(lessThan(a.position, b.position))));
}

Quad select(Quad a, Quad b, bvec4 take_b) { return Quad(mix(a.key, b.key, take_b), mix(a.position, b.position, take_b)); }
Quad reversed(Quad q) { return Quad(q.key.wzyx, q.position.wzyx); }

// Compare-exchange of two quads, component by component: the smaller pairs to `low`.
void order(inout Quad low, inout Quad high) {
  bvec4 swap = goes_before(high, low);
  Quad smaller = select(low, high, swap);
  high = select(high, low, swap);
  low = smaller;
}

// Compare-exchange inside a quad: `partner` is the quad permuted so that each component faces its
// pair, `upper` marks the components that take the larger pair.
Quad order_within(Quad q, Quad partner, bvec4 upper) {
  bvec4 partner_smaller = goes_before(partner, q);
  bvec4 take_partner = bvec4(uvec4(partner_smaller) ^ uvec4(upper));
  // An upper component takes its partner when the partner is larger, i.e. not smaller (no ties
  // between real pairs; equal padding is the same either way).
  return select(q, partner, take_partner);
}

// One step on member bit b: the stage's flip pairs e with e ^ (2^(b+1) - 1), a plain step pairs e
// with e + 2^b, exactly like network indices. Bits 3 and 2 pair whole quads, bits 1 and 0 components.
void step3(bool flip) {
  if (flip) {
    Quad r3 = reversed(q3), r2 = reversed(q2);
    order(q0, r3);
    order(q1, r2);
    q3 = reversed(r3);
    q2 = reversed(r2);
  } else {
    order(q0, q2);
    order(q1, q3);
  }
}

void step2(bool flip) {
  if (flip) {
    Quad r1 = reversed(q1), r3 = reversed(q3);
    order(q0, r1);
    order(q2, r3);
    q1 = reversed(r1);
    q3 = reversed(r3);
  } else {
    order(q0, q1);
    order(q2, q3);
  }
}

Quad quad_step1(Quad q, bool flip) {
  const bvec4 upper = bvec4(false, false, true, true);
  return flip ? order_within(q, reversed(q), upper) : order_within(q, Quad(q.key.zwxy, q.position.zwxy), upper);
}

void step1(bool flip) {
  q0 = quad_step1(q0, flip);
  q1 = quad_step1(q1, flip);
  q2 = quad_step1(q2, flip);
  q3 = quad_step1(q3, flip);
}

// On bit 0 the flip and the plain step pair the same members.
Quad quad_step0(Quad q) { return order_within(q, Quad(q.key.yxwz, q.position.yxwz), bvec4(false, true, false, true)); }

void step0() {
  q0 = quad_step0(q0);
  q1 = quad_step0(q1);
  q2 = quad_step0(q2);
  q3 = quad_step0(q3);
}
