// CPU sorts of key/value pairs, for comparing the GPU strategies against on the same machine (the
// sort micro-benchmark) and for the cpu-radix strategy. Same contract as the GPU strategies:
// ascending keys, equal keys in their input order.
#pragma once

#include <cstdint>
#include <vector>

namespace tilesplat {

// LSD radix sort with 8-bit digits over the low key_bits bits of the keys (higher bits must be
// zero); values move with their keys. Stable. Throws std::invalid_argument if the sizes differ.
void cpu_radix_sort(std::vector<uint64_t>& keys, std::vector<uint32_t>& values, uint32_t key_bits);

}  // namespace tilesplat
