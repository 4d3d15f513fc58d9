// Renderer::Impl: what a renderer holds between frames, and the frame's life around its plan.
//   begin_frame  plans the frame (frame/frame_plan.h), sizes the buffers, uploads the camera and lights
//   run_frame    records the plan (frame/frame_recorder.h) into a command stream and runs it
//   render_frame the retry loop: keys that overflowed grow and the frame re-renders; a composite that
//                needed more dispatches re-runs alone
//   end_frame    the frame's statistics; its lists become reusable
// A frame may also go on without the renderer waiting (render_to_image with HostFrameSync or
// HostCommandBuffer, renderer_async.cpp): it is kept in a FrameInFlight until wait_for_submitted_frame.
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "backward/frame_backward.h"
#include "frame/averaged_frames.h"
#include "frame/frame_accumulator.h"
#include "frame/frame_in_flight.h"
#include "frame/frame_plan.h"
#include "frame/frame_recorder.h"
#include "frame/frame_resources.h"
#include "frame/frame_start.h"
#include "frame/scene_parts.h"
#include "frame/scene_slot.h"
#include "sort/sort_strategy.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene_description.h"
#include "tilesplat/vulkan_interop.h"
#include "vulkan/command_stream.h"
#include "vulkan/context.h"
#include "vulkan/gpu_timer.h"

namespace tilesplat {

struct Renderer::Impl {
  explicit Impl(const RendererOptions& opts) : Impl(opts, vk::ContextOptions{opts.device, opts.validation}) {}
  template <typename ContextSource>
  Impl(const RendererOptions& opts, const ContextSource& source)
      : options(opts), ctx(source), timer(ctx), recorder(ctx, timer), resources(ctx), in_flight(ctx) {}

  SortStrategy& sort(const std::string& name);
  DeviceCaps device_caps() const;

  // What one frame renders: the camera and settings asked for, or, for a frame whose lens and shutter
  // samples accumulate, its next sample's pinhole camera and settings (with `samples` armed for
  // begin_frame: the sums that sample leaves).
  struct FrameInput {
    Camera camera;
    RenderSettings settings;
  };
  FrameInput next_frame_input(const Camera& camera, const RenderSettings& settings);
  // The settings a frame of the scene set is rendered with: over copies that move (set_scene of
  // SceneInstances), an open shutter blurs them (over a still camera unless it has an end camera of its
  // own), and a closed one sees them at time 0, placed there; any other scene, `settings` as they are.
  RenderSettings settings_over_moving_copies(const Camera& camera, const RenderSettings& settings);
  // The moving copies placed where they are at `time` (SceneInstances::Instance::at) and uploaded,
  // unless the buffers have them there already.
  void place_moving_copies(double time);
  // `scene` into the scene buffers, once the submitted frame that reads them is done; the tile lists
  // the buffers hold are then another scene's (scene_generation).
  void upload_scene(const GaussianScene& scene);
  // Renderer::render(camera, settings) of the scene as the buffers hold it (settings_over_moving_copies
  // applied): the frame, its averaged samples, its bands, or one more accumulated sample.
  RenderImage render_set_scene(const Camera& camera, const RenderSettings& settings);
  using FrameStart = tilesplat::FrameStart;  // frame/frame_start.h
  // The plan of a frame of `camera` and `settings` on what the buffers hold now (validating them), without
  // recording or changing anything: begin_frame's, and Renderer::backward's test for reusable lists.
  FramePlan plan_for(const Camera& camera, const RenderSettings& settings, bool depth_image = false,
                     bool without_waiting = false, const ScenePart& part = {},
                     std::optional<uint32_t> samples_before = std::nullopt);
  // Plans the frame (validating the camera and settings), sizes the outputs and uploads what the
  // frame reads from the host. Waits for a frame in flight first: its buffers are the same.
  // without_waiting: a frame render_to_image submits or records and returns (choose_sort_strategy).
  FrameStart begin_frame(const Camera& camera, const RenderSettings& settings, bool depth_image,
                         bool without_waiting = false, const ScenePart& part = {});
  // Records and runs one attempt at the plan; returns the counters the GPU wrote. A composite-only
  // frame rewrites only max_tile_pairs, so the others still describe the lists it read.
  FrameCounters run_frame(const FramePlan& plan, SortStrategy& sorter, const ExternalDepthImage* depth_image);
  // Renders into the output buffers with retries, and fills the statistics (all but cpu_ms). Returns the
  // frame's plan (its first attempt's).
  FramePlan render_frame(const Camera& camera, const RenderSettings& settings,
                         const ExternalDepthImage* depth_image = nullptr, const ScenePart& part = {});
  // The frame's images, read back from the outputs.
  RenderImage read_image(const Camera& camera, const RenderSettings& settings);
  // Depth of field, motion blur: the sample frames averaged (frame/averaged_frames.h), each rendered by
  // render_sample; the frame's statistics are the samples' summed.
  RenderImage average_samples(const Camera& camera, const RenderSettings& settings,
                              const TimedSampleRenderer& render_sample);
  // An image past the device (frame/image_regions.h): the bands of rows it is rendered in, each within
  // the device's largest allocation and a quarter of its memory (one band: the region itself), and the
  // bands rendered by render_band into one image, with their statistics combined.
  std::vector<PixelRegion> image_bands(const Camera& camera, const RenderSettings& settings) const;
  RenderImage render_bands(const Camera& camera, const RenderSettings& settings,
                           const std::vector<PixelRegion>& bands,
                           const std::function<RenderImage(const RenderSettings&)>& render_band);
  // A scene within a memory budget (renderer_parts.cpp): whether its frame would exceed
  // settings.memory_budget (or without one, the device: whole_frame_fits), and the rendering in depth-ordered
  // parts that leaves the image in the outputs and the parts' statistics.
  bool needs_parts(const PartSource& scene, const Camera& camera, const RenderSettings& settings);
  DeviceCapacity device_capacity() const;
  // settings.memory_budget, or without one the share of the device's memory a frame may take.
  uint64_t parts_memory_budget(const RenderSettings& settings) const;
  void render_in_parts(const PartSource& scene, const Camera& camera, const RenderSettings& settings);
  PartCosts part_costs_for(const PartSource& scene, const Camera& camera, const RenderSettings& settings,
                           const std::string& sort_name);
  // Renderer::render(scene, camera, settings) for either kind of scene: set_whole uploads it whole when
  // its frame fits the budget, and `renderer` renders it then.
  RenderImage render_scene(const PartSource& scene, const std::function<void()>& set_whole,
                           const Camera& camera, const RenderSettings& settings, Renderer& renderer);
  void end_frame(const FrameStart& start, const FrameCounters& frame, std::vector<PassTiming> passes,
                 bool lists_whole);
  void add_timings(std::vector<PassTiming>& passes);
  void check_resort_lists(const FramePlan& plan, const FrameCounters& frame) const;
  uint64_t device_bytes() const;

  // Frames the renderer does not wait for (renderer_async.cpp): started and submitted or recorded, and
  // kept in in_flight.
  void submit_frame(const Camera& camera, const RenderSettings& settings, const ExternalImage& target,
                    const ExternalDepthImage* depth_image, const vk::SubmitSync& sync);
  void record_frame_into(const HostCommandBuffer& host, const Camera& camera, const RenderSettings& settings,
                         const ExternalImage& target, const ExternalDepthImage* depth_image);
  void record_frame_to_images(vk::CommandStream& stream, const FrameStart& start, const ExternalImage& target,
                              const ExternalDepthImage* depth_image);
  void wait_for_submitted_frame();

  void read_host_depth(const HostDepth& host, std::vector<float>& out, size_t pixels);

  RendererOptions options;
  vk::Context ctx;
  vk::GpuTimer timer;
  FrameRecorder recorder;
  FrameResources resources;
  std::map<std::string, std::unique_ptr<SortStrategy>> sorts;
  FrameStats stats;
  // The tile lists in the buffers: what they were built for (none after set_scene or a frame that
  // failed).
  std::optional<ListKey> lists;
  FrameAccumulator accumulator;  // the stochastic frames and the lens and shutter samples summed so far
  SceneSlot scene_slot;  // what the scene buffers hold: which scene, which upload, moving copies, a part
  uint64_t uploaded_bytes_reported = 0;     // vk::Context::uploaded_bytes() at the last frame's statistics
  std::unique_ptr<FrameBackward> backward;  // Renderer::backward's passes and buffers, from its first call
  // The frame render_to_image started without waiting (its fence, or a host's timeline): declared last,
  // so that it is destroyed first and waits for the frame before any buffer the frame uses goes.
  FrameInFlight in_flight;
};

// How the functions of vulkan_interop.h, which are not members, reach a renderer's implementation.
struct RendererAccess {
  static Renderer::Impl& impl(Renderer& renderer) { return *renderer.impl_; }
  static std::unique_ptr<Renderer> make(std::unique_ptr<Renderer::Impl> impl) {
    return std::unique_ptr<Renderer>(new Renderer(std::move(impl)));
  }
};

}  // namespace tilesplat
