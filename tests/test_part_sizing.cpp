// How big a scene's parts are (frame/part_sizing.h), without a device: whether a frame needs parts under a
// budget or the device's limits, and how the part capacity follows what the parts before measured.
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>

#include "frame/part_sizing.h"

namespace tilesplat {
namespace {

// 1,000 bytes before any Gaussian, 100 per Gaussian, 10 per pair: a whole frame of n Gaussians with the
// first guess of 4 pairs each holds 1,000 + 140 n bytes.
PartCosts small_costs() {
  PartCosts costs;
  costs.fixed = 1000;
  costs.per_gaussian = 100;
  costs.per_pair = 10;
  return costs;
}

TEST(FrameNeedsParts, PastItsBudget) {
  const PartCosts costs = small_costs();
  const DeviceCapacity roomy;                                 // no limit
  EXPECT_FALSE(frame_needs_parts(costs, 100, 15000, roomy));  // exactly 15,000 bytes
  EXPECT_TRUE(frame_needs_parts(costs, 100, 14999, roomy));
  EXPECT_FALSE(frame_needs_parts(costs, 100, 0, roomy));  // no budget: the device's, which is unlimited
}

TEST(FrameNeedsParts, PastTheDevicesLargestAllocationUnderAnyBudget) {
  PartCosts costs = small_costs();
  costs.largest_per_gaussian = 64;  // e.g. the spherical harmonics
  DeviceCapacity device;
  device.largest_allocation = 64 * 99;  // one Gaussian short of the frame's 100
  EXPECT_TRUE(frame_needs_parts(costs, 100, 1u << 30, device));
  device.largest_allocation = 64 * 100;
  EXPECT_FALSE(frame_needs_parts(costs, 100, 1u << 30, device));
  // Without a budget, the device's memory counts too: three quarters of it (kDeviceMemoryShare).
  device.total = 20000;  // 15,000 bytes for the frame
  EXPECT_FALSE(frame_needs_parts(costs, 100, 0, device));
  device.total = 19999;
  EXPECT_TRUE(frame_needs_parts(costs, 100, 0, device));
}

TEST(PartSizer, TheFirstPartTakesWhatTheBudgetLeavesAtFourPairsAGaussian) {
  const PartCosts costs = small_costs();
  const PartSizer sizer(costs, 15000, DeviceCapacity{});
  EXPECT_EQ(sizer.capacity(), 100u);  // (15,000 - 1,000) / 140
  EXPECT_EQ(sizer.pairs_per_gaussian(), kFirstPairsPerGaussian);
  EXPECT_EQ(sizer.reserved_pairs(), 401u);
  // Not one Gaussian fits: the budget's own error, naming it.
  EXPECT_THROW(PartSizer(costs, 1100, DeviceCapacity{}), std::invalid_argument);
}

TEST(PartSizer, PartsShrinkToThePairsAndTheOverheadMeasuredAndNeverGrow) {
  const PartCosts costs = small_costs();
  PartSizer sizer(costs, 15000, DeviceCapacity{});
  // Fewer pairs than guessed (2 a Gaussian: 2.5 with the margin) would allow more Gaussians, but a part
  // never grows past the ones before (the scene buffers keep the largest part's size).
  sizer.part_rendered(100, 200, /*device_bytes=*/0, /*key_bytes=*/0);
  EXPECT_DOUBLE_EQ(sizer.pairs_per_gaussian(), 2.5);
  EXPECT_EQ(sizer.capacity(), 100u);
  // A part with 8 pairs a Gaussian: 10 with the margin, 200 bytes a Gaussian: 70 Gaussians.
  sizer.part_rendered(100, 800, 0, 0);
  EXPECT_DOUBLE_EQ(sizer.pairs_per_gaussian(), 10.0);
  EXPECT_EQ(sizer.capacity(), 70u);
  EXPECT_EQ(sizer.reserved_pairs(), 701u);
  // The most pairs any part had keep counting: a later part with fewer changes nothing.
  sizer.part_rendered(70, 70, 0, 0);
  EXPECT_DOUBLE_EQ(sizer.pairs_per_gaussian(), 10.0);
  // What the device held beyond the estimate (fixed + largest part's Gaussians + keys) is taken from
  // the budget: 2,000 bytes more leave 12,000 / 200 = 60.
  const uint64_t estimated = 1000 + 100 * 100 + 500;
  sizer.part_rendered(70, 560, estimated + 2000, 500);  // 8 pairs a Gaussian, as the most before
  EXPECT_EQ(sizer.capacity(), 60u);
}

}  // namespace
}  // namespace tilesplat
