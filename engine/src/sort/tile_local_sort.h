// Tile-local sort: a counting sort on the keys' high bits (the tile id of a frame's (tile, depth)
// keys) puts every key into its bin, then one workgroup sorts each bin on the remaining low bits (the
// depth) by (local key, input position), which is the stable order. Bins up to a shared-memory
// capacity are merge-sorted in shared memory; larger ones by a bitonic network in global memory, in
// the bin's own range of the output. The whole sort is six dispatches whatever the key width.
#pragma once

#include <array>
#include <memory>

#include "sort/sort_strategy.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

class TileLocalSort final : public SortStrategy {
 public:
  // How keys of a given width are split, for sorts of up to `capacity` keys.
  struct Binning {
    uint32_t bin_bits;  // the bin is key >> shift: 2^bin_bits bins
    uint32_t shift;     // local key bits
  };
  static Binning binning_for(uint32_t key_bits, uint32_t capacity);

  explicit TileLocalSort(vk::Context& ctx);
  std::string name() const override { return "tile-local"; }
  // Nothing to size: the bin table is sized for the most bins, and the bins live in keys_alt and
  // values_alt (positions until the last pass replaces each with its payload).
  void reserve(uint32_t) override {}
  bool record(vk::CommandStream& stream, SortInput& input) override;
  FrameSortPlan frame_plan() const override { return FrameSortPlan::kTileDepthPairs; }
  uint64_t device_bytes() const override { return bins_.size(); }

  // Bins up to this many keys are sorted in shared memory (narrow, wide local keys).
  uint32_t shared_capacity(bool wide_local) const { return shared_capacity_[wide_local ? 1 : 0]; }

 private:
  const vk::ComputePipeline& sort_pipeline(bool wide_keys, bool wide_local, bool big);

  vk::Context& ctx_;
  uint32_t key_workgroups_;  // cap on the workgroups of the passes over the keys
  uint32_t bin_workgroups_;  // cap on the workgroups that sort bins
  std::array<uint32_t, 2> shared_capacity_;
  vk::ComputePipeline setup_, scan_;
  std::array<vk::ComputePipeline, 2> count_, scatter_;  // [wide keys]
  // [wide keys][wide local][big], built on first use: most runs need one or two of the eight.
  std::array<std::unique_ptr<vk::ComputePipeline>, 8> sort_;
  vk::Buffer bins_;
};

}  // namespace tilesplat
