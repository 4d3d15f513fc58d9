#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

#include "sort/parallel_radix_sort.h"
#include "tilesplat/sort.h"

namespace tilesplat {

bool cpu_radix_sort(std::span<uint32_t> keys, std::span<uint32_t> values, std::span<uint32_t> keys_scratch,
                    std::span<uint32_t> values_scratch, uint32_t key_bits) {
  return detail::parallel_radix_sort(keys, values, keys_scratch, values_scratch, key_bits, 1,
                                     "cpu_radix_sort");
}

bool cpu_radix_sort(std::span<uint64_t> keys, std::span<uint32_t> values, std::span<uint64_t> keys_scratch,
                    std::span<uint32_t> values_scratch, uint32_t key_bits) {
  return detail::parallel_radix_sort(keys, values, keys_scratch, values_scratch, key_bits, 1,
                                     "cpu_radix_sort");
}

void cpu_radix_sort(std::vector<uint64_t>& keys, std::vector<uint32_t>& values, uint32_t key_bits) {
  if (keys.size() != values.size())
    throw std::invalid_argument("cpu_radix_sort: " + std::to_string(keys.size()) + " keys but " +
                                std::to_string(values.size()) + " values");
  std::vector<uint64_t> keys_tmp(keys.size());
  std::vector<uint32_t> values_tmp(values.size());
  if (detail::parallel_radix_sort(std::span(keys), std::span(values), std::span(keys_tmp),
                                  std::span(values_tmp), key_bits, 1, "cpu_radix_sort")) {
    keys.swap(keys_tmp);
    values.swap(values_tmp);
  }
}

}  // namespace tilesplat
