// Frames the renderer does not wait for, and the entry points of vulkan_interop.h. render_to_image
// with HostFrameSync submits the whole frame (its copies into the host's images included) and returns;
// with HostCommandBuffer it records the frame into the host's command buffer. Either frame is kept as
// a FrameInFlight, and its statistics become the last frame's once it has completed
// (wait_for_submitted_frame: at the next frame, set_scene, sort_keys or wait_for_frame).
#include <chrono>
#include <stdexcept>
#include <string>

#include "host_images.h"
#include "renderer_impl.h"

namespace tilesplat {

void Renderer::Impl::submit_frame(const Camera& camera, const RenderSettings& settings,
                                  const ExternalImage& target, const ExternalDepthImage* depth_image,
                                  const vk::SubmitSync& sync) {
  const FrameStart start = begin_frame(camera, settings, depth_image != nullptr, /*without_waiting=*/true);
  vk::CommandStream stream(ctx);
  stream.wait_first(sync);
  record_frame_to_images(stream, start, target, depth_image);
  stream.submit_in_flight(in_flight.submission(), sync);
  in_flight.keep(start, stream.submissions());
}

void Renderer::Impl::record_frame_into(const HostCommandBuffer& host, const Camera& camera,
                                       const RenderSettings& settings, const ExternalImage& target,
                                       const ExternalDepthImage* depth_image) {
  const FrameStart start = begin_frame(camera, settings, depth_image != nullptr, /*without_waiting=*/true);
  vk::CommandStream stream(ctx, host.command_buffer);
  record_frame_to_images(stream, start, target, depth_image);
  stream.end_borrowed();
  in_flight.keep(start, 0, host.timeline, host.value);
}

// A frame that goes on without the renderer waiting for it: its whole recording, from the buffers'
// sizes to the copies into the host's images. It cannot re-render.
void Renderer::Impl::record_frame_to_images(vk::CommandStream& stream, const FrameStart& start,
                                            const ExternalImage& target, const ExternalDepthImage* depth_image) {
  recorder.prepare(start.plan, resources, *start.sorter);
  recorder.record(stream, start.plan, resources, *start.sorter, depth_image);
  recorder.record_copies_to_images(stream.cmd(), start.plan, resources, target, depth_image);
}

// Waits for the frame in flight, if any, and makes its statistics the last frame's. It cannot
// re-render: a frame that overflowed the key buffers or had too few composite chunks was drawn
// without what did not fit (FrameStats::complete false), and the next frame has what it needs.
void Renderer::Impl::wait_for_submitted_frame() {
  const std::optional<FrameInFlight::Completed> frame_info = in_flight.wait();
  if (!frame_info) return;
  const FrameCounters frame = resources.frame_counters();
  stats = {};
  std::vector<PassTiming> passes;
  add_timings(passes);
  stats.submissions = frame_info->submissions;
  stats.cpu_ms = frame_info->cpu_ms;
  const FramePlan& plan = frame_info->start.plan;
  uint32_t& chunks = recorder.composite_chunks(plan.compositor);
  const bool lists_whole = !frame.overflow;
  if (frame.overflow) {
    stats.complete = false;
    resources.grow_keys_for(frame, plan.lists.camera);
  } else {
    check_resort_lists(plan, frame);
    const uint32_t needed = recorder.chunks_for(plan.compositor, frame.max_tile_pairs);
    stats.complete = needed <= chunks;
    chunks = needed;
  }
  end_frame(frame_info->start, frame, std::move(passes), lists_whole);
}

std::unique_ptr<Renderer> create_renderer(const ExternalVulkanDevice& device,
                                          const RendererOptions& options) {
  return RendererAccess::make(std::make_unique<Renderer::Impl>(options, device));
}

void render_to_image(Renderer& renderer, const Camera& camera, const RenderSettings& asked,
                     const ExternalImage& target) {
  Renderer::Impl& r = RendererAccess::impl(renderer);
  const RenderSettings settings = r.settings_over_moving_copies(camera, asked);
  check_images(target, nullptr, camera, settings);
  const auto start = std::chrono::steady_clock::now();
  const Renderer::Impl::FrameInput frame = r.next_frame_input(camera, settings);  // a sample, if accumulating
  const FramePlan plan = r.render_frame(frame.camera, frame.settings);
  r.ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    r.recorder.record_copies_to_images(cmd, plan, r.resources, target, nullptr);
  });
  r.stats.saturated = r.resources.frame_counters().saturation();
  r.stats.cpu_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void render_to_image(Renderer& renderer, const Camera& camera, const RenderSettings& asked,
                     const ExternalImage& target, const ExternalDepthImage& depth) {
  Renderer::Impl& r = RendererAccess::impl(renderer);
  const RenderSettings settings = r.settings_over_moving_copies(camera, asked);
  check_images(target, &depth, camera, settings);
  const auto start = std::chrono::steady_clock::now();
  const Renderer::Impl::FrameInput frame = r.next_frame_input(camera, settings);  // a sample, if accumulating
  const FramePlan plan = r.render_frame(frame.camera, frame.settings, &depth);
  r.ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    r.recorder.record_copies_to_images(cmd, plan, r.resources, target, &depth);
  });
  r.stats.saturated = r.resources.frame_counters().saturation();
  r.stats.cpu_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void render_to_image(Renderer& renderer, const Camera& camera, const RenderSettings& asked,
                     const ExternalImage& target, const ExternalDepthImage* depth,
                     const HostFrameSync& sync) {
  Renderer::Impl& r = RendererAccess::impl(renderer);
  const RenderSettings settings = r.settings_over_moving_copies(camera, asked);
  check_images(target, depth, camera, settings);
  auto check_count = [](size_t count, size_t semaphores, const char* what) {
    if (count != 0 && count != semaphores)
      throw std::invalid_argument(std::string("render_to_image: HostFrameSync has ") + std::to_string(count) +
                                  " " + what + " for " + std::to_string(semaphores) +
                                  " semaphores (give one each, or none)");
  };
  check_count(sync.wait_stages.size(), sync.wait.size(), "wait_stages");
  check_count(sync.wait_values.size(), sync.wait.size(), "wait_values");
  check_count(sync.signal_values.size(), sync.signal.size(), "signal_values");
  const Renderer::Impl::FrameInput frame = r.next_frame_input(camera, settings);  // a sample, if accumulating
  r.submit_frame(frame.camera, frame.settings, target, depth,
                 {sync.wait, sync.wait_stages, sync.wait_values, sync.signal, sync.signal_values});
}

void render_to_image(Renderer& renderer, const Camera& camera, const RenderSettings& asked,
                     const ExternalImage& target, const ExternalDepthImage* depth,
                     const HostCommandBuffer& commands) {
  Renderer::Impl& r = RendererAccess::impl(renderer);
  const RenderSettings settings = r.settings_over_moving_copies(camera, asked);
  check_images(target, depth, camera, settings);
  if (commands.command_buffer == VK_NULL_HANDLE)
    throw std::invalid_argument("render_to_image: HostCommandBuffer has no command buffer");
  if (commands.timeline == VK_NULL_HANDLE)
    throw std::invalid_argument(
        "render_to_image: HostCommandBuffer has no timeline semaphore to say when the frame has completed");
  if (r.sort(choose_sort_strategy(settings.sort, r.device_caps(), /*without_waiting=*/true)).sorts_on_host())
    throw std::invalid_argument(
        "render_to_image: the sort strategy '" + settings.sort +
        "' sorts on the host in the middle of the frame, which a command buffer of the "
        "host's cannot hold: use a GPU strategy, or HostFrameSync");
  const Renderer::Impl::FrameInput frame = r.next_frame_input(camera, settings);  // a sample, if accumulating
  r.record_frame_into(commands, frame.camera, frame.settings, target, depth);
}

void wait_for_frame(Renderer& renderer) {
  RendererAccess::impl(renderer).wait_for_submitted_frame();
}

}  // namespace tilesplat
