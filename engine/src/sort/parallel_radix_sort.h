// The host's radix sort of 32-bit keys over several threads, for orders of tens of millions (the depth
// order of a scene in parts). Each pass, each thread counts the digits of its own contiguous range; a
// range's keys of a digit then go after those of the smaller digits and after the same digit's keys of
// the ranges before it, so each pass is stable and the result is cpu_radix_sort's, bit for bit.
#pragma once

#include <cstdint>
#include <span>

namespace tilesplat::detail {

// As cpu_radix_sort's 32-bit overload (the pairs ping-pong between keys/values and the scratch arrays;
// returns true when they ended in the scratch arrays), over `threads` threads (1: on the caller's alone).
// Throws std::invalid_argument if a size is short.
bool parallel_radix_sort(std::span<uint32_t> keys, std::span<uint32_t> values,
                         std::span<uint32_t> keys_scratch, std::span<uint32_t> values_scratch,
                         uint32_t key_bits, unsigned threads);

}  // namespace tilesplat::detail
