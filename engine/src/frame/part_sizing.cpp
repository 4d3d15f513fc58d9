#include "frame/part_sizing.h"

#include <algorithm>

namespace tilesplat {

bool frame_needs_parts(const PartCosts& costs, size_t gaussians, uint64_t budget,
                       const DeviceCapacity& device) {
  if (budget == 0) return !whole_frame_fits(costs, gaussians, kFirstPairsPerGaussian, device);
  const double whole_bytes =
      double(costs.fixed) +
      double(gaussians) * (double(costs.per_gaussian) + kFirstPairsPerGaussian * double(costs.per_pair));
  // Under any budget, no buffer past the device's largest allocation and no dispatch past its limit.
  DeviceCapacity buffers_only = device;
  buffers_only.total = UINT64_MAX;
  return whole_bytes > double(budget) ||
         !whole_frame_fits(costs, gaussians, kFirstPairsPerGaussian, buffers_only);
}

PartSizer::PartSizer(const PartCosts& costs, uint64_t budget, const DeviceCapacity& device)
    : costs_(costs),
      budget_(budget),
      device_(device),
      capacity_(part_capacity(budget, costs, 0, kFirstPairsPerGaussian, device)) {}

void PartSizer::part_rendered(size_t gaussians, uint64_t pairs, uint64_t device_bytes, uint64_t key_bytes) {
  largest_part_ = std::max(largest_part_, gaussians);
  most_pairs_per_gaussian_ =
      std::max(most_pairs_per_gaussian_, double(pairs) / double(std::max<size_t>(gaussians, 1)));
  pairs_per_gaussian_ = std::max(1.0, 1.25 * most_pairs_per_gaussian_);
  const uint64_t estimated = costs_.fixed + uint64_t(largest_part_) * costs_.per_gaussian + key_bytes;
  const uint64_t overhead = device_bytes > estimated ? device_bytes - estimated : 0;
  capacity_ = std::min(capacity_, part_capacity(budget_, costs_, overhead, pairs_per_gaussian_, device_));
}

}  // namespace tilesplat
