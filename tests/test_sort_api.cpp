// The public sort entry points: Renderer::sort_keys (every GPU strategy, outside a frame) and the
// CPU radix sort the micro-benchmark compares them with. Both against std::stable_sort.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <random>

#include "sort_test_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"
#include "tilesplat/sort.h"

namespace tilesplat {
namespace {

using testing::random_keys;
using testing::stable_order;

TEST(CpuRadixSort, MatchesStableSort) {
  for (uint32_t bits : {1u, 9u, 32u, 45u, 64u}) {
    for (size_t n : {size_t(0), size_t(1), size_t(257), size_t(100000)}) {
      const auto keys = random_keys(n, bits, n + bits, n > 1000 ? 50 : 0);
      std::vector<uint64_t> sorted = keys;
      std::vector<uint32_t> order(n);
      std::iota(order.begin(), order.end(), 0u);
      cpu_radix_sort(sorted, order, bits);
      EXPECT_EQ(order, stable_order(keys)) << "bits " << bits << " n " << n;
      EXPECT_TRUE(std::is_sorted(sorted.begin(), sorted.end()));
    }
  }
  std::vector<uint64_t> keys(3);
  std::vector<uint32_t> values(2);
  EXPECT_THROW(cpu_radix_sort(keys, values, 8), std::invalid_argument);
}

TEST(SortKeys, EveryStrategyMatchesStableSortAndReportsItsTime) {
  Renderer& renderer = testing::validated_renderer();
  const auto keys = random_keys(70000, 45, 3, 1000);  // many equal keys
  const auto expected = stable_order(keys);
  for (const auto& strategy : sort_strategies()) {
    if (!sort_strategy_is_exact(strategy)) continue;  // its order: test_cpu_radix_strategy.cpp
    const Renderer::SortRun run = renderer.sort_keys(strategy, keys, 45);
    EXPECT_EQ(run.order, expected) << strategy;
    ASSERT_EQ(run.keys.size(), keys.size());
    for (size_t i = 0; i < keys.size(); ++i) ASSERT_EQ(run.keys[i], keys[expected[i]]) << strategy << " at " << i;
    EXPECT_GT(run.gpu_ms, 0.0) << strategy;
  }
  EXPECT_TRUE(renderer.sort_keys("radix", {}, 32).keys.empty());
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// The forward-progress cost is visible through the public API: with the spin limit at 0 every
// onesweep look-back on an unpublished predecessor falls back, and the run reports it; strategies
// that never wait report none.
TEST(SortKeys, ReportsOnesweepStallFallbacks) {
  auto renderer = Renderer::create({});  // its own: the strategy reads the limit when first used
  const auto keys = random_keys(200000, 32, 11);
  ::setenv("TILESPLAT_ONESWEEP_SPIN", "0", 1);
  const Renderer::SortRun forced = renderer->sort_keys("onesweep", keys, 32);
  ::unsetenv("TILESPLAT_ONESWEEP_SPIN");
  EXPECT_EQ(forced.order, stable_order(keys));
  EXPECT_GT(forced.fallbacks, 0u);
  EXPECT_EQ(renderer->sort_keys("radix", keys, 32).fallbacks, 0u);
}

// The keys a frame sorts, from a real scene: the float bits of each Gaussian's view depth (as the
// projection writes them), the same depths quantized to 16 bits over their range (many equal keys,
// as in viewers that sort 16-bit depths), and 13-bit tile ids of a 1080p grid taken from the
// Gaussians' screen positions (runs of equal keys of every length).
TEST(SortKeys, RealSceneKeysMatchStableSort) {
  Renderer& renderer = testing::validated_renderer();
  const GaussianScene scene = load_ply(testing::bundled_playbot());
  const Camera camera = resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(0).camera, 1920, 1080);
  const size_t n = scene.size();
  std::vector<float> depth(n);
  std::vector<uint64_t> depth_bits(n), depth16(n), tile_ids(n);
  float near = 1e30f, far = 0;
  for (size_t i = 0; i < n; ++i) {
    const auto p = camera.to_camera({scene.positions[3 * i], scene.positions[3 * i + 1], scene.positions[3 * i + 2]});
    depth[i] = float(p[2]);
    depth_bits[i] = depth[i] > 0 ? std::bit_cast<uint32_t>(depth[i]) : 0xffffffffu;
    if (depth[i] > 0) near = std::min(near, depth[i]), far = std::max(far, depth[i]);
    const double u = p[2] > 0 ? camera.fx * p[0] / p[2] + camera.cx : -1;
    const double v = p[2] > 0 ? camera.fy * p[1] / p[2] + camera.cy : -1;
    const bool on_screen = u >= 0 && v >= 0 && u < camera.width && v < camera.height;
    tile_ids[i] = on_screen ? uint64_t(v / 16) * 120 + uint64_t(u / 16) : 120 * 68;
  }
  ASSERT_LT(near, far);
  for (size_t i = 0; i < n; ++i)
    depth16[i] = depth[i] > 0 ? uint64_t(std::lround((depth[i] - near) / (far - near) * 65535.0)) : 65535;

  struct Case {
    const char* name;
    const std::vector<uint64_t>& keys;
    uint32_t bits;
  };
  for (const Case& c : {Case{"depth bits", depth_bits, 32}, Case{"16-bit depth", depth16, 16},
                        Case{"tile ids", tile_ids, 13}}) {
    const auto expected = stable_order(c.keys);
    for (const auto& strategy : sort_strategies()) {
      if (!sort_strategy_is_exact(strategy)) continue;
      const Renderer::SortRun run = renderer.sort_keys(strategy, c.keys, c.bits);
      EXPECT_EQ(run.order, expected) << strategy << ", " << c.name;
    }
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(SortKeys, RejectsKeysWiderThanTheKeyBitsAndUnknownStrategies) {
  Renderer& renderer = testing::validated_renderer();
  EXPECT_THROW(renderer.sort_keys("radix", {1, 2, 1ull << 40}, 32), std::invalid_argument);
  EXPECT_THROW(renderer.sort_keys("radix", {1}, 0), std::invalid_argument);
  EXPECT_THROW(renderer.sort_keys("radix", {1}, 65), std::invalid_argument);
  EXPECT_THROW(renderer.sort_keys("no-such-sort", {1}, 8), std::invalid_argument);
}

TEST(SortStrategies, GiveBitIdenticalImages) {
  // Every exact strategy gives the same order, so every output of a real scene is identical to the
  // bit. An inexact one (cpu-radix16: 16-bit depths) swaps Gaussians whose depths share a level;
  // its colour is held to 40 dB PSNR against the exact image instead.
  constexpr double kInexactMinPsnrDb = 40;
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(load_ply(testing::bundled_playbot()));
  const Camera camera = resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(3).camera, 320, 180);
  RenderSettings settings;
  const RenderImage first = renderer.render(camera, settings);
  ASSERT_GT(renderer.last_frame_stats().intersections, 10000u);
  for (const auto& strategy : sort_strategies()) {
    settings.sort = strategy;
    const RenderImage image = renderer.render(camera, settings);
    if (!sort_strategy_is_exact(strategy)) {
      const double psnr = compare_images(image, first).psnr_db;
      std::printf("%s: %.2f dB PSNR against the exact image\n", strategy.c_str(), psnr);
      EXPECT_GE(psnr, kInexactMinPsnrDb) << strategy;
      continue;
    }
    EXPECT_EQ(image.rgba, first.rgba) << strategy;
    EXPECT_EQ(image.depth, first.depth) << strategy;
    EXPECT_EQ(image.splat_count, first.splat_count) << strategy;
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

}  // namespace
}  // namespace tilesplat
