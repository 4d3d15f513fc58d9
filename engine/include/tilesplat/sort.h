/// @file
/// CPU sorts of key/value pairs, for comparing the GPU strategies against on the same machine (the
/// sort micro-benchmark) and for the cpu-radix strategy. Same contract as the GPU strategies:
/// ascending keys, equal keys in their input order.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "tilesplat/export.h"

namespace tilesplat {

/// LSD radix sort with 8-bit digits over the low key_bits bits of the keys (higher bits must be
/// zero); values move with their keys. Stable. Throws std::invalid_argument if the sizes differ.
TILESPLAT_API void cpu_radix_sort(std::vector<uint64_t>& keys, std::vector<uint32_t>& values,
                                  uint32_t key_bits);

/// The same sort in caller-owned memory, which it does not allocate: the pairs ping-pong between
/// keys/values and the scratch arrays (each at least keys.size() long), for a caller that keeps
/// its buffers between sorts (the cpu-radix strategy sorts in mapped or staging memory). Returns
/// true when the sorted pairs ended up in the scratch arrays, false when in keys/values. 32-bit keys
/// halve the memory traffic when every key fits. Throws std::invalid_argument if a size is short.
TILESPLAT_API bool cpu_radix_sort(std::span<uint32_t> keys, std::span<uint32_t> values,
                                  std::span<uint32_t> keys_scratch, std::span<uint32_t> values_scratch,
                                  uint32_t key_bits);
/// The same as the 32-bit overload, for 64-bit keys.
TILESPLAT_API bool cpu_radix_sort(std::span<uint64_t> keys, std::span<uint32_t> values,
                                  std::span<uint64_t> keys_scratch, std::span<uint32_t> values_scratch,
                                  uint32_t key_bits);

}  // namespace tilesplat
