// The sort strategies and the prefix sum alone, against std::stable_sort / std::exclusive_scan, on the
// device the tests run on (lavapipe in CI), with the validation layer on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>

#include "passes/frame_counters.h"
#include "passes/prefix_sum_pass.h"
#include "sort/sort_strategy.h"
#include "vulkan/context.h"

namespace tilesplat {
namespace {

vk::Context& context() {
  static vk::Context ctx({"", true});
  return ctx;
}

template <typename T>
std::vector<T> read_back(vk::Context& ctx, const vk::Buffer& buffer, size_t count) {
  std::vector<T> out(count);
  if (count == 0) return out;
  vk::Buffer staging(ctx, count * sizeof(T), vk::MemoryUse::Readback, "test readback");
  ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, 0, count * sizeof(T)};
    vkCmdCopyBuffer(cmd, buffer.handle(), staging.handle(), 1, &region);
  });
  std::memcpy(out.data(), staging.mapped(), count * sizeof(T));
  return out;
}

// The payload of input position i: a bijection that does not follow the input order, as in the
// frame's tile sort (whose values are Gaussian indices in depth order). A strategy that broke ties
// by value instead of by input position would be caught.
uint32_t payload(uint32_t position) { return (position * 2654435761u) ^ 0x5bd1e995u; }
uint32_t position_of(uint32_t value) {
  // 2654435761 * 244002641 = 1 (mod 2^32): the inverse of the multiplication above.
  return (value ^ 0x5bd1e995u) * 244002641u;
}

// Sorts keys (values = payload(input position)) with a strategy and returns (keys, input positions)
// as the GPU left them.
std::pair<std::vector<uint64_t>, std::vector<uint32_t>> gpu_sort(const std::string& strategy,
                                                                  const std::vector<uint64_t>& keys,
                                                                  uint32_t key_bits) {
  vk::Context& ctx = context();
  const uint32_t n = uint32_t(keys.size());
  const uint32_t capacity = std::max<uint32_t>(n, 1);
  KeyBuffers kb = KeyBuffers::allocate(ctx, capacity, key_bits, "test");
  std::vector<uint32_t> values(n);
  for (uint32_t i = 0; i < n; ++i) values[i] = payload(i);
  const std::vector<uint8_t> packed = kb.pack_keys(keys);
  vk::upload(ctx, kb.keys, packed.data(), packed.size());
  vk::upload(ctx, kb.values, values.data(), n * 4ull);
  vk::Buffer counters(ctx, sizeof(FrameCounters), vk::MemoryUse::Readback, "counters");
  SortState state{};
  state.count = n;
  std::memcpy(static_cast<char*>(counters.mapped()) + kTileSortOffset, &state, sizeof(state));

  auto sorter = make_sort_strategy(strategy, ctx);
  sorter->reserve(capacity);
  vk::CommandStream stream(ctx);
  SortInput input{kb, counters, kTileSortOffset, key_bits};
  const bool in_alt = sorter->record(stream, input);
  stream.finish();
  std::vector<uint32_t> positions = read_back<uint32_t>(ctx, in_alt ? kb.values_alt : kb.values, n);
  for (auto& v : positions) v = position_of(v);
  const std::vector<uint8_t> sorted = read_back<uint8_t>(ctx, in_alt ? kb.keys_alt : kb.keys, size_t(n) * kb.key_bytes());
  return {kb.unpack_keys(sorted.data(), n), positions};
}

void expect_sorted_like_stable_sort(const std::string& strategy, const std::vector<uint64_t>& keys,
                                    uint32_t key_bits) {
  std::vector<uint32_t> expected_order(keys.size());
  std::iota(expected_order.begin(), expected_order.end(), 0u);
  std::stable_sort(expected_order.begin(), expected_order.end(),
                   [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
  auto [sorted_keys, order] = gpu_sort(strategy, keys, key_bits);
  ASSERT_EQ(order.size(), keys.size());
  size_t mismatches = 0;
  for (size_t i = 0; i < keys.size(); ++i) {
    if (order[i] != expected_order[i] || sorted_keys[i] != keys[expected_order[i]]) {
      if (++mismatches <= 5)
        ADD_FAILURE() << strategy << " n=" << keys.size() << ": position " << i << " has index " << order[i]
                      << " (key " << sorted_keys[i] << "), expected index " << expected_order[i] << " (key "
                      << keys[expected_order[i]] << ")";
    }
  }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(context().validation_messages(), 0u);
}

// The strategies that must give the exact stable order (cpu-radix16 quantizes: see
// test_cpu_radix_strategy.cpp).
std::vector<std::string> exact_strategies() {
  std::vector<std::string> names;
  for (const auto& name : available_sort_strategies())
    if (sort_strategy_exact(name)) names.push_back(name);
  return names;
}

std::vector<uint64_t> random_keys(size_t n, uint32_t bits, uint64_t seed, uint64_t distinct = 0) {
  std::mt19937_64 rng(seed);
  std::vector<uint64_t> keys(n);
  const uint64_t mask = bits >= 64 ? ~0ull : (1ull << bits) - 1;
  for (auto& k : keys) k = distinct ? (rng() % distinct) * 0x9e3779b97f4a7c15ull & mask : rng() & mask;
  return keys;
}

class GpuSortSizes : public ::testing::TestWithParam<size_t> {};

// 45-bit keys go through 64-bit key buffers, 32-bit keys through 32-bit ones (passes/key_buffers.h).
TEST_P(GpuSortSizes, MatchesStableSortOnRandom45And32BitKeys) {
  for (const auto& strategy : exact_strategies()) {
    expect_sorted_like_stable_sort(strategy, random_keys(GetParam(), 45, GetParam()), 45);
    expect_sorted_like_stable_sort(strategy, random_keys(GetParam(), 32, GetParam() + 1), 32);
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, GpuSortSizes,
                         ::testing::Values(0, 1, 2, 255, 256, 257, 2047, 2048, 2049, (1u << 16) + 1, 1u << 20));

TEST(GpuSort, ManyEqualKeysKeepInputOrder) {
  for (const auto& strategy : exact_strategies()) {
    expect_sorted_like_stable_sort(strategy, random_keys(100000, 45, 7, 3), 45);
    expect_sorted_like_stable_sort(strategy, std::vector<uint64_t>(50000, 12345), 45);
    expect_sorted_like_stable_sort(strategy, random_keys(100000, 32, 8, 5), 32);
  }
}

TEST(GpuSort, FullWidthAndNarrowKeys) {
  for (const auto& strategy : exact_strategies()) {
    expect_sorted_like_stable_sort(strategy, random_keys(30000, 64, 11), 64);
    expect_sorted_like_stable_sort(strategy, random_keys(30000, 32, 12), 32);
    expect_sorted_like_stable_sort(strategy, random_keys(30000, 9, 13), 9);
  }
}

TEST(PrefixSum, MatchesExclusiveScanAtBlockBoundaries) {
  vk::Context& ctx = context();
  PrefixSumPass scan(ctx);
  for (uint32_t n : {1u, 2u, 1023u, 1024u, 1025u, 4096u, 1048576u + 3u, 3000000u}) {
    std::mt19937 rng(n);
    std::vector<uint32_t> values(n);
    for (auto& v : values) v = uint32_t(rng() % 300);
    vk::Buffer src(ctx, n * 4ull, vk::MemoryUse::Device, "scan src");
    vk::Buffer dst(ctx, n * 4ull, vk::MemoryUse::Device, "scan dst");
    vk::Buffer total(ctx, 16, vk::MemoryUse::Readback, "scan total");
    vk::upload(ctx, src, values.data(), n * 4ull);
    ctx.submit_and_wait([&](VkCommandBuffer cmd) { scan.record(cmd, src.address(), dst.address(), n, total.address()); });
    std::vector<uint32_t> expected(n);
    std::exclusive_scan(values.begin(), values.end(), expected.begin(), 0u);
    auto got = read_back<uint32_t>(ctx, dst, n);
    size_t first_bad = n;
    for (size_t i = 0; i < n && first_bad == n; ++i)
      if (got[i] != expected[i]) first_bad = i;
    EXPECT_EQ(first_bad, n) << "n=" << n << " first mismatch at " << first_bad;
    EXPECT_EQ(*total.mapped_as<uint32_t>(), expected.back() + values.back()) << "n=" << n;
  }
  EXPECT_EQ(ctx.validation_messages(), 0u);
}

}  // namespace
}  // namespace tilesplat
