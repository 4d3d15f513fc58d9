// The host's LSD radix sort (8-bit digits) over one thread or several: cpu_radix_sort runs it on one, the
// depth order of a scene in parts (tens of millions of keys) on the host's cores. Each pass, each thread
// counts the digits of its own contiguous range; a range's keys of a digit then go after those of the
// smaller digits and after the same digit's keys of the ranges before it, so each pass is stable and the
// result is the same for any number of threads, bit for bit.
#pragma once

#include <cstdint>
#include <span>

namespace tilesplat::detail {

// As cpu_radix_sort's span overloads (the pairs ping-pong between keys/values and the scratch arrays;
// returns true when they ended in the scratch arrays), over `threads` threads (1: the caller's alone).
// Throws std::invalid_argument, its message starting with `caller`, if a size is short.
bool parallel_radix_sort(std::span<uint32_t> keys, std::span<uint32_t> values,
                         std::span<uint32_t> keys_scratch, std::span<uint32_t> values_scratch,
                         uint32_t key_bits, unsigned threads, const char* caller = "parallel_radix_sort");
bool parallel_radix_sort(std::span<uint64_t> keys, std::span<uint32_t> values,
                         std::span<uint64_t> keys_scratch, std::span<uint32_t> values_scratch,
                         uint32_t key_bits, unsigned threads, const char* caller = "parallel_radix_sort");

}  // namespace tilesplat::detail
