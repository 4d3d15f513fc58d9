// The command buffer a frame (or a lone sort) is recorded into. The frame is normally one submission;
// a pass that needs the host in the middle of it (the cpu-radix sort reads its keys back, sorts them
// and uploads the result) calls flush(), which runs what is recorded so far and goes on in a new
// command buffer. Passes therefore take the stream and ask it for the current command buffer.
#pragma once

#include <vulkan/vulkan.h>

#include "vulkan/context.h"

namespace tilesplat::vk {

class CommandStream {
 public:
  explicit CommandStream(Context& ctx) : ctx_(ctx), cmd_(ctx.begin_one_time()) {}
  // A stream left unfinished (an exception while recording) is discarded without being submitted.
  ~CommandStream();
  CommandStream(const CommandStream&) = delete;
  CommandStream& operator=(const CommandStream&) = delete;

  VkCommandBuffer cmd() const { return cmd_; }
  Context& context() const { return ctx_; }

  // Submits what is recorded, waits for it with its shader and transfer writes visible to the host
  // (mapped memory may be read right after), and begins a new command buffer.
  void flush();
  // Submits what is recorded and waits for it, with the same host visibility; the stream ends.
  void finish();
  // How many times the stream was submitted so far (1 + flushes once finished).
  int submissions() const { return submissions_; }

 private:
  void submit();

  Context& ctx_;
  VkCommandBuffer cmd_;
  int submissions_ = 0;
};

}  // namespace tilesplat::vk
