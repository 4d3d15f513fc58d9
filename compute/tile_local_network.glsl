// The tile-local sort's in-bin network: a bitonic network on (local key, input position) elements.
// Positions are unique, so the order is total: no stability is needed from the network, and the
// arbitrary order in which the binning pass left a bin's elements does not show in the result.
//
// The network is the all-ascending form (stage k first compares i with i ^ (k - 1), then i with
// i + stride for strides k/4 ... 1, smaller element to the lower index), padded to a power of two
// with +infinity elements that are loaded as sentinels and never stored: a sentinel always sits at
// the higher index of its pair, so it never moves into the real range.
//
// Each invocation holds a group of 16 elements in registers and runs up to four steps on it per pass,
// so an element crosses memory once per four steps: lavapipe loads and stores shared memory one lane
// and one component at a time, which makes memory traffic, not compares, the cost of the network.
// The group is four named quads, not an array, so that lavapipe keeps it in registers.
//
// The includer declares WIDE_LOCAL (local keys wider than 32 bits) before including this file.

// Member e of a group is component e % 4 of quad e / 4. An element is w = local key low 32 bits << 32
// | position, plus the local key's high bits in hi (zero unless WIDE_LOCAL); padding is all ones.
struct Quad {
  u64vec4 w;
  uvec4 hi;
};

Quad q0, q1, q2, q3;
// Member e sits at bin index (e < 8 ? g_base : g_base_upper) + (e << g_low_bit).
uint g_base, g_base_upper, g_low_bit;

const uint GROUP_BITS = 4;
const uint GROUP = 16;

uvec4 quad_indices(uint quad) {
  return (quad < 2 ? g_base : g_base_upper) + ((quad * 4 + uvec4(0, 1, 2, 3)) << g_low_bit);
}

const Quad PADDING = Quad(u64vec4(~uint64_t(0)), uvec4(~0u));

// Per component: does a go before b?
bvec4 before(Quad a, Quad b) {
  if (!WIDE_LOCAL) return lessThan(a.w, b.w);
  return bvec4(uvec4(lessThan(a.hi, b.hi)) | (uvec4(equal(a.hi, b.hi)) & uvec4(lessThan(a.w, b.w))));
}

Quad pick(Quad a, Quad b, bvec4 take_b) { return Quad(mix(a.w, b.w, take_b), mix(a.hi, b.hi, take_b)); }
Quad reversed(Quad q) { return Quad(q.w.wzyx, q.hi.wzyx); }

// Compare-exchange of two quads, component by component.
void exchange(inout Quad low, inout Quad high) {
  if (!WIDE_LOCAL) {
    u64vec4 smaller = min(low.w, high.w);
    high.w = max(low.w, high.w);
    low.w = smaller;
    return;
  }
  bvec4 swap = before(high, low);
  Quad smaller = pick(low, high, swap);
  high = pick(high, low, swap);
  low = smaller;
}

// Compare-exchange inside a quad with `partner` (q permuted so each component faces its pair); the
// `upper` components keep the larger element. Real elements never tie, padding ties are identical.
Quad exchange_within(Quad q, Quad partner, bvec4 upper) {
  if (!WIDE_LOCAL) return Quad(mix(min(q.w, partner.w), max(q.w, partner.w), upper), q.hi);
  return pick(q, partner, bvec4(uvec4(before(partner, q)) ^ uvec4(upper)));
}

// One step on member bit b: the stage's flip pairs e with e ^ (2^(b+1) - 1), a plain step pairs e with
// e + 2^b. Bits 3 and 2 pair whole quads, bits 1 and 0 components of a quad.
void step3(bool flip) {
  if (flip) {
    Quad r3 = reversed(q3), r2 = reversed(q2);
    exchange(q0, r3);
    exchange(q1, r2);
    q3 = reversed(r3);
    q2 = reversed(r2);
  } else {
    exchange(q0, q2);
    exchange(q1, q3);
  }
}

void step2(bool flip) {
  if (flip) {
    Quad r1 = reversed(q1), r3 = reversed(q3);
    exchange(q0, r1);
    exchange(q2, r3);
    q1 = reversed(r1);
    q3 = reversed(r3);
  } else {
    exchange(q0, q1);
    exchange(q2, q3);
  }
}

Quad quad_step1(Quad q, bool flip) {
  const bvec4 upper = bvec4(false, false, true, true);
  return exchange_within(q, flip ? reversed(q) : Quad(q.w.zwxy, q.hi.zwxy), upper);
}

void step1(bool flip) {
  q0 = quad_step1(q0, flip);
  q1 = quad_step1(q1, flip);
  q2 = quad_step1(q2, flip);
  q3 = quad_step1(q3, flip);
}

// On bit 0 the flip and the plain step pair the same members.
Quad quad_step0(Quad q) { return exchange_within(q, Quad(q.w.yxwz, q.hi.yxwz), bvec4(false, true, false, true)); }

void step0() {
  q0 = quad_step0(q0);
  q1 = quad_step0(q1);
  q2 = quad_step0(q2);
  q3 = quad_step0(q3);
}

// The stages 2 to 16 on a group of 16 consecutive elements.
void sort_group() {
  step0();
  step1(true);
  step0();
  step2(true);
  step1(false);
  step0();
  step3(true);
  step2(false);
  step1(false);
  step0();
}

// The passes after the group stages: stage_bits 5 ... log2(padded). A stage of s steps runs its first
// (s - 1) % 4 + 1 steps (its flip among them) in one pass, then passes of four, so that its last pass
// ends at stride 1. pass_layout places group g of a pass whose largest stride is 2^(steps_left - 1):
// the group's members take the index bits [low_bit, low_bit + 4) ending at that stride, and a pass that
// starts with the flip takes its upper half mirrored (indices base ^ (2^low_bit - 1)), which turns the
// network's flip into the pairing of member e with e ^ 15, both halves ascending.
void pass_layout(uint g, uint steps_left, bool flip) {
  g_low_bit = steps_left - GROUP_BITS;
  uint low_mask = (1u << g_low_bit) - 1u;
  g_base = ((g >> g_low_bit) << (g_low_bit + GROUP_BITS)) | (g & low_mask);
  g_base_upper = flip ? g_base ^ low_mask : g_base;
}

void run_steps(uint steps, bool flip) {
  step3(flip);
  if (steps >= 2) step2(false);
  if (steps >= 3) step1(false);
  if (steps >= 4) step0();
}
