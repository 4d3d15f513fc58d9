#include "vulkan/command_stream.h"

#include <stdexcept>

#include "vulkan/vk_check.h"

namespace tilesplat::vk {

InFlightSubmission::InFlightSubmission(Context& ctx) : ctx_(ctx) {
  VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  TS_VK_CHECK(vkCreateFence(ctx_.device(), &info, nullptr, &fence_));
}

InFlightSubmission::~InFlightSubmission() {
  if (cmd_ != VK_NULL_HANDLE) {
    vkWaitForFences(ctx_.device(), 1, &fence_, VK_TRUE, UINT64_MAX);  // no throwing from a destructor
    ctx_.free_command_buffer(cmd_);
  }
  vkDestroyFence(ctx_.device(), fence_, nullptr);
}

void InFlightSubmission::wait() {
  if (cmd_ == VK_NULL_HANDLE) return;
  const VkCommandBuffer cmd = cmd_;
  cmd_ = VK_NULL_HANDLE;
  const VkResult result = vkWaitForFences(ctx_.device(), 1, &fence_, VK_TRUE, UINT64_MAX);
  ctx_.free_command_buffer(cmd);
  TS_VK_CHECK(result);
}

CommandStream::~CommandStream() {
  if (cmd_ != VK_NULL_HANDLE && !borrowed_) ctx_.discard(cmd_);
}

void CommandStream::make_writes_host_visible() {
  VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0, nullptr, 0, nullptr);
}

SubmitSync CommandStream::take_first_waits() {
  SubmitSync waits{first_waits_.wait, first_waits_.wait_stages, first_waits_.wait_values, {}, {}};
  first_waits_ = {};
  return waits;
}

void CommandStream::submit() {
  make_writes_host_visible();
  VkCommandBuffer cmd = cmd_;
  cmd_ = VK_NULL_HANDLE;  // end_submit_wait frees it, even when it throws
  ctx_.end_submit_wait(cmd, take_first_waits());
  ++submissions_;
}

void CommandStream::end_borrowed() {
  make_writes_host_visible();
  cmd_ = VK_NULL_HANDLE;
}

void CommandStream::flush() {
  if (borrowed_)
    throw std::logic_error("CommandStream::flush: a host's command buffer cannot be submitted here");
  submit();
  cmd_ = ctx_.begin_one_time();
}

void CommandStream::finish() { submit(); }

void CommandStream::submit_in_flight(InFlightSubmission& in_flight, const SubmitSync& signal) {
  if (in_flight.pending())
    throw std::logic_error("submit_in_flight: the previous submission is still pending");
  make_writes_host_visible();
  SubmitSync sync = take_first_waits();
  sync.signal = signal.signal;
  sync.signal_values = signal.signal_values;
  TS_VK_CHECK(vkResetFences(ctx_.device(), 1, &in_flight.fence_));
  VkCommandBuffer cmd = cmd_;
  cmd_ = VK_NULL_HANDLE;
  try {
    ctx_.end_submit(cmd, sync, in_flight.fence_);
  } catch (...) {
    ctx_.free_command_buffer(cmd);
    throw;
  }
  in_flight.cmd_ = cmd;
  ++submissions_;
}

}  // namespace tilesplat::vk
