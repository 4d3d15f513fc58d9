// The renderer: what it holds between frames (renderer_impl.h) and the frame's life around its plan.
// A frame is planned (frame/frame_plan.h: which passes, which variants, built or reused lists), its
// buffers sized (frame/frame_resources.h), recorded (frame/frame_recorder.h) and run; when its pairs
// overflowed the key buffers they grow and it re-renders, and when a tile's list needed more
// composite dispatches than it had, the composite re-runs alone. The passes, for the sorted frame:
//   projection -> depth sort -> prefix sum -> key emission -> tile sort -> tile ranges -> composite
// The Gaussians are sorted by depth once; the (tile, Gaussian) pairs are then emitted front to back
// and sorted by tile alone (stable). That is the same order as one sort of (tile << 32 | depth)
// keys, for far fewer key bits times keys: on playbot_lod0 at 1080p, 4 digit passes over 0.5M
// Gaussians plus 2 over 1.5M pairs instead of 6 over 1.5M.
// Data flows one way; the only host read-back is the counters (and the image) after the fence.
#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>
#include <utility>

#include "frame/averaged_frames.h"
#include "frame/image_regions.h"
#include "host_depth.h"
#include "host_resources.h"
#include "passes/frame_counters.h"
#include "renderer_impl.h"
#include "settings_checks.h"
#include "sort/key_sort_run.h"
#include "vulkan/readback.h"

namespace tilesplat {

namespace {
constexpr int kMaxRetries = 4;
}  // namespace

SortStrategy& Renderer::Impl::sort(const std::string& name) {
  auto it = sorts.find(name);
  if (it == sorts.end()) it = sorts.emplace(name, make_sort_strategy(name, ctx)).first;
  return *it->second;
}

DeviceCaps Renderer::Impl::device_caps() const {
  const vk::DeviceLimits& limits = ctx.limits();
  return {ctx.is_cpu_device(), ctx.vendor_id(), limits.max_workgroup_count_x, limits.max_allocation_size};
}

uint64_t Renderer::Impl::device_bytes() const {
  uint64_t bytes = resources.device_bytes() + recorder.device_bytes();
  for (const auto& [name, s] : sorts) bytes += s->device_bytes();
  return bytes;
}

FramePlan Renderer::Impl::plan_for(const Camera& camera, const RenderSettings& settings, bool depth_image,
                                   bool without_waiting, const ScenePart& part,
                                   std::optional<uint32_t> samples_before) {
  const DeviceCaps device = device_caps();
  SortStrategy& sorter = sort(choose_sort_strategy(settings.sort, device, without_waiting));
  const SortTraits traits{sorter.name(), sorter.frame_plan(), sorter.sorts_on_host()};
  const FrameContext context{resources.scene_shape(scene_slot.generation()),
                             device,
                             traits,
                             lists,
                             depth_image,
                             part,
                             samples_before,
                             accumulator.stochastic_frames_before(settings),
                             recorder.composite_chunks(settings.compositor)};
  return plan_frame(camera, settings, context);
}

Renderer::Impl::FrameStart Renderer::Impl::begin_frame(const Camera& camera, const RenderSettings& settings,
                                                       bool depth_image, bool without_waiting,
                                                       const ScenePart& part) {
  // A sample of an accumulated lens or shutter frame (next_frame_input) adds to the sums before it; armed
  // for this frame alone, even one that throws.
  std::optional<FrameAccumulator::Samples> sample = accumulator.take_armed_sample();
  scene_slot.check_whole_scene();
  FrameStart start;
  start.time = std::chrono::steady_clock::now();
  wait_for_submitted_frame();
  std::optional<uint32_t> samples_before;
  if (sample) samples_before = sample->before();
  start.plan = plan_for(camera, settings, depth_image, without_waiting, part, samples_before);
  start.sorter = &sort(start.plan.sort.name);
  resources.prepare_outputs(start.plan, settings.host);
  // The sums are this frame's now, and the next frame's once it completes.
  start.sums = accumulator.frame_started(
      settings, start.plan.stochastic_first_sample + start.plan.stochastic_samples, std::move(sample));
  // A frame the renderer waits for fills the statistics as it runs; one that goes on without waiting
  // fills them once it is waited for (wait_for_submitted_frame), and until then the last frame's stay.
  if (!without_waiting) stats = {};
  lists.reset();  // valid again once this frame's lists are complete (not if it throws)
  // Reused lists were built with an equal camera and equal (validated) lights, which are in their
  // buffers still: nothing to upload.
  if (start.plan.build_lists)
    recorder.set_frame_inputs(camera, settings.lighting, settings.near_plane, start.plan.culling_tiles,
                              resources.scene);
  start.fallbacks_before = start.sorter->stall_fallbacks();
  return start;
}

FrameCounters Renderer::Impl::run_frame(const FramePlan& plan, SortStrategy& sorter,
                                        const ExternalDepthImage* depth_image) {
  recorder.prepare(plan, resources, sorter);
  vk::CommandStream stream(ctx);
  recorder.record(stream, plan, resources, sorter, depth_image);
  stream.finish();
  stats.submissions = stream.submissions();
  return resources.frame_counters();
}

// A frame re-renders when it wanted more (tile, Gaussian) pairs than the key buffers hold, which
// grow, or re-runs its composite when a tile's list needs more composite chunks than it had (CPU
// drivers only; the lists are complete then). A frame on reused lists cannot overflow.
FramePlan Renderer::Impl::render_frame(const Camera& camera, const RenderSettings& settings,
                                  const ExternalDepthImage* depth_image, const ScenePart& part) {
  FrameStart start = begin_frame(camera, settings, depth_image != nullptr, false, part);
  const FramePlan& plan = start.plan;
  SortStrategy& sorter = *start.sorter;
  uint32_t& chunks = recorder.composite_chunks(plan.compositor);
  std::vector<PassTiming> passes;  // the GPU time of every attempt: a re-rendered frame cost all of them
  FrameCounters frame = run_frame(plan, sorter, depth_image);
  for (int retry = 1;; ++retry) {
    add_timings(passes);
    if (frame.overflow) {
      if (retry > kMaxRetries) throw FrameResources::beyond_key_limit(frame, camera);
      resources.grow_keys_for(frame, camera, /*tight=*/!part.whole());
      frame = run_frame(plan, sorter, depth_image);
      stats.retries = retry;
      continue;
    }
    check_resort_lists(plan, frame);
    const uint32_t needed = recorder.chunks_for(plan.compositor, frame.max_tile_pairs);
    if (needed <= chunks) {
      // The next frame starts with as many chunks as this one's longest list needed (views change
      // little from frame to frame), no more: one crowded frame must not leave every later frame
      // paying for its chunks and their per-pixel state.
      chunks = needed;
      break;
    }
    if (retry > kMaxRetries) throw std::logic_error("composite chunks did not converge");  // one retry suffices
    chunks = needed;
    // The composite alone, which starts the mean of accumulated stochastic frames anew: the first
    // attempt added to the sums already.
    const FramePlan again = composite_only(plan, chunks);
    start.sums.stochastic.frames = again.stochastic_first_sample + again.stochastic_samples;
    frame = run_frame(again, sorter, depth_image);
    stats.retries = retry;
  }
  end_frame(start, frame, std::move(passes), true);
  return start.plan;
}

// The GPU time of the frame's passes, added to `passes` (summed per pass over a frame's attempts).
void Renderer::Impl::add_timings(std::vector<PassTiming>& passes) {
  double ms = 0;
  for (const auto& section : timer.read(&ms)) {
    auto it = std::find_if(passes.begin(), passes.end(), [&](const PassTiming& p) { return p.name == section.name; });
    if (it == passes.end())
      passes.push_back({section.name, section.ms});
    else
      it->gpu_ms += section.ms;
  }
  stats.gpu_ms += ms;
}

// Per-pixel re-sorting holds a tile's list in shared memory: a longer one is an error.
void Renderer::Impl::check_resort_lists(const FramePlan& plan, const FrameCounters& frame) const {
  if (plan.resort_window > 0 && frame.max_tile_pairs > 0)
    throw std::runtime_error("per-pixel re-sorting (resort" + std::to_string(plan.resort_window) + "): a tile lists " +
                             std::to_string(frame.max_tile_pairs) + " splats, more than this device's limit of " +
                             std::to_string(recorder.max_resort_splats()) + " for that mode (render without resortN)");
}

// The statistics of a completed frame; its lists become reusable when they are whole.
void Renderer::Impl::end_frame(const FrameStart& start, const FrameCounters& frame, std::vector<PassTiming> passes,
                               bool lists_whole) {
  if (lists_whole) lists = start.plan.lists;
  accumulator.frame_completed(start.sums, start.plan.stochastic_accumulate, lists_whole && stats.complete);
  stats.accumulated_frames = start.sums.stochastic.frames;  // 0 for the other compositors (no samples)
  stats.accumulated_samples = start.sums.samples ? start.sums.samples->samples : 0;
  stats.passes = std::move(passes);
  stats.reused_sorted_lists = !start.plan.build_lists;
  stats.sort_bits = start.plan.build_lists ? start.plan.sort_bits : 0;
  stats.sort_strategy = start.plan.sort.name;
  stats.gaussians = resources.scene.count;
  stats.visible = frame.visible;
  stats.saturated = frame.saturation();
  stats.intersections = frame.tile_sort.count;
  stats.sort_fallbacks = start.sorter->stall_fallbacks() - start.fallbacks_before;
  stats.device_bytes = device_bytes();
  stats.peak_device_bytes = stats.device_bytes;
  stats.uploaded_bytes = ctx.uploaded_bytes() - uploaded_bytes_reported;
  uploaded_bytes_reported = ctx.uploaded_bytes();
}

// RenderImage::host_depth: the composite's surface view depths in the host's convention, the host's
// own depth (or its far value) where the splats' alpha never reached the threshold.
void Renderer::Impl::read_host_depth(const HostDepth& host, std::vector<float>& out, size_t pixels) {
  vk::read_buffer(ctx, resources.host_surface_depth, out, pixels);
  for (size_t i = 0; i < pixels; ++i) out[i] = host_depth_out(host, out[i], i);
}

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Renderer::~Renderer() = default;

std::unique_ptr<Renderer> Renderer::create(const RendererOptions& options) {
  return RendererAccess::make(std::make_unique<Impl>(options));
}

void Renderer::set_scene(const GaussianScene& scene) {
  Impl& r = *impl_;
  r.upload_scene(scene);
  r.scene_slot.set_whole();
}

void Renderer::set_scene(SceneInstances scene) {
  set_scene(merge_instances(scene));  // where the copies are at time 0
  if (!scene.moves()) return;
  impl_->scene_slot.keep_moving_copies(std::move(scene));
}

RenderSettings Renderer::Impl::settings_over_moving_copies(const Camera& camera,
                                                           const RenderSettings& settings) {
  if (!scene_slot.has_moving_copies()) return settings;
  if (settings.shutter.opens()) return shutter_over_moving_models(settings, camera);
  place_moving_copies(0.0);
  return settings;
}

void Renderer::Impl::place_moving_copies(double time) {
  std::optional<GaussianScene> placed = scene_slot.moving_copies_at(time);
  if (!placed) return;
  upload_scene(*placed);
  scene_slot.placed(time);
}

void Renderer::Impl::upload_scene(const GaussianScene& scene) {
  wait_for_submitted_frame();  // it reads the scene's buffers
  scene_slot.uploaded();
  resources.upload_scene(scene);
}

RenderImage Renderer::Impl::average_samples(const Camera& camera, const RenderSettings& settings,
                                            const TimedSampleRenderer& render_sample) {
  const auto start = std::chrono::steady_clock::now();
  FrameStats frame;
  frame.samples = 0;
  RenderImage image =
      render_averaged(camera, settings,
                      TimedSampleRenderer([&](const Camera& sample_camera,
                                              const RenderSettings& sample_settings, double time) {
                        RenderImage sample = render_sample(sample_camera, sample_settings, time);
                        add_sample_stats(frame, stats);
                        return sample;
                      }));
  stats = frame;
  stats.cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return image;
}

Renderer::Impl::FrameInput Renderer::Impl::next_frame_input(const Camera& camera,
                                                            const RenderSettings& settings) {
  if (!settings.accumulate_samples || !averages_samples(settings)) return {camera, settings};
  check_accumulated_samples(settings, camera);
  wait_for_submitted_frame();  // the sums it leaves, if it completes, are the ones to continue
  const int index = int(accumulator.arm_next_sample(scene_slot.identity(), camera, settings));
  // Sample `index`: the camera at its time, seen from its point of the aperture (one joint sample).
  FrameInput sample{camera, settings};
  const Shutter& shutter = settings.shutter;
  if (shutter.enabled()) {
    const double time = shutter_time(shutter.open, shutter.close, shutter.pattern, index, 1);
    sample.camera = camera_between(camera, *shutter.end_camera, time);
    place_moving_copies(time);  // copies that move (set_scene of SceneInstances) where they are then
  }
  if (settings.lens.enabled())
    sample.camera =
        lens_sample_camera(sample.camera, settings.lens, lens_sample(settings.lens.pattern, index, 1));
  sample.settings.lens = {};
  sample.settings.shutter = {};
  sample.settings.accumulate_samples = false;
  return sample;
}

RenderImage Renderer::render(const Camera& camera, const RenderSettings& settings) {
  return impl_->render_set_scene(camera, impl_->settings_over_moving_copies(camera, settings));
}

RenderImage Renderer::Impl::render_set_scene(const Camera& camera, const RenderSettings& settings) {
  const bool accumulates = settings.accumulate_samples && averages_samples(settings);
  if (averages_samples(settings) && !accumulates)  // depth of field, motion blur
    return average_samples(
        camera, settings,
        [&](const Camera& sample_camera, const RenderSettings& sample_settings, double time) {
          if (settings.shutter.opens()) place_moving_copies(time);  // (a lens alone samples no time)
          return render_set_scene(sample_camera, sample_settings);
        });
  if (const std::vector<PixelRegion> bands = image_bands(camera, settings); bands.size() > 1) {
    if (accumulates)
      throw std::invalid_argument(
          "RenderSettings::accumulate_samples: the image is larger than the device renders in one band; "
          "render its samples in one call, without accumulate_samples");
    return render_bands(camera, settings, bands,
                        [&](const RenderSettings& band) { return render_set_scene(camera, band); });
  }
  const auto start = std::chrono::steady_clock::now();
  // The frame, or one more sample of the lens and the shutter added to the earlier calls' on the device.
  const FrameInput frame = next_frame_input(camera, settings);
  render_frame(frame.camera, frame.settings);
  RenderImage image = read_image(frame.camera, frame.settings);
  stats.cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return image;
}

// The frame's outputs: the whole image, or the pixels of the region's tiles, of which the region's are
// kept (frame/image_regions.h).
RenderImage Renderer::Impl::read_image(const Camera& camera, const RenderSettings& settings) {
  RenderImage image;
  image.width = int(resources.outputs.width);
  image.height = int(resources.outputs.height);
  const size_t pixels = image.pixels();
  vk::read_buffer(ctx, resources.outputs.rgba, image.rgba, pixels * 4);
  if (settings.depth) vk::read_buffer(ctx, resources.outputs.depth, image.depth, pixels);
  if (settings.splat_count) vk::read_buffer(ctx, resources.outputs.count, image.splat_count, pixels);
  if (settings.host && settings.host->write_depth) read_host_depth(*settings.host, image.host_depth, pixels);
  return crop(image, tile_aligned(settings.region, camera.width, camera.height),
              resolved_region(settings.region, camera.width, camera.height));
}

std::vector<PixelRegion> Renderer::Impl::image_bands(const Camera& camera,
                                                     const RenderSettings& settings) const {
  validate(settings.region, camera.width, camera.height);
  const PixelRegion region = resolved_region(settings.region, camera.width, camera.height);
  // The image comes back whole on the host: it must fit the machine.
  const uint64_t image_bytes = uint64_t(std::max(region.width, 0)) * uint64_t(std::max(region.height, 0)) *
                               image_bytes_per_pixel(settings);
  if (const uint64_t host = detail::host_physical_memory(); host > 0 && image_bytes > host)
    throw std::runtime_error(
        "invalid camera: image size " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
        (settings.region.whole() ? std::string() : " (region " + to_string(settings.region) + ")") +
        " needs " + std::to_string(image_bytes >> 20) +
        " MiB of host memory for its images, more than this machine's " + std::to_string(host >> 20) +
        " MiB");
  // A host's depth is the whole image's: such a frame is not split (a region refuses it).
  if (settings.host) return {region};
  const DeviceCapacity device = device_capacity();
  const uint64_t pixels = std::min(device.largest_allocation / kLargestBytesPerPixel,
                                   device.total / 4 / frame_bytes_per_pixel(settings));
  return bands_within(region, 1, pixels);
}

RenderImage Renderer::Impl::render_bands(
    const Camera& camera, const RenderSettings& settings, const std::vector<PixelRegion>& bands,
    const std::function<RenderImage(const RenderSettings&)>& render_band) {
  const auto start = std::chrono::steady_clock::now();
  const PixelRegion whole = resolved_region(settings.region, camera.width, camera.height);
  RenderImage image = image_to_assemble(whole, settings);
  FrameStats frame;
  frame.image_bands = 0;
  RenderSettings band_settings = settings;
  for (const PixelRegion& band : bands) {
    band_settings.region = band;
    paste(image, whole, render_band(band_settings), band);
    add_band_stats(frame, stats);
  }
  stats = frame;
  stats.cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return image;
}

const FrameStats& Renderer::last_frame_stats() const { return impl_->stats; }

Renderer::SortRun Renderer::sort_keys(const std::string& strategy, const std::vector<uint64_t>& keys,
                                      uint32_t key_bits) {
  check_sort_keys(keys, key_bits);
  impl_->wait_for_submitted_frame();  // the sorts' buffers are the frames'
  return run_key_sort(impl_->ctx, impl_->timer, impl_->sort(sort_strategy_for(strategy)), keys, key_bits);
}

DeviceInfo Renderer::device_info() const {
  const auto& l = impl_->ctx.limits();
  return {impl_->ctx.device_name(), impl_->ctx.driver_name(),
          l.subgroup_size,          l.max_storage_buffer_range,
          l.max_shared_memory,      l.timestamp_period_ns,
          l.max_image_dimension_2d, impl_->ctx.is_cpu_device(),
          impl_->ctx.vendor_id(),   l.max_allocation_size,
          l.device_memory};
}

uint64_t Renderer::validation_messages() const { return impl_->ctx.validation_messages(); }

std::vector<std::string> sort_strategies() { return available_sort_strategies(); }
bool sort_strategy_is_exact(const std::string& name) {
  return name == "auto" || sort_strategy_exact(name);
}

std::string Renderer::sort_strategy_for(const std::string& requested) const {
  return choose_sort_strategy(requested, impl_->device_caps(), /*without_waiting=*/false);
}
std::vector<std::string> list_devices() { return vk::Context::list_devices(); }
std::vector<std::string> list_device_uuids() {
  return vk::Context::list_device_uuids();
}

}  // namespace tilesplat
