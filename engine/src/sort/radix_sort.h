// LSD radix sort, 8-bit digits, reduce-then-scan: per pass a histogram of each block, a scan of the
// counts per digit across blocks, then a stable scatter. Only the passes the key width needs are run.
// Every block belongs to one subgroup, so it needs no inter-workgroup forward-progress guarantee and
// works at any subgroup size (4 to 128).
#pragma once

#include "sort/sort_strategy.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

class RadixSort final : public SortStrategy {
 public:
  explicit RadixSort(vk::Context& ctx);
  std::string name() const override { return "radix"; }
  void reserve(uint32_t max_keys) override;
  bool record(vk::CommandStream& stream, SortInput& input) override;
  uint64_t device_bytes() const override { return histogram_.size() + digit_totals_.size(); }

  uint32_t block_keys() const { return block_keys_; }

 private:
  uint32_t blocks_for(uint32_t keys) const;

  vk::Context& ctx_;
  uint32_t subgroups_per_workgroup_;
  uint32_t block_keys_;
  vk::ComputePipeline setup_, scan_pass_;
  vk::ComputePipeline histogram_pass_[2], scatter_pass_[2];  // [wide keys]
  // CPU drivers: the same passes through texel buffers (radix_common.glsl, TS_TEXEL_BUFFERS).
  bool texel_buffers_;
  vk::ComputePipeline histogram_texel_pass_[2], scatter_texel_pass_[2];  // [wide keys]
  vk::Buffer unused_keys_;  // the texel binding of the key width a pass does not write
  vk::Buffer histogram_;
  vk::Buffer digit_totals_;
};

}  // namespace tilesplat
