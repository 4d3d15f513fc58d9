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

#include "sort/onesweep_sort.h"
#include "sort_test_support.h"

namespace tilesplat {
namespace {

using namespace testing;

void expect_stable_order(OnesweepSort& sorter, const std::vector<uint64_t>& keys, uint32_t key_bits) {
  testing::expect_stable_order(keys, sort_on_device(sorter, keys, key_bits), "bits=" + std::to_string(key_bits));
}

TEST(OnesweepSort, ForcedFallbackMatchesStableSort) {
  OnesweepSort sorter(sort_test_context(), 0u);  // every partition counts its predecessor's keys itself
  ASSERT_EQ(sorter.spin_limit(), 0u);
  for (size_t n : {size_t(0), size_t(1), size_t(257), (size_t(1) << 16) + 1, size_t(1) << 20}) {
    for (uint32_t bits : {32u, 45u}) {
      SCOPED_TRACE(::testing::Message() << "n=" << n << " bits=" << bits);
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
  OnesweepSort sorter(sort_test_context(), OnesweepSort::kDefaultSpinLimit);
  OnesweepSort short_spin(sort_test_context(), 1u);
  // Long waits once ran out of lavapipe's loop budget and corrupted the order (see
  // onesweep_pass.comp); on a CPU driver the limit asked for is capped below that budget.
  OnesweepSort long_spin(sort_test_context(), 1000000u);
  if (sort_test_context().is_cpu_device()) {
    EXPECT_LT(long_spin.spin_limit(), 65535u);
  }
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
  EXPECT_EQ(OnesweepSort(sort_test_context()).spin_limit(), 17u);
  ASSERT_EQ(setenv("TILESPLAT_ONESWEEP_SPIN", "lots", 1), 0);
  EXPECT_THROW(OnesweepSort{sort_test_context()}, std::invalid_argument);
  ASSERT_EQ(unsetenv("TILESPLAT_ONESWEEP_SPIN"), 0);
  EXPECT_EQ(OnesweepSort(sort_test_context()).spin_limit(), OnesweepSort::kDefaultSpinLimit);
  EXPECT_EQ(OnesweepSort(sort_test_context(), 5u).spin_limit(), 5u);
  if (outer) setenv("TILESPLAT_ONESWEEP_SPIN", saved.c_str(), 1);
}

TEST(OnesweepSort, RejectsMoreKeysThanAStatusWordCounts) {
  OnesweepSort sorter(sort_test_context(), 1u);
  EXPECT_THROW(sorter.reserve(1u << 30), std::length_error);
}

}  // namespace
}  // namespace tilesplat

