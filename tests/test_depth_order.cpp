// The host's depth order of a scene rendered in parts (engine/src/frame/scene_parts.h): the order, the
// boundaries where a part may end, the parts' indices and the budget's arithmetic, without a device.
#include <gtest/gtest.h>

#include <bit>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "frame/scene_parts.h"
#include "sort/parallel_radix_sort.h"
#include "test_support.h"
#include "tilesplat/sort.h"

namespace tilesplat {
namespace {

// Gaussians on the camera's axis (the axis camera looks down +z from the origin) at these depths.
GaussianScene on_axis(const std::vector<float>& depths) {
  GaussianScene scene;
  for (float z : depths) {
    scene.positions.insert(scene.positions.end(), {0.0f, 0.0f, z});
    scene.log_scales.insert(scene.log_scales.end(), {-3.0f, -3.0f, -3.0f});
    scene.rotations.insert(scene.rotations.end(), {1.0f, 0.0f, 0.0f, 0.0f});
    scene.opacity_logits.push_back(1.0f);
    scene.sh.insert(scene.sh.end(), {0.5f, 0.25f, float(scene.size())});
  }
  return scene;
}

TEST(DepthOrder, SortsFrontToBackAndLeavesOutWhatIsBehindTheNearPlane) {
  const GaussianScene scene = on_axis({5, 1, -2, 3, 0.1f, 2});
  const DepthOrder order(PartSource(scene), testing::axis_camera(64, 64, 50), 0.2, 32, kDepthMarginFloat64);
  ASSERT_EQ(order.size(), 4u);  // -2 and 0.1 are behind the near plane (0.2)
  EXPECT_EQ(order.part_indices(0, 4), (std::vector<uint32_t>{0, 1, 3, 5}));  // ascending: the GPU's tie order
  // Front to back: 1 (index 1), 2 (5), 3 (3), 5 (0); each position alone is that Gaussian.
  EXPECT_EQ(order.part_indices(0, 1), std::vector<uint32_t>{1});
  EXPECT_EQ(order.part_indices(1, 2), std::vector<uint32_t>{5});
  EXPECT_EQ(order.part_indices(3, 4), std::vector<uint32_t>{0});
  for (size_t i = 1; i < 4; ++i) EXPECT_TRUE(order.boundary(i)) << i;
  EXPECT_FALSE(order.boundary(0));
  EXPECT_TRUE(order.boundary(4));
}

TEST(DepthOrder, NoBoundaryBetweenDepthsTheGpuMayOrderEitherWay) {
  // Equal depths tie (the GPU then orders by index, which parts cannot follow); depths one float apart
  // stay apart in a float64 projection, not in a float32 one.
  const float z = 3.0f;
  const float next = std::bit_cast<float>(std::bit_cast<uint32_t>(z) + 1);
  const GaussianScene scene = on_axis({z, 4.0f, next, z, 2.0f});
  const Camera camera = testing::axis_camera(64, 64, 50);
  const DepthOrder order(PartSource(scene), camera, 0.2, 32, kDepthMarginFloat64);
  ASSERT_EQ(order.size(), 5u);
  // 2 | 3, 3 | 3+ulp | 4
  EXPECT_TRUE(order.boundary(1));
  EXPECT_FALSE(order.boundary(2));
  EXPECT_TRUE(order.boundary(3));
  EXPECT_TRUE(order.boundary(4));
  EXPECT_FALSE(DepthOrder(PartSource(scene), camera, 0.2, 32, kDepthMarginFloat32).boundary(3));
  // A part asked to end inside the tie ends before it, or, starting in it, after it.
  EXPECT_EQ(order.part_end(0, 2), 1u);
  EXPECT_EQ(order.part_end(1, 1), 3u);
  EXPECT_EQ(order.part_end(0, 100), 5u);
}

TEST(DepthOrder, TheFloat32MarginAndTwentyFourBitKeysWidenTheGaps) {
  // 1e-6 apart at depth 3: apart in 32-bit keys of float64 depths, not within float32's margin.
  const GaussianScene scene = on_axis({3.0f, 3.000001f, 3.5f});
  const Camera camera = testing::axis_camera(64, 64, 50);
  EXPECT_TRUE(DepthOrder(PartSource(scene), camera, 0.2, 32, kDepthMarginFloat64).boundary(1));
  EXPECT_FALSE(DepthOrder(PartSource(scene), camera, 0.2, 32, kDepthMarginFloat32).boundary(1));
  // 24-bit keys drop 8 bits: 3 and 3.000001 share one.
  EXPECT_FALSE(DepthOrder(PartSource(scene), camera, 0.2, 24, kDepthMarginFloat64).boundary(1));
  EXPECT_TRUE(DepthOrder(PartSource(scene), camera, 0.2, 24, kDepthMarginFloat64).boundary(2));
  EXPECT_NE(testing::error_of<std::invalid_argument>([&] {
              DepthOrder(PartSource(scene), camera, 0.2, 16, kDepthMarginFloat64);
            }).find("24- or 32-bit depth keys"),
            std::string::npos);
}

TEST(DepthOrder, AFisheyeSortsByDistance) {
  // (0, 0, 2) is at distance 2; (3, 0, 1) at z 1 but distance sqrt(10).
  GaussianScene scene = on_axis({2.0f, 1.0f});
  scene.positions[3] = 3.0f;
  const Camera pinhole = testing::axis_camera(64, 64, 50);
  EXPECT_EQ(DepthOrder(PartSource(scene), pinhole, 0.2, 32, kDepthMarginFloat64).part_indices(0, 1),
            std::vector<uint32_t>{1});
  EXPECT_EQ(DepthOrder(PartSource(scene), fisheye_camera(pinhole, 180), 0.2, 32, kDepthMarginFloat64)
                .part_indices(0, 1),
            std::vector<uint32_t>{0});
}

// Spread over threads, the order and its boundaries are one thread's, bit for bit: ranges that cull
// differently, keys that tie across ranges, more threads than the host has.
TEST(DepthOrder, AnyNumberOfThreadsGivesOneThreadsOrder) {
  std::vector<float> depths;
  uint32_t state = 12345;
  for (int i = 0; i < 100003; ++i) {
    state = state * 1664525u + 1013904223u;
    depths.push_back(-1.0f + float(state >> 22) / 64.0f);  // -1 to 15 in steps of 1/64: many ties
  }
  const GaussianScene scene = on_axis(depths);
  const Camera camera = testing::axis_camera(64, 64, 50);
  for (const int bits : {32, 24})
    for (const double margin : {kDepthMarginFloat64, kDepthMarginFloat32}) {
      const DepthOrder one(PartSource(scene), camera, 0.2, bits, margin, 1);
      ASSERT_GT(one.size(), 80000u);
      ASSERT_LT(one.size(), depths.size());  // some are behind the near plane
      // Depths 1/64 apart are far beyond either margin and the 24-bit keys' step, so a part may end
      // exactly where the depth changes: a check of the order's own, whatever computed it.
      size_t wrong_boundaries = 0;
      for (size_t i = 1; i < one.size(); ++i) {
        EXPECT_LE(depths[one.index(i - 1)], depths[one.index(i)]);
        wrong_boundaries += one.boundary(i) != (depths[one.index(i - 1)] != depths[one.index(i)]);
      }
      EXPECT_EQ(wrong_boundaries, 0u) << bits << "-bit keys";
      for (const unsigned threads : {2u, 3u, 7u, 16u}) {
        const DepthOrder many(PartSource(scene), camera, 0.2, bits, margin, threads);
        ASSERT_EQ(many.size(), one.size());
        size_t different = 0;
        for (size_t i = 0; i < one.size(); ++i)
          different += many.index(i) != one.index(i) || many.boundary(i + 1) != one.boundary(i + 1);
        EXPECT_EQ(different, 0u) << threads << " threads, " << bits << "-bit keys";
      }
    }
}

// The depth order's sort: cpu_radix_sort's result for any number of threads, stable (the values are
// the keys' first positions, so a tie out of order shows).
TEST(ParallelRadixSort, IsTheOneThreadSortForAnyNumberOfThreads) {
  uint32_t state = 99;
  for (const size_t n : {size_t(0), size_t(1), size_t(5), size_t(1000), size_t(100003)})
    for (const uint32_t bits : {32u, 24u, 9u}) {
      std::vector<uint32_t> keys(n), values(n);
      for (size_t i = 0; i < n; ++i) {
        state = state * 1664525u + 1013904223u;
        keys[i] = (state >> 8) & ((bits == 32 ? 0u : (1u << bits)) - 1u);  // the low `bits` bits
        values[i] = uint32_t(i);
      }
      std::vector<uint32_t> expected_keys = keys, expected_values = values, ks(n), vs(n);
      if (cpu_radix_sort(std::span(expected_keys), std::span(expected_values), std::span(ks), std::span(vs),
                         bits)) {
        expected_keys.swap(ks);
        expected_values.swap(vs);
      }
      for (const unsigned threads : {1u, 2u, 3u, 8u, 64u}) {
        std::vector<uint32_t> k = keys, v = values, k2(n), v2(n);
        if (detail::parallel_radix_sort(std::span(k), std::span(v), std::span(k2), std::span(v2), bits,
                                        threads)) {
          k.swap(k2);
          v.swap(v2);
        }
        EXPECT_EQ(k, expected_keys) << n << " keys of " << bits << " bits, " << threads << " threads";
        EXPECT_EQ(v, expected_values) << n << " keys of " << bits << " bits, " << threads << " threads";
      }
    }
  std::vector<uint32_t> keys(4), values(3), scratch(4);
  EXPECT_THROW(detail::parallel_radix_sort(std::span(keys), std::span(values), std::span(scratch),
                                           std::span(scratch), 32, 2),
               std::invalid_argument);
}

TEST(PartSizing, GatherKeepsEveryAttributeOfTheIndices) {
  GaussianScene scene = on_axis({1, 2, 3});
  scene.normals = {0, 0, 1, 0, 1, 0, 1, 0, 0};
  const std::vector<uint32_t> indices = {2, 0};
  const GaussianScene part = gather_gaussians(scene, indices);
  ASSERT_EQ(part.size(), 2u);
  EXPECT_EQ(part.positions, (std::vector<float>{0, 0, 3, 0, 0, 1}));
  EXPECT_EQ(part.sh, (std::vector<float>{0.5f, 0.25f, 3, 0.5f, 0.25f, 1}));
  EXPECT_EQ(part.normals, (std::vector<float>{1, 0, 0, 0, 0, 1}));
  EXPECT_EQ(part.log_scales.size(), 6u);
  EXPECT_EQ(part.rotations.size(), 8u);
  EXPECT_EQ(part.sh_degree, scene.sh_degree);
}

TEST(PartSizing, CapacityIsTheBudgetOverTheCostsOrAClearError) {
  const PartCosts costs{1000, 100, 10};
  EXPECT_EQ(part_capacity(1000 + 200 + 1500, costs, 200, 5.0), 10u);  // 1500 / (100 + 5 * 10)
  const std::string error =
      testing::error_of<std::invalid_argument>([&] { part_capacity(1100, costs, 50, 5.0); });
  EXPECT_NE(error.find("leaves no room for a Gaussian"), std::string::npos) << error;
  EXPECT_NE(error.find("150 bytes per Gaussian"), std::string::npos) << error;
}

TEST(PartSizing, NoBufferOfAPartPassesTheLargestAllocation) {
  PartCosts costs{1000, 100, 10};
  costs.largest_per_gaussian = 64;
  costs.largest_per_pair = 4;
  costs.invocations_per_gaussian = 2;
  const DeviceCapacity device{6400, UINT64_MAX, 1};
  EXPECT_EQ(part_capacity(1ull << 40, costs, 0, 4.0, device), 100u);  // 6400 / 64
  EXPECT_EQ(part_capacity(1ull << 40, costs, 0, 40.0, device), 39u);  // (6400 / 4 - 1) / 40
  EXPECT_EQ(part_capacity(1000 + 1500, costs, 0, 5.0, device), 10u);  // the budget's 10 are fewer
  EXPECT_EQ(part_capacity(1ull << 40, costs, 0, 4.0, {1 << 20, UINT64_MAX, 1}), 128u);  // 256 / 2 a dispatch
  const std::string error = testing::error_of<std::invalid_argument>([&] {
    part_capacity(1ull << 40, costs, 0, 4.0, {32, UINT64_MAX, 1});
  });
  EXPECT_NE(error.find("largest allocation (32 bytes) cannot hold the buffers of one Gaussian"),
            std::string::npos)
      << error;
}

TEST(PartSizing, AWholeFrameFitsTheDeviceOrIsSplit) {
  PartCosts costs{1000, 100, 10};
  costs.largest_per_gaussian = 64;
  costs.largest_per_pair = 4;
  costs.invocations_per_gaussian = 1;
  const DeviceCapacity roomy{1ull << 30, 1ull << 34};
  EXPECT_TRUE(whole_frame_fits(costs, 1000, 4.0, roomy));
  EXPECT_EQ(device_frame_budget(roomy), 3ull << 32);
  // The largest per-Gaussian buffer: 64 bytes each.
  EXPECT_TRUE(whole_frame_fits(costs, 1000, 4.0, {64000, 1ull << 34}));
  EXPECT_FALSE(whole_frame_fits(costs, 1001, 4.0, {64000, 1ull << 34}));
  // The key buffers: 4,000 pairs with a quarter's headroom make 8,192, at 4 bytes each.
  costs.largest_per_gaussian = 16;
  EXPECT_TRUE(whole_frame_fits(costs, 1000, 4.0, {32768, 1ull << 34}));
  EXPECT_FALSE(whole_frame_fits(costs, 1000, 4.0, {32767, 1ull << 34}));
  // Each dispatch within the device's workgroups: 1000 invocations are 4 workgroups of 256.
  EXPECT_TRUE(whole_frame_fits(costs, 1000, 4.0, {1ull << 30, 1ull << 34, 4}));
  EXPECT_FALSE(whole_frame_fits(costs, 1000, 4.0, {1ull << 30, 1ull << 34, 3}));
  // All of it within 3/4 of the device's memory: 1000 + 1000 * (100 + 4 * 10) = 141,000 bytes.
  EXPECT_TRUE(whole_frame_fits(costs, 1000, 4.0, {1ull << 30, 188000}));
  EXPECT_FALSE(whole_frame_fits(costs, 1000, 4.0, {1ull << 30, 187999}));
}

TEST(PartSizing, CostsFollowTheFrame) {
  const GaussianScene scene = on_axis({1, 2});
  const Camera camera = testing::axis_camera(32, 16, 50);
  RenderSettings settings;
  const PartCosts plain = part_costs(PartSource(scene), camera, settings, 1, false);
  // Colour, depth, counts and two 32-byte halves of state per pixel; two tiles of ranges.
  EXPECT_EQ(plain.fixed, 32u * 16u * (16 + 4 + 4 + 64) + 2 * 8);
  settings.depth = false;
  settings.splat_count = false;
  EXPECT_EQ(part_costs(PartSource(scene), camera, settings, 1, false).fixed, 32u * 16u * (16 + 64) + 2 * 8);
  const PartCosts seams = part_costs(PartSource(scene), camera, settings, 2, true);
  EXPECT_GT(seams.per_gaussian, plain.per_gaussian);
  EXPECT_GT(seams.per_pair, plain.per_pair);
  // The largest buffers: the projected splats (64 bytes a record, two records a Gaussian with seam
  // copies), and a key buffer (wide keys: 8 bytes a pair).
  EXPECT_EQ(plain.largest_per_gaussian, 64u);
  EXPECT_EQ(plain.largest_per_pair, 4u);
  EXPECT_EQ(seams.largest_per_gaussian, 128u);
  EXPECT_EQ(seams.largest_per_pair, 8u);
  EXPECT_EQ(plain.invocations_per_gaussian, 1u);
  EXPECT_EQ(seams.invocations_per_gaussian, 2u);
}

}  // namespace
}  // namespace tilesplat
