#include "vulkan/gpu_timer.h"

#include <algorithm>

#include "vulkan/vk_check.h"

namespace tilesplat::vk {

GpuTimer::GpuTimer(Context& ctx, uint32_t max_marks) : ctx_(ctx), max_marks_(max_marks) {
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = max_marks;
  TS_VK_CHECK(vkCreateQueryPool(ctx.device(), &info, nullptr, &pool_));
}

GpuTimer::~GpuTimer() { vkDestroyQueryPool(ctx_.device(), pool_, nullptr); }

void GpuTimer::begin_frame(VkCommandBuffer cmd) {
  names_.clear();
  vkCmdResetQueryPool(cmd, pool_, 0, max_marks_);
  vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, pool_, 0);
}

void GpuTimer::mark(VkCommandBuffer cmd, const std::string& section) {
  if (names_.size() + 1 >= max_marks_) return;  // out of queries: later sections go untimed
  names_.push_back(section);
  vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, pool_, uint32_t(names_.size()));
}

std::vector<GpuTimer::Section> GpuTimer::read(double* frame_ms) const {
  std::vector<Section> sections;
  if (frame_ms) *frame_ms = 0;
  if (names_.empty()) return sections;
  std::vector<uint64_t> ticks(names_.size() + 1);
  TS_VK_CHECK(vkGetQueryPoolResults(ctx_.device(), pool_, 0, uint32_t(ticks.size()), ticks.size() * sizeof(uint64_t),
                                    ticks.data(), sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  const uint32_t bits = ctx_.limits().timestamp_valid_bits;
  const uint64_t mask = bits >= 64 ? ~0ull : ((1ull << bits) - 1);
  const double ns_per_tick = ctx_.limits().timestamp_period_ns;
  auto elapsed_ms = [&](uint64_t a, uint64_t b) { return double(((b & mask) - (a & mask)) & mask) * ns_per_tick * 1e-6; };
  for (size_t i = 0; i < names_.size(); ++i) {
    double ms = elapsed_ms(ticks[i], ticks[i + 1]);
    auto it = std::find_if(sections.begin(), sections.end(), [&](const Section& s) { return s.name == names_[i]; });
    if (it != sections.end())
      it->ms += ms;
    else
      sections.push_back({names_[i], ms});
  }
  if (frame_ms) *frame_ms = elapsed_ms(ticks.front(), ticks.back());
  return sections;
}

}  // namespace tilesplat::vk
