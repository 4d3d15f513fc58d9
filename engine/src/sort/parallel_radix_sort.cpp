#include "sort/parallel_radix_sort.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "host_resources.h"

namespace tilesplat::detail {

namespace {

template <typename Key>
bool radix_sort(std::span<Key> keys, std::span<uint32_t> values, std::span<Key> keys_scratch,
                std::span<uint32_t> values_scratch, uint32_t key_bits, unsigned threads, const char* caller) {
  const size_t n = keys.size();
  if (values.size() != n || keys_scratch.size() < n || values_scratch.size() < n)
    throw std::invalid_argument(std::string(caller) + ": " + std::to_string(n) + " keys but " +
                                std::to_string(values.size()) + " values and scratch for " +
                                std::to_string(keys_scratch.size()) + " keys and " +
                                std::to_string(values_scratch.size()) + " values");
  constexpr uint32_t kMaxPasses = sizeof(Key);
  const uint32_t passes = std::min((std::clamp<uint32_t>(key_bits, 1, 8 * kMaxPasses) + 7) / 8, kMaxPasses);
  threads = std::clamp<unsigned>(threads, 1, unsigned(std::min<size_t>(std::max<size_t>(n, 1), 1u << 16)));
  using Counts = std::array<std::array<size_t, 256>, kMaxPasses>;
  // Every pass's digit counts, per range, in one read of the keys (as the one-thread sort does).
  std::vector<Counts> counts(threads, Counts{});
  for_each_range(n, threads, [&](unsigned r, size_t begin, size_t end) {
    const Key* const from_keys = keys.data();
    Counts c{};
    for (size_t i = begin; i < end; ++i)
      for (uint32_t p = 0; p < passes; ++p) ++c[p][(from_keys[i] >> (8 * p)) & 0xff];
    counts[r] = c;
  });

  Key* src_keys = keys.data();
  uint32_t* src_values = values.data();
  Key* dst_keys = keys_scratch.data();
  uint32_t* dst_values = values_scratch.data();
  bool in_scratch = false;
  for (uint32_t p = 0; p < passes; ++p) {
    // A pass whose digit is the same for every key moves nothing (the totals of the first read hold for
    // every pass: a pass permutes the keys, it does not change them).
    bool one_digit = false;
    for (size_t digit = 0; digit < 256 && !one_digit; ++digit) {
      size_t total = 0;
      for (unsigned r = 0; r < threads; ++r) total += counts[r][p][digit];
      one_digit = total == n;
    }
    if (one_digit) continue;
    // The ranges cover the same positions every pass, and after a pass other keys lie there: each
    // range's counts of this pass's digit are those of its keys now (one range: the first read's).
    if (p > 0 && threads > 1)
      for_each_range(n, threads, [&](unsigned r, size_t begin, size_t end) {
        const Key* const from_keys = src_keys;
        std::array<size_t, 256> c{};
        for (size_t i = begin; i < end; ++i) ++c[(from_keys[i] >> (8 * p)) & 0xff];
        counts[r][p] = c;
      });
    // Where each range's keys of each digit start: after every smaller digit, then after the same
    // digit's keys of the ranges before it.
    size_t running = 0;
    for (size_t digit = 0; digit < 256; ++digit)
      for (unsigned r = 0; r < threads; ++r) {
        const size_t count = counts[r][p][digit];
        counts[r][p][digit] = running;
        running += count;
      }
    const uint32_t shift = 8 * p;
    for_each_range(n, threads, [&](unsigned r, size_t begin, size_t end) {
      // The pointers copied to this thread's stack: read through references into the caller's, they would
      // share cache lines with what the caller's own range writes.
      const Key* const from_keys = src_keys;
      const uint32_t* const from_values = src_values;
      Key* const to_keys = dst_keys;
      uint32_t* const to_values = dst_values;
      std::array<size_t, 256> next = counts[r][p];
      for (size_t i = begin; i < end; ++i) {
        const size_t dst = next[(from_keys[i] >> shift) & 0xff]++;
        to_keys[dst] = from_keys[i];
        to_values[dst] = from_values[i];
      }
    });
    std::swap(src_keys, dst_keys);
    std::swap(src_values, dst_values);
    in_scratch = !in_scratch;
  }
  return in_scratch;
}

}  // namespace

bool parallel_radix_sort(std::span<uint32_t> keys, std::span<uint32_t> values,
                         std::span<uint32_t> keys_scratch, std::span<uint32_t> values_scratch,
                         uint32_t key_bits, unsigned threads, const char* caller) {
  return radix_sort(keys, values, keys_scratch, values_scratch, key_bits, threads, caller);
}

bool parallel_radix_sort(std::span<uint64_t> keys, std::span<uint32_t> values,
                         std::span<uint64_t> keys_scratch, std::span<uint32_t> values_scratch,
                         uint32_t key_bits, unsigned threads, const char* caller) {
  return radix_sort(keys, values, keys_scratch, values_scratch, key_bits, threads, caller);
}

}  // namespace tilesplat::detail
