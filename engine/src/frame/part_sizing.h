// How big the parts of a scene rendered in parts are (renderer_parts.cpp runs them): whether a frame needs
// parts at all, and each part's capacity, which adapts to what the parts before it measured. No device:
// the costs and the device's capacity come in as numbers (frame/scene_parts.h), so the rules are tested
// on their own (tests/test_part_sizing.cpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include "frame/scene_parts.h"

namespace tilesplat {

// The first part's guess of (tile, Gaussian) pairs per Gaussian, as set_scene's first key buffers (4 n).
inline constexpr double kFirstPairsPerGaussian = 4;

// Whether a frame of `gaussians` with these costs renders in parts. Without a budget (0): where the whole
// frame would not fit the device (whole_frame_fits), as every frame did before budgets. Under one: where it
// would take more than the budget, or any buffer past the device's largest allocation, or any dispatch
// past its workgroup count.
bool frame_needs_parts(const PartCosts& costs, size_t gaussians, uint64_t budget,
                       const DeviceCapacity& device);

class PartSizer {
 public:
  // The first part's capacity: part_capacity with kFirstPairsPerGaussian and nothing measured yet. Throws
  // std::invalid_argument (part_capacity's message) when not even one Gaussian fits the budget.
  PartSizer(const PartCosts& costs, uint64_t budget, const DeviceCapacity& device);

  // The most Gaussians the next part may hold.
  size_t capacity() const { return capacity_; }
  double pairs_per_gaussian() const { return pairs_per_gaussian_; }
  // The pairs the key buffers are reserved for: those of a part of the capacity, the same from part to
  // part, so that no part makes new buffers.
  uint64_t reserved_pairs() const { return uint64_t(pairs_per_gaussian_ * double(capacity_)) + 1; }

  // A part rendered: its Gaussians, its pairs (FrameStats::intersections), what the device held for the
  // frame (FrameStats::device_bytes) and its key buffers' bytes. The next parts take as many pairs per
  // Gaussian as the most any part had with a quarter more (a part with more pairs than its key buffers hold
  // renders again), and room for what the device held beyond the estimate (the sort strategy's buffers,
  // the pipelines' own); never more Gaussians than before, as the scene buffers keep the largest part's size.
  void part_rendered(size_t gaussians, uint64_t pairs, uint64_t device_bytes, uint64_t key_bytes);

 private:
  PartCosts costs_;
  uint64_t budget_;
  DeviceCapacity device_;
  size_t capacity_;
  double pairs_per_gaussian_ = kFirstPairsPerGaussian;
  double most_pairs_per_gaussian_ = 0;
  size_t largest_part_ = 0;
};

}  // namespace tilesplat
