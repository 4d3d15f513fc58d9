#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

#include "tilesplat/sort.h"

namespace tilesplat {

void cpu_radix_sort(std::vector<uint64_t>& keys, std::vector<uint32_t>& values, uint32_t key_bits) {
  if (keys.size() != values.size())
    throw std::invalid_argument("cpu_radix_sort: " + std::to_string(keys.size()) + " keys but " +
                                std::to_string(values.size()) + " values");
  const size_t n = keys.size();
  const uint32_t passes = (std::clamp<uint32_t>(key_bits, 1, 64) + 7) / 8;
  std::vector<uint64_t> keys_tmp(n);
  std::vector<uint32_t> values_tmp(n);
  // All digit histograms in one read of the keys; a pass whose digit is the same for every key
  // (all keys in one bucket) moves nothing and is skipped.
  std::vector<std::array<size_t, 256>> counts(passes);
  for (auto& c : counts) c.fill(0);
  for (const uint64_t key : keys)
    for (uint32_t p = 0; p < passes; ++p) ++counts[p][(key >> (8 * p)) & 0xff];
  for (uint32_t p = 0; p < passes; ++p) {
    auto& c = counts[p];
    if (std::any_of(c.begin(), c.end(), [n](size_t v) { return v == n; })) continue;
    size_t running = 0;
    for (auto& v : c) {
      const size_t count = v;
      v = running;
      running += count;
    }
    const uint32_t shift = 8 * p;
    for (size_t i = 0; i < n; ++i) {
      const size_t dst = c[(keys[i] >> shift) & 0xff]++;
      keys_tmp[dst] = keys[i];
      values_tmp[dst] = values[i];
    }
    keys.swap(keys_tmp);
    values.swap(values_tmp);
  }
}

}  // namespace tilesplat
