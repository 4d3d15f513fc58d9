#include "passes/prefix_sum_pass.h"

#include "shader_io.h"

namespace tilesplat {

namespace {
using BlocksPush = shader_io::PrefixSumBlocksPush;  // compute/shader_io.h
using AddPush = shader_io::PrefixSumAddPush;        // compute/shader_io.h
}  // namespace

PrefixSumPass::PrefixSumPass(vk::Context& ctx)
    : ctx_(ctx),
      scan_blocks_(ctx, "prefix_sum_blocks", sizeof(BlocksPush)),
      add_offsets_(ctx, "prefix_sum_add", sizeof(AddPush)) {}

void PrefixSumPass::record(VkCommandBuffer cmd, VkDeviceAddress src, VkDeviceAddress dst, uint32_t count,
                           VkDeviceAddress total, VkDeviceAddress order) {
  if (count == 0) return;  // the caller's total stays at the zero it was cleared to
  // Levels: level 0 scans `count` values; level k scans the block totals of level k - 1.
  struct Level {
    VkDeviceAddress data;
    uint32_t count;
  };
  std::vector<Level> levels{{dst, count}};
  while (levels.back().count > kBlock) {
    size_t index = levels.size() - 1;
    uint32_t blocks = vk::div_ceil(levels.back().count, kBlock);
    if (level_sums_.size() <= index || level_sums_[index].size() < blocks * sizeof(uint32_t)) {
      level_sums_.resize(index + 1);
      level_sums_[index] = vk::Buffer(ctx_, blocks * sizeof(uint32_t), vk::MemoryUse::Device, "prefix sum level");
    }
    levels.push_back({level_sums_[index].address(), blocks});
  }
  // Down the levels: scan blocks locally, each level's block totals go to the next level's data;
  // the single block of the top level writes the grand total.
  for (size_t k = 0; k < levels.size(); ++k) {
    VkDeviceAddress in = k == 0 ? src : levels[k].data;
    VkDeviceAddress sums = k + 1 < levels.size() ? levels[k + 1].data : total;
    const bool gather = k == 0 && order != 0;
    scan_blocks_.bind(cmd, BlocksPush{in, levels[k].data, sums, gather ? order : in, levels[k].count, gather});
    scan_blocks_.dispatch(cmd, vk::div_ceil(levels[k].count, kBlock));
    vk::barrier(cmd);
  }
  // Back up: add each scanned block total to its block.
  for (size_t k = levels.size() - 1; k-- > 0;) {
    add_offsets_.bind(cmd, AddPush{levels[k].data, levels[k + 1].data, levels[k].count});
    add_offsets_.dispatch(cmd, vk::div_ceil(levels[k].count, kBlock));
    vk::barrier(cmd);
  }
}

uint64_t PrefixSumPass::device_bytes() const {
  uint64_t bytes = 0;
  for (const auto& b : level_sums_) bytes += b.size();
  return bytes;
}

}  // namespace tilesplat
