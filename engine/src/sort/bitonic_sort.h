// Global bitonic sorting network on (key, input position) pairs. Its work depends on the count, not
// on the key width: log2(n) * (log2(n) + 1) / 2 compare-exchange steps over every key, which each
// invocation runs four at a time on 16 keys it holds in registers. A network is not stable; breaking
// ties by input position makes it so. It synchronises nothing beyond one invocation, so it works at
// any subgroup and workgroup size.
#pragma once

#include <array>

#include "sort/sort_strategy.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

class BitonicSort final : public SortStrategy {
 public:
  explicit BitonicSort(vk::Context& ctx);
  std::string name() const override { return "bitonic"; }
  // The network runs in keys_alt and values_alt (the positions live in values_alt until the last pass
  // replaces each with its payload; the padding to a power of two is never stored), except that a key
  // packed with its position needs a 64-bit word: with 32-bit key buffers, those run in a scratch
  // buffer sized here.
  void reserve(uint32_t max_keys) override;
  bool record(vk::CommandStream& stream, SortInput& input) override;
  uint64_t device_bytes() const override { return network_.size(); }

 private:
  vk::Context& ctx_;
  vk::Buffer network_;
  uint32_t max_workgroups_;
  vk::ComputePipeline setup_;
  // Indexed by whether the key and its position share one 64-bit word (see compute/bitonic_common.glsl).
  std::array<vk::ComputePipeline, 4> sort_groups_, merge_;  // [packed * 2 + wide keys]
};

}  // namespace tilesplat
