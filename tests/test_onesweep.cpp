// The onesweep sort's stall fallback (sort/onesweep_sort.h): forced on every partition's predecessor,
// it must still give exactly std::stable_sort's order. The normal path is covered by the tests that
// run every registered strategy (test_gpu_sort.cpp, test_sort_api.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <numeric>
#include <random>
#include <string>

#include "passes/frame_counters.h"
#include "sort/onesweep_sort.h"
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

std::vector<uint64_t> random_keys(size_t n, uint32_t bits, uint64_t seed, uint64_t distinct = 0) {
  std::mt19937_64 rng(seed);
  std::vector<uint64_t> keys(n);
  const uint64_t mask = bits >= 64 ? ~0ull : (1ull << bits) - 1;
  for (auto& k : keys) k = distinct ? (rng() % distinct) * 0x9e3779b97f4a7c15ull & mask : rng() & mask;
  return keys;
}

// Sorts keys whose values are their input positions and checks keys and positions against
// std::stable_sort.
void expect_stable_order(OnesweepSort& sorter, const std::vector<uint64_t>& keys, uint32_t key_bits) {
  vk::Context& ctx = context();
  const uint32_t n = uint32_t(keys.size());
  const uint32_t capacity = std::max<uint32_t>(n, 1);
  KeyBuffers kb = KeyBuffers::allocate(ctx, capacity, key_bits, "onesweep test");
  std::vector<uint32_t> positions(n);
  std::iota(positions.begin(), positions.end(), 0u);
  const std::vector<uint8_t> packed = kb.pack_keys(keys);
  vk::upload(ctx, kb.keys, packed.data(), packed.size());
  vk::upload(ctx, kb.values, positions.data(), n * 4ull);
  vk::Buffer counters(ctx, sizeof(FrameCounters), vk::MemoryUse::Readback, "onesweep test counters");
  SortState state{};
  state.count = n;
  std::memcpy(static_cast<char*>(counters.mapped()) + kTileSortOffset, &state, sizeof(state));

  sorter.reserve(capacity);
  vk::CommandStream stream(ctx);
  SortInput input{kb, counters, kTileSortOffset, key_bits};
  const bool in_alt = sorter.record(stream, input);
  stream.finish();
  const auto order = read_back<uint32_t>(ctx, in_alt ? kb.values_alt : kb.values, n);
  const auto bytes = read_back<uint8_t>(ctx, in_alt ? kb.keys_alt : kb.keys, size_t(n) * kb.key_bytes());
  const auto sorted = kb.unpack_keys(bytes.data(), n);

  std::vector<uint32_t> expected(n);
  std::iota(expected.begin(), expected.end(), 0u);
  std::stable_sort(expected.begin(), expected.end(), [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
  size_t mismatches = 0;
  for (size_t i = 0; i < n; ++i) {
    if (order[i] != expected[i] || sorted[i] != keys[expected[i]]) {
      if (++mismatches <= 5)
        ADD_FAILURE() << "n=" << n << " bits=" << key_bits << ": position " << i << " has index " << order[i]
                      << " (key " << sorted[i] << "), expected " << expected[i] << " (key " << keys[expected[i]]
                      << ")";
    }
  }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(ctx.validation_messages(), 0u);
}

TEST(OnesweepSort, ForcedFallbackMatchesStableSort) {
  OnesweepSort sorter(context(), 0u);  // every partition counts its predecessor's keys itself
  ASSERT_EQ(sorter.spin_limit(), 0u);
  for (size_t n : {size_t(0), size_t(1), size_t(257), (size_t(1) << 16) + 1, size_t(1) << 20}) {
    for (uint32_t bits : {32u, 45u}) {
      SCOPED_TRACE(testing::Message() << "n=" << n << " bits=" << bits);
      const uint64_t before = sorter.fallbacks();
      expect_stable_order(sorter, random_keys(n, bits, n + bits), bits);
      // Each pass falls back at least once per partition after the first.
      const uint64_t partitions = (n + sorter.partition_keys() - 1) / sorter.partition_keys();
      const uint64_t passes = (bits + 7) / 8;
      EXPECT_GE(sorter.fallbacks() - before, passes * (partitions > 0 ? partitions - 1 : 0));
      expect_stable_order(sorter, random_keys(n, bits, n + bits + 2, 7), bits);  // many equal keys
    }
  }
  expect_stable_order(sorter, std::vector<uint64_t>(100000, 12345), 45);
  expect_stable_order(sorter, random_keys(100000, 13, 5, 40), 13);
}

// Any spin limit gives the same order; how often the default one falls back depends on the timing,
// so it is only reported.
TEST(OnesweepSort, DefaultSpinLimitMatchesStableSortAndReportsFallbacks) {
  OnesweepSort sorter(context(), OnesweepSort::kDefaultSpinLimit);
  OnesweepSort short_spin(context(), 1u);
  // Long waits once desynchronised the workgroup's barriers on lavapipe (see onesweep_pass.comp).
  OnesweepSort long_spin(context(), 1000000u);
  for (size_t n : {size_t(2049), size_t(1) << 20}) {
    expect_stable_order(sorter, random_keys(n, 32, n), 32);
    expect_stable_order(short_spin, random_keys(n, 45, n, 1000), 45);
    expect_stable_order(long_spin, random_keys(n, 8, n + 1), 8);
  }
  std::printf("onesweep fallbacks: %llu at spin limit %u, %llu at spin limit 1 (%u-key partitions)\n",
              static_cast<unsigned long long>(sorter.fallbacks()), sorter.spin_limit(),
              static_cast<unsigned long long>(short_spin.fallbacks()), sorter.partition_keys());
  RecordProperty("fallbacks", std::to_string(sorter.fallbacks()));
}

TEST(OnesweepSort, SpinLimitFromTheEnvironment) {
  const char* outer = std::getenv("TILESPLAT_ONESWEEP_SPIN");
  const std::string saved = outer ? outer : "";
  ASSERT_EQ(setenv("TILESPLAT_ONESWEEP_SPIN", "17", 1), 0);
  EXPECT_EQ(OnesweepSort(context()).spin_limit(), 17u);
  ASSERT_EQ(setenv("TILESPLAT_ONESWEEP_SPIN", "lots", 1), 0);
  EXPECT_THROW(OnesweepSort{context()}, std::invalid_argument);
  ASSERT_EQ(unsetenv("TILESPLAT_ONESWEEP_SPIN"), 0);
  EXPECT_EQ(OnesweepSort(context()).spin_limit(), OnesweepSort::kDefaultSpinLimit);
  EXPECT_EQ(OnesweepSort(context(), 5u).spin_limit(), 5u);
  if (outer) setenv("TILESPLAT_ONESWEEP_SPIN", saved.c_str(), 1);
}

TEST(OnesweepSort, RejectsMoreKeysThanAStatusWordCounts) {
  OnesweepSort sorter(context(), 1u);
  EXPECT_THROW(sorter.reserve(1u << 30), std::length_error);
}

}  // namespace
}  // namespace tilesplat

