#include "vulkan/command_stream.h"

namespace tilesplat::vk {

CommandStream::~CommandStream() {
  if (cmd_ != VK_NULL_HANDLE) ctx_.discard(cmd_);
}

void CommandStream::submit() {
  VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0, nullptr, 0, nullptr);
  VkCommandBuffer cmd = cmd_;
  cmd_ = VK_NULL_HANDLE;  // end_submit_wait frees it, even when it throws
  ctx_.end_submit_wait(cmd);
  ++submissions_;
}

void CommandStream::flush() {
  submit();
  cmd_ = ctx_.begin_one_time();
}

void CommandStream::finish() { submit(); }

}  // namespace tilesplat::vk
