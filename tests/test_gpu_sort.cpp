// The sort strategies and the prefix sum alone, against std::stable_sort / std::exclusive_scan, on the
// device the tests run on (lavapipe in CI), with the validation layer on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <numeric>
#include <random>

#include "passes/prefix_sum_pass.h"
#include "sort_test_support.h"

namespace tilesplat {
namespace {

using namespace testing;

// The strategies that must give the exact stable order (cpu-radix16 quantizes: see
// test_cpu_radix_strategy.cpp).
std::vector<std::string> exact_strategies() {
  std::vector<std::string> names;
  for (const auto& name : available_sort_strategies())
    if (sort_strategy_exact(name)) names.push_back(name);
  return names;
}

void expect_sorted_like_stable_sort(const std::string& strategy, const std::vector<uint64_t>& keys,
                                    uint32_t key_bits) {
  const auto sorter = make_sort_strategy(strategy, sort_test_context());
  expect_stable_order(keys, sort_on_device(*sorter, keys, key_bits), strategy + " bits=" + std::to_string(key_bits));
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

// CPU drivers sort through texel buffers (vk::texel_buffers_wanted), GPUs through buffer addresses:
// on lavapipe both layouts run here, at the block boundaries and with many equal keys, and must give
// the stable order, with the validation layer silent.
TEST(GpuSort, RadixTexelAndAddressLayoutsBothSortStably) {
  for (const char* texel_buffers : {"0", "1"}) {
    ::setenv("TILESPLAT_TEXEL_BUFFERS", texel_buffers, 1);
    const auto sorter = make_sort_strategy("radix", sort_test_context());
    ::unsetenv("TILESPLAT_TEXEL_BUFFERS");
    const std::string label = std::string("radix, texel buffers ") + texel_buffers;
    for (const auto& [keys, bits] :
         {std::pair{random_keys(2049, 32, 31), 32u}, std::pair{random_keys(300000, 32, 32), 32u},
          std::pair{random_keys(300000, 64, 33), 64u}, std::pair{random_keys(100000, 45, 34, 3), 45u}})
      expect_stable_order(keys, sort_on_device(*sorter, keys, bits), label + " bits=" + std::to_string(bits));
  }
  EXPECT_EQ(sort_test_context().validation_messages(), 0u);
}

TEST(PrefixSum, MatchesExclusiveScanAtBlockBoundaries) {
  vk::Context& ctx = sort_test_context();
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
    auto got = read_back<uint32_t>(dst, n);
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
