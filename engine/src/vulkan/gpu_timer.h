// GPU timestamps around named passes, read back after the frame's fence.
#pragma once

#include <vulkan/vulkan.h>

#include <string>
#include <vector>

#include "vulkan/context.h"

namespace tilesplat::vk {

class GpuTimer {
 public:
  GpuTimer(Context& ctx, uint32_t max_marks = 64);
  ~GpuTimer();
  GpuTimer(const GpuTimer&) = delete;
  GpuTimer& operator=(const GpuTimer&) = delete;

  void begin_frame(VkCommandBuffer cmd);  // resets the pool and writes the frame's first mark
  // Ends the previous section (or the frame start) and names it.
  void mark(VkCommandBuffer cmd, const std::string& section);

  struct Section {
    std::string name;
    double ms;
  };
  // After the frame completed: durations of each section (sections with the same name are summed,
  // first-appearance order kept) and the whole-frame time.
  std::vector<Section> read(double* frame_ms) const;

 private:
  Context& ctx_;
  VkQueryPool pool_ = VK_NULL_HANDLE;
  uint32_t max_marks_;
  std::vector<std::string> names_;  // names_[i] labels the interval ending at timestamp i + 1
};

}  // namespace tilesplat::vk
