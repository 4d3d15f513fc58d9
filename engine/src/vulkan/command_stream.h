// The command buffer a frame (or a lone sort) is recorded into. The frame is normally one submission;
// a pass that needs the host in the middle of it (the cpu-radix sort reads its keys back, sorts them
// and uploads the result) calls flush(), which runs what is recorded so far and goes on in a new
// command buffer. Passes therefore take the stream and ask it for the current command buffer.
#pragma once

#include <vulkan/vulkan.h>

#include "vulkan/context.h"

namespace tilesplat::vk {

// A submission nobody waited for yet (a frame render_to_image submitted with the host's semaphores):
// its fence and command buffer. wait() (or the destructor) waits for it and frees the command buffer.
class InFlightSubmission {
 public:
  explicit InFlightSubmission(Context& ctx);
  ~InFlightSubmission();
  InFlightSubmission(const InFlightSubmission&) = delete;
  InFlightSubmission& operator=(const InFlightSubmission&) = delete;

  bool pending() const { return cmd_ != VK_NULL_HANDLE; }
  // Waits for the submission to complete (nothing when none is pending).
  void wait();

 private:
  friend class CommandStream;
  Context& ctx_;
  VkFence fence_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
};

class CommandStream {
 public:
  explicit CommandStream(Context& ctx) : ctx_(ctx), cmd_(ctx.begin_one_time()) {}
  // Records into a host application's command buffer (in the recording state), which the host submits:
  // flush() is an error there, may_split() does nothing, and end_borrowed() ends the stream.
  CommandStream(Context& ctx, VkCommandBuffer borrowed) : ctx_(ctx), cmd_(borrowed), borrowed_(true) {}
  // A stream left unfinished (an exception while recording) is discarded without being submitted.
  ~CommandStream();
  CommandStream(const CommandStream&) = delete;
  CommandStream& operator=(const CommandStream&) = delete;

  VkCommandBuffer cmd() const { return cmd_; }
  Context& context() const { return ctx_; }

  // Semaphores (the host's) the stream's first submission waits for; only their wait half is used.
  void wait_first(const SubmitSync& waits) { first_waits_ = waits; }

  // Submits what is recorded, waits for it with its shader and transfer writes visible to the host
  // (mapped memory may be read right after), and begins a new command buffer. Throws std::logic_error
  // on a host's command buffer.
  void flush();
  // Where a long stream (the stochastic composite's samples) may be cut into submissions: flush() on
  // the stream's own command buffers, nothing on a host's.
  void may_split() {
    if (!borrowed_) flush();
  }
  // Ends a stream on a host's command buffer, with its writes made visible to the host once the host's
  // submission of it has completed.
  void end_borrowed();
  // Submits what is recorded and waits for it, with the same host visibility; the stream ends.
  void finish();
  // Submits what is recorded without waiting, signalling `signal` (its wait half unused) and
  // `in_flight`'s fence, which must not be pending; the stream ends. The writes are visible to the host
  // once in_flight.wait() returns.
  void submit_in_flight(InFlightSubmission& in_flight, const SubmitSync& signal);
  // How many times the stream was submitted so far (1 + flushes once finished).
  int submissions() const { return submissions_; }

 private:
  void make_writes_host_visible();
  void submit();
  SubmitSync take_first_waits();

  Context& ctx_;
  VkCommandBuffer cmd_;
  SubmitSync first_waits_;
  bool borrowed_ = false;
  int submissions_ = 0;
};

}  // namespace tilesplat::vk
