// The tile-local sort alone against std::stable_sort (its bins, the shared-memory and the big-bin
// paths, every key layout), and in a frame against the radix sort, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>

#include "sort/tile_local_sort.h"
#include "sort_test_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "vulkan/context.h"

namespace tilesplat {
namespace {

using namespace testing;

std::unique_ptr<SortStrategy>& strategy() {
  static std::unique_ptr<SortStrategy> sorter = make_sort_strategy("tile-local", sort_test_context());
  return sorter;
}

// Sorts in buffers of `capacity` keys (the count stays n, as in a frame whose buffers are larger than
// its pairs) and checks against std::stable_sort.
void expect_stable_sort(const std::vector<uint64_t>& keys, uint32_t key_bits, uint32_t capacity = 0) {
  expect_stable_order(keys, sort_on_device(*strategy(), keys, key_bits, capacity),
                      "bits=" + std::to_string(key_bits) + " capacity=" + std::to_string(capacity));
}

// Keys like a frame's: a few tile ids in the high word (so bins far larger than shared memory), a
// depth in the low word drawn from few values (many equal keys).
std::vector<uint64_t> tile_keys(size_t n, uint32_t tiles, uint32_t depths, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<uint64_t> keys(n);
  for (auto& k : keys) k = (rng() % tiles) << 32 | uint64_t(0x3f800000u + uint32_t(rng() % depths) * 977u);
  return keys;
}

TEST(TileLocalSort, IsRegisteredAndSortsTileDepthPairsInFrames) {
  EXPECT_EQ(strategy()->name(), "tile-local");
  EXPECT_EQ(strategy()->frame_plan(), FrameSortPlan::kTileDepthPairs);
  const auto names = available_sort_strategies();
  EXPECT_NE(std::find(names.begin(), names.end(), "tile-local"), names.end());
}

TEST(TileLocalSort, BinsOnTheTileIdAndKeepsLocalKeysNarrowWhenItCan) {
  // A 1080p frame: 13 tile bits above 32 depth bits.
  EXPECT_EQ(TileLocalSort::binning_for(45, 1900000).bin_bits, 13u);
  EXPECT_EQ(TileLocalSort::binning_for(45, 1900000).shift, 32u);
  EXPECT_EQ(TileLocalSort::binning_for(32, 1u << 20).bin_bits, 12u);
  EXPECT_EQ(TileLocalSort::binning_for(3, 1u << 20).bin_bits, 3u);  // never more bins than keys values
  EXPECT_EQ(TileLocalSort::binning_for(1, 1).bin_bits, 1u);
  EXPECT_EQ(TileLocalSort::binning_for(64, 100).shift, 48u);  // the 2^16 bins limit: wide local keys
}

class TileLocalSortSizes : public ::testing::TestWithParam<uint32_t> {};

TEST_P(TileLocalSortSizes, MatchesStableSortOn45And32BitKeys) {
  const uint32_t n = GetParam();
  expect_stable_sort(random_keys(n, 45, n), 45);
  expect_stable_sort(random_keys(n, 32, n + 1), 32);
}

INSTANTIATE_TEST_SUITE_P(Sizes, TileLocalSortSizes,
                         ::testing::Values(0u, 1u, 2u, 15u, 16u, 17u, 255u, 256u, 257u, 2047u, 2048u, 2049u,
                                           (1u << 16) + 1, 1u << 20, 1u << 22));

TEST(TileLocalSort, BinsLargerThanSharedMemory) {
  // 3 tiles: bins of about 30000 keys, sorted in global memory, with many equal depths.
  expect_stable_sort(tile_keys(100000, 3, 50, 1), 45);
  // Every size around the shared capacity and the network's powers of two, in one bin each.
  const uint32_t cap = dynamic_cast<TileLocalSort&>(*strategy()).shared_capacity(false);
  for (uint32_t m : {cap - 1, cap, cap + 1, 2 * cap - 1, 2 * cap + 17, 5 * cap + 3})
    expect_stable_sort(tile_keys(m, 1, 1000, m), 33);
  // A frame-like mix: most tiles small, a few far over the capacity.
  std::vector<uint64_t> keys = tile_keys(60000, 2000, 1u << 20, 5);
  const std::vector<uint64_t> big = tile_keys(20000, 3, 1u << 20, 6);
  keys.insert(keys.begin() + 1000, big.begin(), big.end());
  expect_stable_sort(keys, 43);
}

TEST(TileLocalSort, ManyFullBinsInOneWorkgroup) {
  // 2^17 keys of 41 bits make 512 bins (bin bits 9, local keys 32 bits) over 8 workgroups on
  // lavapipe, workgroup w taking bins w, w + 8, ...: the bins of workgroup 0, each at the shared
  // capacity, are the most work one workgroup gets, which must stay within lavapipe's loop limit.
  const uint32_t cap = dynamic_cast<TileLocalSort&>(*strategy()).shared_capacity(false);
  const uint32_t n = 1u << 17;
  ASSERT_EQ(TileLocalSort::binning_for(41, n).shift, 32u);
  std::mt19937_64 rng(11);
  std::vector<uint64_t> keys(n);
  for (uint32_t i = 0; i < n; ++i) {
    const uint64_t bin = std::min<uint64_t>(i / cap, 63) * 8;
    keys[i] = bin << 32 | (rng() & 0xffffffffu);
  }
  std::shuffle(keys.begin(), keys.end(), rng);
  expect_stable_sort(keys, 41);
}

TEST(TileLocalSort, EqualKeysKeepInputOrder) {
  expect_stable_sort(std::vector<uint64_t>(50000, 12345), 45);
  expect_stable_sort(std::vector<uint64_t>(50000, 7), 32);
  expect_stable_sort(std::vector<uint64_t>(3000, 0), 1);
  std::vector<uint64_t> few = random_keys(100000, 45, 7);
  for (auto& k : few) k %= 5;
  expect_stable_sort(few, 45);
  for (auto& k : few) k <<= 40;  // equal within few bins; all local keys 0
  expect_stable_sort(few, 45);
}

TEST(TileLocalSort, EveryKeyWidthAndLayout) {
  for (uint32_t bits : {1u, 5u, 9u, 16u, 31u, 32u, 33u, 40u, 48u, 49u, 56u, 63u, 64u})
    expect_stable_sort(random_keys(20000, bits, bits), bits);
  // Wide local keys (over 48 key bits) with bins over the shared capacity, and equal high parts.
  std::vector<uint64_t> keys = random_keys(30000, 64, 3);
  for (auto& k : keys) k = (k & 0xffff00000000ffffull) % 7 | (k & 0x0000ff0000000000ull);
  expect_stable_sort(keys, 64);
}

TEST(TileLocalSort, CountBelowTheBufferCapacity) {
  // A frame's key buffers are larger than its pairs: keys past the count are neither sorted nor touched.
  expect_stable_sort(random_keys(30000, 45, 9), 45, 100000);
  expect_stable_sort(random_keys(1, 32, 9), 32, 5000);
}

TEST(TileLocalSort, FrameImageEqualsRadixBitForBit) {
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(load_ply(testing::bundled_playbot()));
  const auto views = load_cameras_json(testing::bundled_playbot_cameras());
  for (size_t view : {size_t(0), size_t(3)}) {
    const Camera camera = resize_camera(views.at(view).camera, 640, 360);
    RenderSettings settings;
    settings.sort = "radix";
    const RenderImage radix = renderer.render(camera, settings);
    settings.sort = "tile-local";
    const RenderImage tile_local = renderer.render(camera, settings);
    const FrameStats& stats = renderer.last_frame_stats();
    EXPECT_GT(stats.intersections, 10000u);
    std::vector<std::string> passes;
    for (const auto& p : stats.passes) passes.push_back(p.name);
    EXPECT_EQ(std::count(passes.begin(), passes.end(), "depth_sort"), 0) << "the pairs are sorted once";
    EXPECT_TRUE(radix.rgba == tile_local.rgba) << "view " << view;
    EXPECT_TRUE(radix.depth == tile_local.depth) << "view " << view;
    EXPECT_TRUE(radix.splat_count == tile_local.splat_count) << "view " << view;
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

}  // namespace
}  // namespace tilesplat
