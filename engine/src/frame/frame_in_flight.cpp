#include "frame/frame_in_flight.h"

#include <chrono>
#include <utility>

#include "vulkan/vk_check.h"

namespace tilesplat {
namespace {

// Waits for a timeline semaphore (a host's, HostCommandBuffer) to reach `value`.
VkResult wait_for_value(VkDevice device, VkSemaphore timeline, uint64_t value) {
  VkSemaphoreWaitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
  wait.semaphoreCount = 1;
  wait.pSemaphores = &timeline;
  wait.pValues = &value;
  return vkWaitSemaphores(device, &wait, UINT64_MAX);
}

}  // namespace

FrameInFlight::~FrameInFlight() {
  if (frame_ && frame_->timeline != VK_NULL_HANDLE)
    wait_for_value(ctx_.device(), frame_->timeline, frame_->value);  // no throwing from a destructor
}

void FrameInFlight::keep(const FrameStart& start, int submissions, VkSemaphore timeline, uint64_t value) {
  const double cpu_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start.time).count();
  frame_ = Kept{{start, submissions, cpu_ms}, timeline, value};
}

std::optional<FrameInFlight::Completed> FrameInFlight::wait() {
  if (!frame_) return std::nullopt;
  Kept kept = std::move(*frame_);
  frame_.reset();
  if (kept.timeline != VK_NULL_HANDLE)
    TS_VK_CHECK(wait_for_value(ctx_.device(), kept.timeline, kept.value));
  else
    submission_.wait();
  return std::move(kept.frame);
}

}  // namespace tilesplat
