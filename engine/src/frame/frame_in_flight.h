// FrameInFlight: the frame a renderer started without waiting for it (render_to_image with HostFrameSync,
// which submits it, or HostCommandBuffer, which records it into a host's command buffer), until it is
// waited for. At most one: a frame waits for the one before it (its buffers are the same). Destroyed
// before the buffers the frame uses (Renderer::Impl declares it last), it waits for the frame first.
#pragma once
#include <optional>

#include "frame/frame_start.h"
#include "vulkan/command_stream.h"
#include "vulkan/context.h"

namespace tilesplat {

class FrameInFlight {
 public:
  explicit FrameInFlight(vk::Context& ctx) : ctx_(ctx), submission_(ctx) {}
  // A frame recorded into a host's command buffer may still run: its timeline is waited for (a frame the
  // renderer submitted itself is waited for by the submission's own destructor).
  ~FrameInFlight();
  FrameInFlight(const FrameInFlight&) = delete;
  FrameInFlight& operator=(const FrameInFlight&) = delete;

  // The fence and command buffer of the renderer's own submission (vk::CommandStream::submit_in_flight).
  vk::InFlightSubmission& submission() { return submission_; }

  // What a completed frame hands back.
  struct Completed {
    FrameStart start;
    int submissions = 0;
    double cpu_ms = 0;  // from its start to its submission or recording
  };
  // Keeps the frame started at `start`: submitted by the renderer (`timeline` null), or recorded into a
  // host's command buffer that signals `timeline` with `value` when it completes.
  void keep(const FrameStart& start, int submissions, VkSemaphore timeline = VK_NULL_HANDLE,
            uint64_t value = 0);
  bool pending() const { return frame_.has_value(); }
  // Waits for the kept frame, if any, and hands it back (once); nothing when none is kept.
  std::optional<Completed> wait();

 private:
  struct Kept {
    Completed frame;
    VkSemaphore timeline = VK_NULL_HANDLE;
    uint64_t value = 0;
  };
  vk::Context& ctx_;
  vk::InFlightSubmission submission_;
  std::optional<Kept> frame_;
};

}  // namespace tilesplat
