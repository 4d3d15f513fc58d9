#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

#include "tilesplat/sort.h"

namespace tilesplat {

namespace {

template <typename Key>
bool radix_sort(std::span<Key> keys, std::span<uint32_t> values, std::span<Key> keys_scratch,
                std::span<uint32_t> values_scratch, uint32_t key_bits) {
  const size_t n = keys.size();
  if (values.size() != n || keys_scratch.size() < n || values_scratch.size() < n)
    throw std::invalid_argument("cpu_radix_sort: " + std::to_string(n) + " keys but " + std::to_string(values.size()) +
                                " values and scratch for " + std::to_string(keys_scratch.size()) + " keys and " +
                                std::to_string(values_scratch.size()) + " values");
  constexpr uint32_t kMaxPasses = sizeof(Key);
  const uint32_t passes = std::min((std::clamp<uint32_t>(key_bits, 1, 64) + 7) / 8, kMaxPasses);
  // All digit histograms in one read of the keys; a pass whose digit is the same for every key
  // (all keys in one bucket) moves nothing and is skipped.
  std::array<std::array<size_t, 256>, kMaxPasses> counts{};
  for (const Key key : keys)
    for (uint32_t p = 0; p < passes; ++p) ++counts[p][(key >> (8 * p)) & 0xff];
  Key* src_keys = keys.data();
  uint32_t* src_values = values.data();
  Key* dst_keys = keys_scratch.data();
  uint32_t* dst_values = values_scratch.data();
  bool in_scratch = false;
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
      const size_t dst = c[(src_keys[i] >> shift) & 0xff]++;
      dst_keys[dst] = src_keys[i];
      dst_values[dst] = src_values[i];
    }
    std::swap(src_keys, dst_keys);
    std::swap(src_values, dst_values);
    in_scratch = !in_scratch;
  }
  return in_scratch;
}

}  // namespace

bool cpu_radix_sort(std::span<uint32_t> keys, std::span<uint32_t> values, std::span<uint32_t> keys_scratch,
                    std::span<uint32_t> values_scratch, uint32_t key_bits) {
  return radix_sort(keys, values, keys_scratch, values_scratch, key_bits);
}

bool cpu_radix_sort(std::span<uint64_t> keys, std::span<uint32_t> values, std::span<uint64_t> keys_scratch,
                    std::span<uint32_t> values_scratch, uint32_t key_bits) {
  return radix_sort(keys, values, keys_scratch, values_scratch, key_bits);
}

void cpu_radix_sort(std::vector<uint64_t>& keys, std::vector<uint32_t>& values, uint32_t key_bits) {
  if (keys.size() != values.size())
    throw std::invalid_argument("cpu_radix_sort: " + std::to_string(keys.size()) + " keys but " +
                                std::to_string(values.size()) + " values");
  std::vector<uint64_t> keys_tmp(keys.size());
  std::vector<uint32_t> values_tmp(values.size());
  if (radix_sort<uint64_t>(keys, values, keys_tmp, values_tmp, key_bits)) {
    keys.swap(keys_tmp);
    values.swap(values_tmp);
  }
}

}  // namespace tilesplat
