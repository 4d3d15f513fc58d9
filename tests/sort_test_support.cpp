#include "sort_test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>

#include "vulkan/command_stream.h"

namespace tilesplat::testing {

vk::Context& sort_test_context() {
  static vk::Context ctx({"", true});
  return ctx;
}

uint32_t payload(uint32_t position) { return (position * 2654435761u) ^ 0x5bd1e995u; }
uint32_t position_of(uint32_t value) {
  // 2654435761 * 244002641 = 1 (mod 2^32): the inverse of the multiplication above.
  return (value ^ 0x5bd1e995u) * 244002641u;
}

std::vector<uint64_t> random_keys(size_t n, uint32_t bits, uint64_t seed, uint64_t distinct) {
  std::mt19937_64 rng(seed);
  std::vector<uint64_t> keys(n);
  const uint64_t mask = bits >= 64 ? ~0ull : (1ull << bits) - 1;
  // The odd multiplier spreads the few distinct values over every key bit (a bijection mod 2^bits).
  for (auto& k : keys) k = (distinct ? (rng() % distinct) * 0x9e3779b97f4a7c15ull : rng()) & mask;
  return keys;
}

std::vector<uint32_t> stable_order(const std::vector<uint64_t>& keys) {
  std::vector<uint32_t> order(keys.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
  return order;
}

DeviceSortInput upload_sort_input(const std::vector<uint64_t>& keys, uint32_t key_bits, uint32_t capacity,
                                  bool count_on_host) {
  vk::Context& ctx = sort_test_context();
  const uint32_t n = uint32_t(keys.size());
  DeviceSortInput in;
  in.count = n;
  in.buffers = KeyBuffers::allocate(ctx, std::max({capacity, n, 1u}), key_bits, "test");
  if (n > 0) {
    std::vector<uint32_t> values(n);
    for (uint32_t i = 0; i < n; ++i) values[i] = payload(i);
    const std::vector<uint8_t> packed = in.buffers.pack_keys(keys);
    vk::upload(ctx, in.buffers.keys, packed.data(), packed.size());
    vk::upload(ctx, in.buffers.values, values.data(), n * 4ull);
  }
  in.counters = vk::Buffer(ctx, sizeof(FrameCounters), vk::MemoryUse::Readback, "test counters");
  std::memset(in.counters.mapped(), 0, sizeof(FrameCounters));
  if (count_on_host) {
    SortState state{};
    state.count = n;
    std::memcpy(in.counters.mapped_as<char>() + kTileSortOffset, &state, sizeof(state));
  }
  return in;
}

SortedPairs read_sorted(const KeyBuffers& buffers, bool in_alt, uint32_t n) {
  SortedPairs got;
  got.positions.resize(n);
  std::vector<uint8_t> keys(size_t(n) * buffers.key_bytes());
  if (n > 0) {
    vk::Context& ctx = sort_test_context();
    vk::Buffer staging(ctx, keys.size() + n * 4ull, vk::MemoryUse::Readback, "test readback");
    ctx.submit_and_wait([&](VkCommandBuffer cmd) {
      const VkBufferCopy key_region{0, 0, keys.size()};
      const VkBufferCopy value_region{0, keys.size(), n * 4ull};
      vkCmdCopyBuffer(cmd, (in_alt ? buffers.keys_alt : buffers.keys).handle(), staging.handle(), 1, &key_region);
      vkCmdCopyBuffer(cmd, (in_alt ? buffers.values_alt : buffers.values).handle(), staging.handle(), 1,
                      &value_region);
    });
    std::memcpy(keys.data(), staging.mapped(), keys.size());
    std::memcpy(got.positions.data(), staging.mapped_as<char>() + keys.size(), n * 4ull);
  }
  for (auto& v : got.positions) v = position_of(v);
  got.keys = buffers.unpack_keys(keys.data(), n);
  return got;
}

SortedPairs sort_on_device(SortStrategy& sorter, const std::vector<uint64_t>& keys, uint32_t key_bits,
                           uint32_t capacity) {
  DeviceSortInput in = upload_sort_input(keys, key_bits, capacity);
  sorter.reserve(in.buffers.capacity);
  vk::CommandStream stream(sort_test_context());
  SortInput input = in.input(key_bits);
  const bool in_alt = sorter.record(stream, input);
  stream.finish();
  return read_sorted(in.buffers, in_alt, in.count);
}

void expect_order(const std::vector<uint64_t>& keys, const std::vector<uint32_t>& expected, const SortedPairs& got,
                  const std::string& what) {
  ASSERT_EQ(got.positions.size(), expected.size()) << what;
  ASSERT_EQ(got.keys.size(), expected.size()) << what;
  size_t mismatches = 0;
  for (size_t i = 0; i < expected.size(); ++i) {
    if (got.positions[i] != expected[i] || got.keys[i] != keys[expected[i]]) {
      if (++mismatches <= 5)
        ADD_FAILURE() << what << " n=" << keys.size() << ": position " << i << " has index " << got.positions[i]
                      << " (key " << got.keys[i] << "), expected index " << expected[i] << " (key "
                      << keys[expected[i]] << ")";
    }
  }
  EXPECT_EQ(mismatches, 0u) << what;
  EXPECT_EQ(sort_test_context().validation_messages(), 0u) << what;
}

}  // namespace tilesplat::testing
