// A scene rendered within a memory budget (Renderer::render(scene, camera, settings)), the caller's or,
// without one, the device's: whole, as set_scene and render(camera, settings) do, when its frame fits;
// else in depth-ordered parts (frame/scene_parts.h).
// Each part's Gaussians go into the same scene buffers and render as one frame of the usual plan, its
// composite carrying every pixel's state to the next part (ScenePart); the parts are sized to the budget
// from what the frame holds before any Gaussian, the bytes per Gaussian and per pair, the pairs each
// Gaussian brought in the parts before, and what the sort strategy's buffers measured.
#include <algorithm>
#include <chrono>
#include <functional>
#include <future>

#include "camera/camera_models.h"
#include "frame/averaged_frames.h"
#include "frame/frame_stats_sum.h"
#include "frame/part_sizing.h"
#include "frame/scene_parts.h"
#include "renderer_impl.h"
#include "tilesplat/lod_set.h"
#include "tilesplat/scene_description.h"

namespace tilesplat {

namespace {

// The statistics of the parts so far, with one more part's.
void add_part_stats(FrameStats& total, const FrameStats& part) {
  if (total.scene_parts == 0) {
    total = part;
    total.scene_parts = 1;
    return;
  }
  add_frame_stats(total, part, FrameCounts::kDisjoint);
  total.scene_parts += 1;
}

}  // namespace

// What a part of this frame costs on the device, with the strategy's key width.
PartCosts Renderer::Impl::part_costs_for(const PartSource& scene, const Camera& camera,
                                         const RenderSettings& settings, const std::string& sort_name) {
  const bool wide_keys = sort(sort_name).frame_plan() == FrameSortPlan::kTileDepthPairs;
  const SceneShape shape{0, uint32_t(std::min<size_t>(scene.size(), UINT32_MAX)), scene.sh_degree(),
                         scene.has_normals()};
  const uint32_t seam_copies =
      projection_variant(settings, shape, camera_models::drawn_model(camera)).seam_copies();
  return part_costs(scene, camera, settings, seam_copies, wide_keys);
}

DeviceCapacity Renderer::Impl::device_capacity() const {
  return {ctx.limits().max_allocation_size, ctx.limits().device_memory, ctx.limits().max_workgroup_count_x};
}

uint64_t Renderer::Impl::parts_memory_budget(const RenderSettings& settings) const {
  return settings.memory_budget > 0 ? settings.memory_budget : device_frame_budget(device_capacity());
}

bool Renderer::Impl::needs_parts(const PartSource& scene, const Camera& camera,
                                 const RenderSettings& settings) {
  const std::string sort_name = choose_sort_strategy(settings.sort, device_caps(), /*without_waiting=*/false);
  // An image past the device renders in bands of rows (image_bands): the largest band's frame is the one
  // that must fit, not the whole image's.
  const std::vector<PixelRegion> bands = image_bands(camera, settings);
  auto pixels = [](const PixelRegion& band) { return uint64_t(band.width) * uint64_t(band.height); };
  RenderSettings frame = settings;
  frame.region =
      *std::max_element(bands.begin(), bands.end(),
                        [&](const PixelRegion& a, const PixelRegion& b) { return pixels(a) < pixels(b); });
  const PartCosts costs = part_costs_for(scene, camera, frame, sort_name);
  return frame_needs_parts(costs, scene.size(), settings.memory_budget, device_capacity());
}

namespace {

// A part's Gaussians on the host: positions [begin, end) of the depth order, gathered (and placed, for
// copies) as a scene of their own.
struct GatheredPart {
  size_t begin = 0, end = 0;
  size_t gaussians = 0;
  GaussianScene scene;
};

GatheredPart gather_part(const PartSource& source, const DepthOrder& order, size_t begin, size_t capacity) {
  GatheredPart part;
  part.begin = begin;
  part.end = order.size() == 0 ? 0 : order.part_end(begin, capacity);
  const std::vector<uint32_t> indices = order.part_indices(part.begin, part.end);
  part.gaussians = indices.size();
  part.scene = source.gather(indices);
  return part;
}

}  // namespace

void Renderer::Impl::render_in_parts(const PartSource& scene, const Camera& camera,
                                     const RenderSettings& settings) {
  wait_for_submitted_frame();
  const std::string sort_name = choose_sort_strategy(settings.sort, device_caps(), /*without_waiting=*/false);
  const PartCosts costs = part_costs_for(scene, camera, settings, sort_name);
  const bool wide_keys = sort(sort_name).frame_plan() == FrameSortPlan::kTileDepthPairs;
  validate_scene_parts(settings, sort_name);
  const uint64_t budget = parts_memory_budget(settings);
  // The budget counts what the renderer holds, and the strategies used before keep the scratch their
  // largest frames grew: all but this frame's go (made again, by sort(), when a frame asks for them).
  std::erase_if(sorts, [&](const auto& entry) { return entry.first != sort_name; });
  PartSizer sizer(costs, budget, device_capacity());  // or a clear error when not one Gaussian fits
  const auto order_start = std::chrono::steady_clock::now();
  const DepthOrder order(scene, camera, settings.near_plane, settings.accuracy,
                         ctx.features().shader_float64 ? kDepthMarginFloat64 : kDepthMarginFloat32);
  const std::chrono::duration<double, std::milli> order_time = std::chrono::steady_clock::now() - order_start;

  // A whole scene's buffers go: the parts size their own, which the next frame under the same budget
  // reuses.
  if (scene_slot.start_parts(budget)) resources.release_scene();
  const SceneSlot::DrawingParts drawing(scene_slot);  // frames of this call's parts, and no other, run on one
  lists.reset();
  FrameStats total;
  total.scene_parts = 0;
  GatheredPart part = gather_part(scene, order, 0, sizer.capacity());
  // The next part, gathered on another thread while this one uploads and renders (on a GPU the host's
  // gathering and placing is most of a part's time). It is gathered for the capacity so far, which a part
  // can only shrink: when the next part then ends elsewhere, it is gathered again.
  std::future<GatheredPart> next;
  for (uint32_t index = 0;; ++index) {
    const bool last = part.end == order.size();
    if (!last)
      next = std::async(std::launch::async, gather_part, std::cref(scene), std::cref(order), part.end,
                        sizer.capacity());
    resources.upload_scene(part.scene, /*reuse_buffers=*/true);
    part.scene = {};
    scene_slot.uploaded();  // the lists in the buffers are the previous part's
    lists.reset();
    resources.reserve_pairs(sizer.reserved_pairs(), wide_keys);
    render_frame(camera, settings, nullptr, ScenePart{index, last});
    lists.reset();  // a part's lists are no frame's
    add_part_stats(total, stats);
    if (last) break;
    sizer.part_rendered(part.gaussians, stats.intersections, stats.device_bytes, resources.keys.bytes());
    GatheredPart gathered = next.get();
    part = order.part_end(gathered.begin, sizer.capacity()) == gathered.end
               ? std::move(gathered)
               : gather_part(scene, order, gathered.begin, sizer.capacity());
  }
  total.gaussians = scene.size();
  total.depth_order_ms = order_time.count();
  stats = total;
}

RenderImage Renderer::Impl::render_scene(const PartSource& scene, const std::function<void()>& set_whole,
                                         const Camera& camera, const RenderSettings& settings,
                                         Renderer& renderer) {
  refuse_accumulated_samples(settings, "render(scene, camera, settings), which uploads its scene each call,");
  if (!needs_parts(scene, camera, settings)) {
    set_whole();
    return renderer.render(camera, settings);
  }
  if (averages_samples(settings))  // depth of field, motion blur: every sample frame in parts
    return average_samples(camera, settings,
                           [&](const Camera& sample_camera, const RenderSettings& sample_settings, double) {
                             return render_scene(scene, set_whole, sample_camera, sample_settings, renderer);
                           });
  if (const std::vector<PixelRegion> bands = image_bands(camera, settings); bands.size() > 1)
    return render_bands(camera, settings, bands, [&](const RenderSettings& band) {
      return render_scene(scene, set_whole, camera, band, renderer);
    });
  const auto start = std::chrono::steady_clock::now();
  render_in_parts(scene, camera, settings);
  RenderImage image = read_image(camera, settings);
  stats.cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return image;
}

RenderImage Renderer::render(const GaussianScene& scene, const Camera& camera,
                             const RenderSettings& settings) {
  return impl_->render_scene(
      PartSource(scene), [&] { set_scene(scene); }, camera, settings, *this);
}

RenderImage Renderer::render(const SceneInstances& scene, const Camera& camera,
                             const RenderSettings& settings) {
  refuse_accumulated_samples(settings, "render(scene, camera, settings), which uploads its scene each call,");
  if (blurs_moving_models(scene, settings)) {
    // Moving models under an open shutter: each time sample renders the copies where they are then (and
    // the camera where it is then: still without an end camera), whole or in parts as any frame.
    return impl_->average_samples(
        camera, shutter_over_moving_models(settings, camera),
        [&](const Camera& sample_camera, const RenderSettings& sample_settings, double time) {
          return impl_->render_scene(
              PartSource(scene, time), [&] { set_scene(merge_instances(scene, time)); }, sample_camera,
              sample_settings, *this);
        });
  }
  return impl_->render_scene(
      PartSource(scene), [&] { set_scene(merge_instances(scene)); }, camera, settings, *this);
}

RenderImage Renderer::render(const SceneInParts& scene, const Camera& camera,
                             const RenderSettings& settings) {
  return impl_->render_scene(
      PartSource(scene), [&] { set_scene(scene.load()); }, camera, settings, *this);
}

bool Renderer::renders_in_parts(const GaussianScene& scene, const Camera& camera,
                                const RenderSettings& settings) {
  return impl_->needs_parts(PartSource(scene), camera, settings);
}

bool Renderer::renders_in_parts(const SceneInstances& scene, const Camera& camera,
                                const RenderSettings& settings) {
  return impl_->needs_parts(PartSource(scene), camera, settings);
}

bool Renderer::renders_in_parts(const SceneInParts& scene, const Camera& camera,
                                const RenderSettings& settings) {
  return impl_->needs_parts(PartSource(scene), camera, settings);
}

RenderImage Renderer::render(const LodSet& set, const Camera& camera, const RenderSettings& settings) {
  const GaussianScene scene = settings.splat_budget > 0
                                  ? set.load_selection(select_lod_levels(set, camera, settings.splat_budget))
                                  : set.load_level(0);
  return render(scene, camera, settings);
}

}  // namespace tilesplat
