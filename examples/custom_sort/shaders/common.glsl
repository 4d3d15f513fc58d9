// What the three passes of the serial-chunk radix sort share: the push constants and the buffers
// they reach by device address (tilesplat's key buffers are created with device-address usage).
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

// Each invocation owns CHUNK consecutive pairs and walks them in order: that walk is what keeps
// the sort stable without any ranking inside a workgroup.
#define CHUNK 256u
#define RADIX 256u

layout(buffer_reference, std430, buffer_reference_align = 8) buffer Keys64 { uint64_t key[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Words { uint word[]; };

layout(push_constant) uniform Push {
  uint64_t keys_in;     // Keys64 or Words, by `wide`
  uint64_t values_in;   // Words
  uint64_t keys_out;
  uint64_t values_out;
  uint64_t counts;      // Words: RADIX rows of `chunk_capacity` per-chunk digit counts, digit-major
  uint64_t count;       // Words: word 0 is the number of pairs, written on the GPU
  uint shift;           // the digit's lowest key bit
  uint wide;            // 1: 64-bit keys, 0: 32-bit keys
  uint chunk_capacity;  // chunks the counts buffer has room for
} pc;

uint pair_count() { return Words(pc.count).word[0]; }
uint chunks() { return (pair_count() + CHUNK - 1u) / CHUNK; }

uint64_t key_at(uint64_t keys, uint i) {
  return pc.wide != 0u ? Keys64(keys).key[i] : uint64_t(Words(keys).word[i]);
}

uint digit_of(uint64_t key) { return uint(key >> pc.shift) & (RADIX - 1u); }
