#include "sort/parallel_radix_sort.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "host_threads.h"

namespace tilesplat::detail {

bool parallel_radix_sort(std::span<uint32_t> keys, std::span<uint32_t> values,
                         std::span<uint32_t> keys_scratch, std::span<uint32_t> values_scratch,
                         uint32_t key_bits, unsigned threads) {
  const size_t n = keys.size();
  if (values.size() != n || keys_scratch.size() < n || values_scratch.size() < n)
    throw std::invalid_argument("parallel_radix_sort: " + std::to_string(n) + " keys but " +
                                std::to_string(values.size()) + " values and scratch for " +
                                std::to_string(keys_scratch.size()) + " keys and " +
                                std::to_string(values_scratch.size()) + " values");
  constexpr uint32_t kMaxPasses = 4;
  const uint32_t passes = std::min((std::clamp<uint32_t>(key_bits, 1, 32) + 7) / 8, kMaxPasses);
  threads = std::clamp<unsigned>(threads, 1, unsigned(std::max<size_t>(n, 1)));
  using Counts = std::array<std::array<size_t, 256>, kMaxPasses>;
  // Every pass's digit counts, per range, in one read of the keys (as the one-thread sort does).
  std::vector<Counts> counts(threads, Counts{});
  for_each_range(n, threads, [&](unsigned r, size_t begin, size_t end) {
    Counts& c = counts[r];
    for (size_t i = begin; i < end; ++i)
      for (uint32_t p = 0; p < passes; ++p) ++c[p][(keys[i] >> (8 * p)) & 0xff];
  });

  uint32_t* src_keys = keys.data();
  uint32_t* src_values = values.data();
  uint32_t* dst_keys = keys_scratch.data();
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
    // range's counts of this pass's digit are those of its keys now.
    if (p > 0)
      for_each_range(n, threads, [&](unsigned r, size_t begin, size_t end) {
        std::array<size_t, 256>& c = counts[r][p];
        c.fill(0);
        for (size_t i = begin; i < end; ++i) ++c[(src_keys[i] >> (8 * p)) & 0xff];
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
      std::array<size_t, 256>& next = counts[r][p];
      for (size_t i = begin; i < end; ++i) {
        const size_t dst = next[(src_keys[i] >> shift) & 0xff]++;
        dst_keys[dst] = src_keys[i];
        dst_values[dst] = src_values[i];
      }
    });
    std::swap(src_keys, dst_keys);
    std::swap(src_values, dst_values);
    in_scratch = !in_scratch;
  }
  return in_scratch;
}

}  // namespace tilesplat::detail
