// The frame: a fixed list of passes recorded into one command buffer.
//   projection -> depth sort -> prefix sum -> key emission -> tile sort -> tile ranges -> composite
// The Gaussians are sorted by depth once; the (tile, Gaussian) pairs are then emitted front to back
// and sorted by tile alone (stable). That is the same order as one sort of (tile << 32 | depth)
// keys, for far fewer key bits times keys: on playbot_lod0 at 1080p, 4 digit passes over 0.5M
// Gaussians plus 2 over 1.5M pairs instead of 6 over 1.5M.
// Data flows one way; the only host read-back is the counters (and the image) after the fence.
//
// The stochastic compositor (Compositor::kStochastic) needs no depth order: its frame is
//   projection -> prefix sum -> key emission -> tile binning -> tile ranges -> stochastic composite
// with the pairs grouped by tile only, and one composite dispatch per averaged sample.
// A frame whose tile lists would equal the previous frame's (same scene, camera, sort strategy,
// accuracy modes, antialiasing, lighting and compositor) runs the composite alone on the lists left
// in the buffers (FrameStats::reused_sorted_lists).
#include "tilesplat/renderer.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "host_depth.h"
#include "host_images.h"
#include "passes/composite_pass.h"
#include "passes/composite_resort_pass.h"
#include "passes/depth_quantize_pass.h"
#include "passes/frame_counters.h"
#include "passes/host_depth_pass.h"
#include "passes/key_emission_pass.h"
#include "passes/pack_colour_pass.h"
#include "passes/prefix_sum_pass.h"
#include "passes/projection_pass.h"
#include "passes/stochastic_composite_pass.h"
#include "passes/tile_coverage.h"
#include "passes/tile_ranges_pass.h"
#include "sort/sort_strategy.h"
#include "tilesplat/reference.h"
#include "tilesplat/vulkan_interop.h"
#include "vulkan/command_stream.h"
#include "vulkan/context.h"
#include "vulkan/gpu_timer.h"
#include "vulkan/vk_check.h"

namespace tilesplat {

namespace {

constexpr uint32_t kMinKeyCapacity = 1u << 16;
constexpr int kMaxRetries = 4;
// Pairs a frame may sort: key buffer positions and the prefix sum's offsets are 32-bit.
constexpr uint64_t kMaxKeyCapacity = 1ull << 31;

uint32_t grow_capacity(uint64_t needed) {
  // Headroom so that a moving camera does not re-grow every frame.
  uint64_t target = std::max<uint64_t>(kMinKeyCapacity, needed + needed / 4);
  return uint32_t(std::min<uint64_t>(std::bit_ceil(target), kMaxKeyCapacity));
}

void check_camera(const Camera& camera, const vk::DeviceLimits& limits, bool cpu_driver) {
  try {
    validate(camera);  // size, intrinsics, pose; then what this device can hold
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());  // render() reports every camera it cannot render as a runtime_error
  }
  auto fail = [](const std::string& why) { throw std::runtime_error("invalid camera: " + why); };
  // Tile rects pack each coordinate in 16 bits, and the composite dispatches one workgroup per tile.
  // On CPU drivers a shader invocation may loop over a row or column of tiles, and llvmpipe cuts
  // loops short after 65535 iterations (key_emission_big.comp): there 16384 tiles per axis.
  const uint64_t max_tiles = cpu_driver ? 16384 : std::min<uint64_t>(0xffff, limits.max_workgroup_count_x);
  const uint64_t tiles_x = (uint64_t(camera.width) + kTileSize - 1) / kTileSize;
  const uint64_t tiles_y = (uint64_t(camera.height) + kTileSize - 1) / kTileSize;
  if (tiles_x > max_tiles || tiles_y > std::min<uint64_t>(max_tiles, 0xffff))
    fail("image size " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
         " exceeds the renderer's limit of " + std::to_string(max_tiles) + " tiles (of 16 pixels) per axis");
  const uint64_t rgba_bytes = uint64_t(camera.width) * uint64_t(camera.height) * 16;
  if (rgba_bytes > limits.max_allocation_size)
    fail("image size " + std::to_string(camera.width) + "x" + std::to_string(camera.height) + " needs " +
         std::to_string(rgba_bytes >> 20) + " MiB for its colour buffer, more than the device's largest allocation (" +
         std::to_string(limits.max_allocation_size >> 20) + " MiB)");
}

// Settings the stochastic compositor cannot honour. Throws std::invalid_argument.
constexpr uint32_t kMaxStochasticFrames = 4096;
void validate_compositor(const RenderSettings& settings) {
  if (settings.compositor != Compositor::kStochastic) return;
  auto fail = [](const std::string& why) { throw std::invalid_argument("stochastic compositor: " + why); };
  const AccuracyModes& modes = settings.accuracy;
  if (modes.resort_window > 0)
    fail("per-pixel re-sorting (resort" + std::to_string(modes.resort_window) +
         ") re-orders depth-sorted lists, and this compositor sorts nothing: use the sorted compositor");
  if (modes.depth_key_bits != 32)
    fail(std::to_string(modes.depth_key_bits) +
         "-bit depth keys approximate the depth sort, which this compositor does not run (it compares full view "
         "depths): use 32-bit depth keys");
  if (settings.stochastic.frames < 1 || settings.stochastic.frames > kMaxStochasticFrames)
    fail("stochastic.frames must be 1 to " + std::to_string(kMaxStochasticFrames) + ", not " +
         std::to_string(settings.stochastic.frames));
}

// Waits for a timeline semaphore (a host's, HostCommandBuffer) to reach `value`.
VkResult wait_for_value(VkDevice device, VkSemaphore timeline, uint64_t value) {
  VkSemaphoreWaitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
  wait.semaphoreCount = 1;
  wait.pSemaphores = &timeline;
  wait.pValues = &value;
  return vkWaitSemaphores(device, &wait, UINT64_MAX);
}

template <typename T>
vk::Buffer make_buffer(vk::Context& ctx, size_t count, const char* name) {
  return vk::Buffer(ctx, VkDeviceSize(count) * sizeof(T), vk::MemoryUse::Device, name);
}

}  // namespace

struct Renderer::Impl {
  explicit Impl(const RendererOptions& opts) : Impl(opts, vk::ContextOptions{opts.device, opts.validation}) {}
  template <typename ContextSource>
  Impl(const RendererOptions& opts, const ContextSource& source)
      : options(opts),
        ctx(source),
        timer(ctx),
        projection(ctx),
        depth_quantize(ctx),
        prefix_sum(ctx),
        key_emission(ctx),
        tile_ranges(ctx),
        composite(ctx),
        pack_colour(ctx),
        host_depth(ctx),
        composite_resort(ctx),
        stochastic_composite(ctx),
        counters(ctx, sizeof(FrameCounters), vk::MemoryUse::Readback, "frame counters"),
        in_flight(ctx) {}
  // A frame recorded into a host's command buffer may still run on the buffers about to go (a frame
  // the renderer submitted itself is waited for by in_flight's destructor).
  ~Impl() {
    if (submitted && submitted->timeline != VK_NULL_HANDLE)
      wait_for_value(ctx.device(), submitted->timeline, submitted->value);  // no throwing from a destructor
  }

  SortStrategy& sort(const std::string& name) {
    auto it = sorts.find(name);
    if (it == sorts.end()) it = sorts.emplace(name, make_sort_strategy(name, ctx)).first;
    return *it->second;
  }

  // The output images of this frame's size: colour always, depth and counts only while frames ask
  // for them (an output not asked for holds no memory).
  void ensure_outputs(uint32_t width, uint32_t height, bool depth, bool count) {
    const size_t pixels = size_t(width) * height;
    if (outputs.width != width || outputs.height != height) {
      outputs.rgba = vk::Buffer(ctx, pixels * 16, vk::MemoryUse::Device, "output rgba");
      outputs.depth.reset();
      outputs.count.reset();
      outputs.width = width;
      outputs.height = height;
      const uint32_t tiles = vk::div_ceil(width, kTileSize) * vk::div_ceil(height, kTileSize);
      ranges = vk::Buffer(ctx, VkDeviceSize(tiles) * 8, vk::MemoryUse::Device, "tile ranges");
    }
    if (!depth) outputs.depth.reset();
    else if (outputs.depth.size() == 0) outputs.depth = vk::Buffer(ctx, pixels * 4, vk::MemoryUse::Device, "output depth");
    if (!count) outputs.count.reset();
    else if (outputs.count.size() == 0)
      outputs.count = vk::Buffer(ctx, pixels * 4, vk::MemoryUse::Device, "output splat count");
  }

  // The pair keys are 32-bit tile ids, or 64-bit (tile, depth) keys for a strategy that sorts
  // those itself (FrameSortPlan::kTileDepthPairs).
  void ensure_key_capacity(uint32_t capacity, bool wide) {
    if (keys.capacity < capacity || keys.wide_keys != wide)
      keys = KeyBuffers::allocate(ctx, std::max(capacity, keys.capacity), wide ? 64 : 32, "sort");
  }

  uint64_t device_bytes() const {
    uint64_t bytes = 0;
    for (const vk::Buffer* b : {&scene.positions,
                                &scene.log_scales,
                                &scene.rotations,
                                &scene.opacity_logits,
                                &scene.sh,
                                &scene.sh_half,
                                &scene.covariances_half,
                                &scene.normals,
                                &projected.splats,
                                &projected.rects,
                                &projected.tile_counts,
                                &projected.offsets,
                                &projected.depth_offsets,
                                &projected.big_splats,
                                &projected.ray_depth,
                                &ranges,
                                &composite_state,
                                &outputs.rgba,
                                &outputs.depth,
                                &outputs.count,
                                &host_view_depth,
                                &host_window_depth,
                                &host_surface_depth,
                                &packed_colour,
                                &counters})
      bytes += b->size();
    bytes += projected.depth_order.bytes() + keys.bytes();
    bytes += prefix_sum.device_bytes();
    for (const auto& [name, s] : sorts) bytes += s->device_bytes();
    return bytes;
  }

  // The projection a frame's accuracy modes call for.
  ProjectionVariant projection_variant(const RenderSettings& settings) const {
    const AccuracyModes& modes = settings.accuracy;
    ProjectionVariant v;
    v.dilation_tenths = settings.antialiasing == Antialiasing::kMip ? 1 : 3;
    v.compensate_opacity = settings.antialiasing != Antialiasing::kClassic;
    v.stored_sh_degree = scene.sh_degree;
    v.sh_degree = std::min(scene.sh_degree, modes.sh_degree_cap);
    v.sh_half = modes.fp16_sh;
    v.covariance_half = modes.fp16_covariance;
    v.opacity_extent = modes.extent == AccuracyModes::Extent::kOpacityAware;
    v.square_tiles = modes.tile_test == AccuracyModes::TileTest::kSquare;
    v.alpha_inv = coverage_alpha_inv(modes.alpha_cutoff);
    v.depth_key_bits = uint32_t(modes.depth_key_bits);
    v.ray_depth = modes.resort_window > 0;
    v.lighting = settings.lighting.enabled();
    v.file_normals = v.lighting && scene.file_normals;
    return v;
  }

  // Records and runs one frame: with build_lists, everything from the projection on; without, only
  // the composite, over the tile lists the previous frame left in the buffers (FrameStats::
  // reused_sorted_lists). Returns the counters the GPU wrote: a composite-only frame rewrites only
  // max_tile_pairs, so the others still describe the lists it read.
  FrameCounters run_frame(const Camera& camera, const RenderSettings& settings, SortStrategy& sorter,
                          bool build_lists, const ExternalDepthImage* depth_image) {
    prepare_frame(settings, sorter, build_lists, uint32_t(camera.width), uint32_t(camera.height));
    vk::CommandStream stream(ctx);
    record_frame(stream, camera, settings, sorter, build_lists, depth_image);
    stream.finish();
    stats.submissions = stream.submissions();
    return frame_counters();
  }

  FrameCounters frame_counters() const {
    FrameCounters result;
    std::memcpy(&result, counters.mapped(), sizeof(result));
    return result;
  }

  // Sizes the buffers a frame's passes will use.
  void prepare_frame(const RenderSettings& settings, SortStrategy& sorter, bool build_lists, uint32_t width,
                     uint32_t height) {
    const bool stochastic = settings.compositor == Compositor::kStochastic;
    const ProjectionVariant variant = projection_variant(settings);
    const bool needs_state = stochastic
                                 ? StochasticCompositePass::needs_state(settings.stochastic.frames, stochastic_chunks)
                                 : composite_chunks > 1;
    // One buffer serves both composites: the state they carry between their dispatches (chunks,
    // samples) lives only within a frame.
    const VkDeviceSize state_bytes = std::max(CompositePass::state_bytes(width, height),
                                              StochasticCompositePass::state_bytes(width, height));
    if (needs_state && composite_state.size() < state_bytes)
      composite_state = vk::Buffer(ctx, state_bytes, vk::MemoryUse::Device, "composite state (chunks, samples)");
    else if (!needs_state && composite_state.size() > 0)
      composite_state = vk::Buffer();  // 32 bytes a pixel that a one-dispatch composite does not use
    if (build_lists) {
      projection.prepare(scene, variant);
      if (variant.ray_depth && projected.ray_depth.size() < VkDeviceSize(scene.count) * kRayDepthBytes)
        projected.ray_depth =
            vk::Buffer(ctx, std::max<VkDeviceSize>(kRayDepthBytes, VkDeviceSize(scene.count) * kRayDepthBytes),
                       vk::MemoryUse::Device, "ray depth (re-sorting)");
      // Depth-sorted frames of a strategy that sorts (tile, depth) pairs itself use 64-bit keys; the
      // stochastic frame only bins by tile, in 32-bit keys whatever the strategy.
      const bool wide = !stochastic && sorter.frame_plan() == FrameSortPlan::kTileDepthPairs;
      ensure_key_capacity(keys.capacity, wide);
      sorter.reserve(std::max(scene.count, keys.capacity));
    }
  }

  // Records a frame's passes into the stream: the host's depth image in (when given), the lists
  // (build_lists) and the composite.
  void record_frame(vk::CommandStream& stream, const Camera& camera, const RenderSettings& settings,
                    SortStrategy& sorter, bool build_lists, const ExternalDepthImage* depth_image) {
    timer.begin_frame(stream.cmd());
    if (depth_image) {
      record_host_depth_in(stream.cmd(), *depth_image, settings.host->convention);
      timer.mark(stream.cmd(), "host_depth_in");
    }
    if (build_lists) {
      lists_in_alt = record_lists(stream, camera, settings, sorter);
    } else {
      // The composite's chunk 0 raises the longest-list counter: it starts from zero again.
      vkCmdFillBuffer(stream.cmd(), counters.handle(), offsetof(FrameCounters, max_tile_pairs), sizeof(uint32_t), 0);
      vk::barrier(stream.cmd());
    }

    const AccuracyModes& modes = settings.accuracy;
    const CompositeInputs inputs{.splats = projected.splats,
                                 .tile_lists = lists_in_alt ? keys.values_alt : keys.values,
                                 .ranges = ranges,
                                 .out = outputs,
                                 .background = settings.background,
                                 .write_depth = settings.depth,
                                 .write_count = settings.splat_count,
                                 .cutoffs = {modes.alpha_cutoff, modes.transmittance_cutoff}};
    if (settings.compositor == Compositor::kStochastic) {
      stochastic_composite.record(stream, inputs, {settings.stochastic.frames, settings.stochastic.seed},
                                  {stochastic_chunks, composite_state, counters.address()});
      timer.mark(stream.cmd(), "stochastic_composite");
    } else {
      if (modes.resort_window > 0)
        composite_resort.record(stream.cmd(), inputs, projected.ray_depth, camera,
                                uint32_t(modes.resort_window), counters.address());
      else
        composite.record(stream.cmd(), inputs, {composite_chunks, composite_state, counters.address()},
                         host_surface(settings));
      timer.mark(stream.cmd(), "composite");
    }
  }

  // Records the passes that build each tile's list into the stream, from the projection to the tile
  // ranges. Returns whether the lists ended in keys.values_alt (else keys.values).
  //   sorted:     projection -> depth sort -> prefix sum (depth order) -> key emission -> tile sort
  //               (stable, so each tile's run stays front to back) -> tile ranges
  //   stochastic: projection -> prefix sum (index order) -> key emission -> tile binning -> tile ranges
  // The stochastic frame never sorts by depth: its composite needs each tile's splats, in any order.
  // Its tile binning is the strategy's sort over the tile bits of 32-bit keys, used only to group the
  // pairs by tile (they come out in index order within a tile, being stable, which the composite
  // does not rely on).
  bool record_lists(vk::CommandStream& stream, const Camera& camera, const RenderSettings& settings,
                    SortStrategy& sorter) {
    const uint32_t tiles_x = vk::div_ceil(uint32_t(camera.width), kTileSize);
    const uint32_t tiles_y = vk::div_ceil(uint32_t(camera.height), kTileSize);
    const uint32_t tiles = tiles_x * tiles_y;
    // Tile ids run to `tiles` inclusive: the key emission's padding uses that id (never in practice).
    const uint32_t tile_bits = uint32_t(std::bit_width(tiles));
    const ProjectionVariant variant = projection_variant(settings);
    // The per-Gaussian depth key: the view depth's float bits, or fewer (AccuracyModes::depth_key_bits).
    const uint32_t depth_bits = variant.depth_key_bits;
    const uint32_t n = scene.count;
    const bool stochastic = settings.compositor == Compositor::kStochastic;

    VkCommandBuffer cmd = stream.cmd();
    vkCmdFillBuffer(cmd, counters.handle(), 0, VK_WHOLE_SIZE, 0);
    vkCmdFillBuffer(cmd, ranges.handle(), 0, VK_WHOLE_SIZE, 0);
    vkCmdFillBuffer(cmd, counters.handle(), kDepthSortOffset + offsetof(SortState, count), sizeof(uint32_t), n);
    // The nearest visible depth is a minimum over the Gaussians: it starts at the largest value.
    vkCmdFillBuffer(cmd, counters.handle(), kDepthRangeOffset, sizeof(uint32_t), 0xffffffffu);
    // The big-splat key emission's dispatch is (listed splats, 1, 1).
    vkCmdFillBuffer(cmd, counters.handle(), kBigSplatsOffset + sizeof(uint32_t), 2 * sizeof(uint32_t), 1);
    vk::barrier(cmd);

    projection.record(cmd, scene, projected, counters.address(), variant);
    vk::barrier(cmd);
    timer.mark(cmd, "projection");
    if (depth_bits == 16) {
      depth_quantize.record(cmd, projected, n, counters.address());
      vk::barrier(cmd);
      timer.mark(cmd, "depth_quantize");
    }

    if (stochastic) {
      // Offsets in index order; the key emission then writes each Gaussian's tile ids at its offset.
      prefix_sum.record(stream.cmd(), projected.tile_counts.address(), projected.offsets.address(), n,
                        counters.address());
      timer.mark(stream.cmd(), "prefix_sum");
      key_emission.record(stream.cmd(), projected, nullptr, keys, n, tiles_x, tiles, counters, variant.square_tiles,
                          variant.alpha_inv);
      vk::barrier(stream.cmd());
      timer.mark(stream.cmd(), "key_emission");
      SortInput binning{keys, counters, kTileSortOffset, tile_bits, false};
      const bool in_alt = sorter.record(stream, binning);
      timer.mark(stream.cmd(), "tile_binning");
      record_tile_ranges(stream.cmd(), in_alt, tiles);
      stats.sort_bits = tile_bits;
      return in_alt;
    }

    // Depth first: sort the Gaussians by depth, then emit the pairs front to back, so that the
    // pair sort only needs the tile bits. Otherwise the strategy sorts (tile, depth) pairs itself.
    const bool depth_first = sorter.frame_plan() == FrameSortPlan::kDepthThenTile;
    const vk::Buffer* depth_order = nullptr;
    if (depth_first) {
      SortInput depth_input{projected.depth_order, counters, kDepthSortOffset, depth_bits, true};
      depth_order = sorter.record(stream, depth_input) ? &projected.depth_order.values_alt
                                                       : &projected.depth_order.values;
      timer.mark(stream.cmd(), "depth_sort");
      prefix_sum.record(stream.cmd(), projected.tile_counts.address(), projected.depth_offsets.address(), n,
                        counters.address(), depth_order->address());
    } else {
      prefix_sum.record(stream.cmd(), projected.tile_counts.address(), projected.offsets.address(), n,
                        counters.address());
    }
    timer.mark(stream.cmd(), "prefix_sum");

    key_emission.record(stream.cmd(), projected, depth_order, keys, n, tiles_x, tiles, counters,
                        variant.square_tiles, variant.alpha_inv);
    vk::barrier(stream.cmd());
    timer.mark(stream.cmd(), "key_emission");

    // In 64-bit keys the tile id sits above bit 32 whatever the depth key's width.
    SortInput tile_input{keys, counters, kTileSortOffset, depth_first ? tile_bits : 32 + tile_bits, !depth_first};
    const bool sorted_in_alt = sorter.record(stream, tile_input);
    timer.mark(stream.cmd(), "tile_sort");
    record_tile_ranges(stream.cmd(), sorted_in_alt, tiles);
    stats.sort_bits = depth_bits + tile_bits;
    return sorted_in_alt;
  }

  void record_tile_ranges(VkCommandBuffer cmd, bool in_alt, uint32_t tiles) {
    tile_ranges.record(cmd, in_alt ? keys.keys_alt : keys.keys, keys.wide_keys, ranges, counters, kRangesArgsOffset,
                       tiles);
    vk::barrier(cmd);
    timer.mark(cmd, "tile_ranges");
  }

  std::string too_many_intersections(const FrameCounters& frame, const Camera& camera) const {
    return "frame needs " + std::to_string(frame.wanted_intersections()) + " tile intersections (pairs of " +
           std::to_string(frame.visible) + " visible Gaussians and the " + std::to_string(camera.width) + "x" +
           std::to_string(camera.height) + " image's 16x16 tiles)";
  }

  // Everything a frame's tile lists depend on. When it equals the key of the lists in the buffers,
  // a frame runs the composite alone: the background, the outputs requested, the stochastic frames
  // and seed, and the transmittance cut-off change only the composite (the whole AccuracyModes is
  // compared anyway, to keep this simple and safe).
  struct ListKey {
    uint64_t scene_generation = 0;
    Camera camera;
    std::string sort;
    AccuracyModes accuracy;
    Antialiasing antialiasing = Antialiasing::kClassic;
    Lighting lighting;
    Compositor compositor = Compositor::kSorted;  // sorted and binned-only lists differ

    bool operator==(const ListKey&) const = default;
  };

  // RenderSettings::host's buffers: the host's surfaces as view depths (+inf where it drew nothing) in
  // host_view_depth, uploaded from HostDepth::depth or converted on the device from a depth image
  // (host_window_depth holds its window depths, and the depth out before it is copied back); room
  // for the surface depth the composite writes. Each released when a frame does without it.
  void prepare_host_depth(const RenderSettings& settings, size_t pixels, bool depth_image) {
    const HostDepth* host = settings.host ? &*settings.host : nullptr;
    const VkDeviceSize bytes = pixels * sizeof(float);
    auto ensure = [&](vk::Buffer& buffer, bool wanted, const char* name) {
      if (!wanted)
        buffer.reset();
      else if (buffer.size() != bytes)
        buffer = vk::Buffer(ctx, bytes, vk::MemoryUse::Device, name);
    };
    const bool from_memory = host && !host->depth.empty();
    ensure(host_view_depth, from_memory || depth_image, "host view depth");
    ensure(host_window_depth, depth_image, "host window depth (depth image)");
    ensure(host_surface_depth, host && host->write_depth, "host surface depth");
    if (from_memory) {
      const std::vector<float> view_depth = host_view_depths(*host);
      vk::upload(ctx, host_view_depth, view_depth.data(), bytes);
    }
  }

  // The host's depth image into host_window_depth and, as view depths, into host_view_depth.
  void record_host_depth_in(VkCommandBuffer cmd, const ExternalDepthImage& image,
                            const DepthConvention& convention) {
    copy_image_to_buffer(cmd, image.image, depth_aspect(image), image.layout, host_window_depth, image.width,
                         image.height);
    vk::barrier(cmd);
    host_depth.record_view_depths(cmd, convention, host_window_depth, host_view_depth, image.width,
                                  image.height);
    vk::barrier(cmd);
  }

  // The splats' depth where they reached the threshold, and the host's own elsewhere, into the host's
  // depth image (after the frame that wrote host_surface_depth).
  void record_host_depth_out(VkCommandBuffer cmd, const ExternalDepthImage& image,
                             const DepthConvention& convention) {
    host_depth.record_window_depths(cmd, convention, host_surface_depth, host_window_depth, image.width,
                                    image.height);
    vk::barrier(cmd);
    copy_buffer_to_image(cmd, host_window_depth, image.image, depth_aspect(image), image.layout, image.width,
                         image.height);
  }

  CompositePass::HostSurface host_surface(const RenderSettings& settings) const {
    CompositePass::HostSurface surface;
    if (!settings.host) return surface;
    if (host_view_depth.size() > 0) surface.view_depth = &host_view_depth;
    if (host_surface_depth.size() > 0) surface.surface_depth = &host_surface_depth;
    surface.surface_alpha = settings.host->alpha_threshold;
    surface.exact_depth_order = settings.accuracy.depth_key_bits == 32;
    return surface;
  }

  // The frame's colour into the host's image: as it is for RGBA32F, else packed into the image's
  // texel format first (pack_colour.comp).
  void copy_colour_to_image(VkCommandBuffer cmd, const ExternalImage& target) {
    const vk::Buffer* source = &outputs.rgba;
    if (target.format != VK_FORMAT_R32G32B32A32_SFLOAT) {
      const VkDeviceSize bytes =
          VkDeviceSize(target.width) * target.height * PackColourPass::texel_bytes(target.format);
      if (packed_colour.size() < bytes)
        packed_colour = vk::Buffer(ctx, bytes, vk::MemoryUse::Device, "packed colour (render_to_image)");
      pack_colour.record(cmd, target.format, outputs.rgba, packed_colour, target.width, target.height);
      vk::barrier(cmd);  // the packing's writes before the copy's reads
      source = &packed_colour;
    }
    copy_buffer_to_image(cmd, *source, target.image, VK_IMAGE_ASPECT_COLOR_BIT, target.layout, target.width,
                         target.height);
  }

  // RenderImage::host_depth: the composite's surface view depths in the host's convention, the host's
  // own depth (or its far value) where the splats' alpha never reached the threshold.
  void read_host_depth(const HostDepth& host, std::vector<float>& out, size_t pixels) {
    read_output(host_surface_depth, out, pixels);
    for (size_t i = 0; i < pixels; ++i) out[i] = host_depth_out(host, out[i], i);
  }

  // What a frame was built for and started from, for its statistics once it completed.
  struct FrameStart {
    ListKey key;
    bool reuse = false;  // the frame runs the composite alone, on the lists in the buffers
    SortStrategy* sorter = nullptr;
    uint64_t fallbacks_before = 0;
    std::chrono::steady_clock::time_point time;
  };

  // Checks a frame's camera and settings, sizes the outputs and uploads what the frame reads from
  // the host (the host's depth values, the camera and lights unless the lists are reused). Waits for
  // a frame in flight first: its buffers are the same.
  FrameStart begin_frame(const Camera& camera, const RenderSettings& settings, bool depth_image) {
    FrameStart start;
    start.time = std::chrono::steady_clock::now();
    wait_for_submitted_frame();
    check_camera(camera, ctx.limits(), ctx.is_cpu_device());
    validate(settings.accuracy);
    validate_compositor(settings);
    validate_host_depth(settings, camera);
    prepare_host_depth(settings, size_t(camera.width) * size_t(camera.height), depth_image);
    start.sorter = &sort(settings.sort);
    ensure_outputs(uint32_t(camera.width), uint32_t(camera.height), settings.depth, settings.splat_count);
    stats = {};
    start.key = {scene_generation,      camera,
                 settings.sort,         settings.accuracy,
                 settings.antialiasing, settings.lighting,
                 settings.compositor};
    start.reuse = settings.reuse_lists && lists && *lists == start.key;
    lists.reset();  // valid again once this frame's lists are complete (not if it throws)
    // Reused lists were built with an equal camera and equal (validated) lights, which are in their
    // buffers still: nothing to upload.
    if (!start.reuse) {
      projection.set_lighting(settings.lighting, scene);  // validates the lights; uploads normals on first use
      projection.set_camera(camera);
    }
    start.fallbacks_before = start.sorter->stall_fallbacks();
    return start;
  }

  // The GPU time of the frame's passes, added to `passes` (summed per pass over a frame's attempts).
  void add_timings(std::vector<PassTiming>& passes) {
    double ms = 0;
    for (const auto& section : timer.read(&ms)) {
      auto it = std::find_if(passes.begin(), passes.end(),
                             [&](const PassTiming& p) { return p.name == section.name; });
      if (it == passes.end())
        passes.push_back({section.name, section.ms});
      else
        it->gpu_ms += section.ms;
    }
    stats.gpu_ms += ms;
  }

  uint32_t& composite_chunks_of(const RenderSettings& settings) {
    return settings.compositor == Compositor::kStochastic ? stochastic_chunks : composite_chunks;
  }
  uint32_t chunks_for(const RenderSettings& settings, uint64_t longest) const {
    return settings.compositor == Compositor::kStochastic ? stochastic_composite.chunks_for(longest)
                                                          : composite.chunks_for(longest);
  }

  // A frame that wanted more pairs than the key buffers hold: they grow, within the renderer's limit.
  std::runtime_error beyond_key_limit(const FrameCounters& frame, const Camera& camera) const {
    return std::runtime_error(too_many_intersections(frame, camera) + ", more than the renderer's limit of " +
                              std::to_string(kMaxKeyCapacity) + " (2^31)");
  }
  void grow_keys_for(const FrameCounters& frame, const Camera& camera) {
    if (frame.wanted_intersections() > kMaxKeyCapacity) throw beyond_key_limit(frame, camera);
    try {  // larger key and sort buffers, which the device may not have room for
      ensure_key_capacity(grow_capacity(frame.wanted_intersections()), keys.wide_keys);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(too_many_intersections(frame, camera) + ": " + e.what());
    }
  }

  // Per-pixel re-sorting holds a tile's list in shared memory: a longer one is an error.
  void check_resort_lists(const RenderSettings& settings, const FrameCounters& frame) const {
    if (settings.compositor != Compositor::kStochastic && settings.accuracy.resort_window > 0 &&
        frame.max_tile_pairs > 0)
      throw std::runtime_error(
          "per-pixel re-sorting (resort" + std::to_string(settings.accuracy.resort_window) +
          "): a tile lists " + std::to_string(frame.max_tile_pairs) +
          " splats, more than this device's limit of " + std::to_string(composite_resort.max_tile_splats()) +
          " for that mode (render without resortN)");
  }

  // The statistics of a completed frame; its lists become reusable when they are whole.
  void end_frame(const FrameStart& start, const FrameCounters& frame, std::vector<PassTiming> passes,
                 bool lists_whole) {
    if (lists_whole) lists = start.key;
    stats.passes = std::move(passes);
    stats.reused_sorted_lists = start.reuse;
    stats.gaussians = scene.count;
    stats.visible = frame.visible;
    stats.intersections = frame.tile_sort.count;
    stats.sort_fallbacks = start.sorter->stall_fallbacks() - start.fallbacks_before;
    stats.device_bytes = device_bytes();
    stats.uploaded_bytes = ctx.uploaded_bytes() - uploaded_bytes_reported;
    uploaded_bytes_reported = ctx.uploaded_bytes();
  }

  // Renders into the output buffers, growing the key buffers and re-rendering on overflow, and
  // fills the frame statistics (all but cpu_ms). With a depth image, each attempt converts it first.
  void render_frame(const Camera& camera, const RenderSettings& settings,
                    const ExternalDepthImage* depth_image = nullptr) {
    const FrameStart start = begin_frame(camera, settings, depth_image != nullptr);
    SortStrategy& sorter = *start.sorter;
    uint32_t& chunks = composite_chunks_of(settings);
    std::vector<PassTiming> passes;  // the GPU time of every attempt: a re-rendered frame cost all of them
    // A frame re-renders when it wanted more (tile, Gaussian) pairs than the key buffers hold, which
    // grow, or re-runs its composite when a tile's list needs more composite chunks than it had (CPU
    // drivers only; the lists are complete then). A frame on reused lists cannot overflow.
    FrameCounters frame = run_frame(camera, settings, sorter, !start.reuse, depth_image);
    for (int retry = 1;; ++retry) {
      add_timings(passes);
      if (frame.overflow) {
        if (retry > kMaxRetries) throw beyond_key_limit(frame, camera);
        grow_keys_for(frame, camera);
        frame = run_frame(camera, settings, sorter, true, depth_image);
        stats.retries = retry;
        continue;
      }
      check_resort_lists(settings, frame);
      if (chunks_for(settings, frame.max_tile_pairs) <= chunks) {
        // The next frame starts with as many chunks as this one's longest list needed (views change
        // little from frame to frame), no more: one crowded frame must not leave every later frame
        // paying for its chunks and their per-pixel state.
        chunks = chunks_for(settings, frame.max_tile_pairs);
        break;
      }
      if (retry > kMaxRetries)
        throw std::logic_error("composite chunks did not converge");  // one retry suffices
      chunks = chunks_for(settings, frame.max_tile_pairs);
      frame = run_frame(camera, settings, sorter, /*build_lists=*/false, depth_image);
      stats.retries = retry;
    }
    end_frame(start, frame, std::move(passes), true);
  }

  // A frame render_to_image did not wait for (HostFrameSync, HostCommandBuffer): what its completion needs.
  struct SubmittedFrame {
    FrameStart start;
    Camera camera;
    RenderSettings settings;  // without HostDepth::depth, which a depth image stands in for
    int submissions = 0;
    double cpu_ms = 0;
    // Recorded into a host's command buffer: complete once this timeline semaphore reaches `value`
    // (else the renderer's own submission, in_flight).
    VkSemaphore timeline = VK_NULL_HANDLE;
    uint64_t value = 0;
  };

  // Records a whole frame, its copies into the host's images included, and submits it without
  // waiting (render_to_image with HostFrameSync).
  void submit_frame(const Camera& camera, const RenderSettings& settings, const ExternalImage& target,
                    const ExternalDepthImage* depth_image, const vk::SubmitSync& sync) {
    const FrameStart start = begin_frame(camera, settings, depth_image != nullptr);
    vk::CommandStream stream(ctx);
    stream.wait_first(sync);
    record_frame_to_images(stream, start, camera, settings, target, depth_image);
    stream.submit_in_flight(in_flight, sync);
    keep_submitted(start, camera, settings, stream.submissions());
  }

  // Records a whole frame, its copies into the host's images included, into the host's command buffer
  // (render_to_image with HostCommandBuffer), which the host submits and reports complete through its
  // timeline semaphore.
  void record_frame_into(const HostCommandBuffer& host, const Camera& camera, const RenderSettings& settings,
                         const ExternalImage& target, const ExternalDepthImage* depth_image) {
    if (sort(settings.sort).sorts_on_host())
      throw std::invalid_argument(
          "render_to_image: the sort strategy '" + settings.sort +
          "' sorts on the host in the middle of the frame, which a command buffer of the "
          "host's cannot hold: use a GPU strategy, or HostFrameSync");
    const FrameStart start = begin_frame(camera, settings, depth_image != nullptr);
    vk::CommandStream stream(ctx, host.command_buffer);
    record_frame_to_images(stream, start, camera, settings, target, depth_image);
    stream.end_borrowed();
    keep_submitted(start, camera, settings, 0, host.timeline, host.value);
  }

  // A frame that goes on without the renderer waiting for it (submit_frame, record_frame_into): its
  // whole recording, from the buffers' sizes to the copies into the host's images.
  void record_frame_to_images(vk::CommandStream& stream, const FrameStart& start, const Camera& camera,
                              const RenderSettings& settings, const ExternalImage& target,
                              const ExternalDepthImage* depth_image) {
    prepare_frame(settings, *start.sorter, !start.reuse, uint32_t(camera.width), uint32_t(camera.height));
    record_frame(stream, camera, settings, *start.sorter, !start.reuse, depth_image);
    record_copies_to_images(stream.cmd(), settings, target, depth_image);
  }

  // What the host sees of a frame: its colour, and with a depth image and write_depth, the splats' depth.
  void record_copies_to_images(VkCommandBuffer cmd, const RenderSettings& settings,
                               const ExternalImage& target, const ExternalDepthImage* depth_image) {
    copy_colour_to_image(cmd, target);
    if (depth_image && settings.host->write_depth)
      record_host_depth_out(cmd, *depth_image, settings.host->convention);
  }

  void keep_submitted(const FrameStart& start, const Camera& camera, const RenderSettings& settings,
                      int submissions, VkSemaphore timeline = VK_NULL_HANDLE, uint64_t value = 0) {
    RenderSettings kept = settings;
    kept.host
        .reset();  // only the compositor and modes are looked at again, and HostDepth::depth is not owned
    const double cpu_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start.time).count();
    submitted = SubmittedFrame{start, camera, std::move(kept), submissions, cpu_ms, timeline, value};
  }

  // Waits for the frame in flight, if any, and makes its statistics the last frame's. It cannot
  // re-render: a frame that overflowed the key buffers or had too few composite chunks was drawn
  // without what did not fit (FrameStats::complete false), and the next frame has what it needs.
  void wait_for_submitted_frame() {
    if (!submitted) return;
    const SubmittedFrame frame_info = std::move(*submitted);
    submitted.reset();
    if (frame_info.timeline != VK_NULL_HANDLE)
      TS_VK_CHECK(wait_for_value(ctx.device(), frame_info.timeline, frame_info.value));
    else
      in_flight.wait();
    const FrameCounters frame = frame_counters();
    stats = {};
    std::vector<PassTiming> passes;
    add_timings(passes);
    stats.submissions = frame_info.submissions;
    stats.cpu_ms = frame_info.cpu_ms;
    const RenderSettings& settings = frame_info.settings;
    uint32_t& chunks = composite_chunks_of(settings);
    bool lists_whole = !frame.overflow;
    if (frame.overflow) {
      stats.complete = false;
      grow_keys_for(frame, frame_info.camera);
    } else {
      check_resort_lists(settings, frame);
      stats.complete = chunks_for(settings, frame.max_tile_pairs) <= chunks;
      chunks = chunks_for(settings, frame.max_tile_pairs);
    }
    end_frame(frame_info.start, frame, std::move(passes), lists_whole);
  }

  template <typename T>
  void read_output(const vk::Buffer& buffer, std::vector<T>& out, size_t count) {
    out.resize(count);
    if (count == 0) return;  // memcpy must not see the null data() of an empty vector
    if (buffer.mapped()) {
      std::memcpy(out.data(), buffer.mapped(), count * sizeof(T));
      return;
    }
    vk::Buffer staging(ctx, count * sizeof(T), vk::MemoryUse::Readback, buffer.name() + " (readback)");
    ctx.submit_and_wait([&](VkCommandBuffer cmd) {
      VkBufferCopy region{0, 0, count * sizeof(T)};
      vkCmdCopyBuffer(cmd, buffer.handle(), staging.handle(), 1, &region);
    });
    std::memcpy(out.data(), staging.mapped(), count * sizeof(T));
  }

  RendererOptions options;
  vk::Context ctx;
  vk::GpuTimer timer;
  ProjectionPass projection;
  DepthQuantizePass depth_quantize;
  PrefixSumPass prefix_sum;
  KeyEmissionPass key_emission;
  TileRangesPass tile_ranges;
  CompositePass composite;
  PackColourPass pack_colour;  // render_to_image into a colour image of another format than RGBA32F
  HostDepthPass host_depth;    // render_to_image with a depth image
  CompositeResortPass composite_resort;
  StochasticCompositePass stochastic_composite;
  std::map<std::string, std::unique_ptr<SortStrategy>> sorts;

  SceneBuffers scene;
  ProjectedBuffers projected;
  KeyBuffers keys;
  vk::Buffer ranges;
  OutputBuffers outputs;
  vk::Buffer counters;
  // Dispatches per composite (CompositePass::Chunks), kept for later frames once a scene needed more.
  uint32_t composite_chunks = 1;
  uint32_t stochastic_chunks = 1;  // the same for the stochastic composite
  vk::Buffer composite_state;  // per-pixel state between a composite's dispatches (chunks, samples)
  vk::Buffer packed_colour;    // render_to_image: the frame in the host image's texel format
  vk::Buffer host_view_depth;  // RenderSettings::host: the host's surfaces as view depth, per pixel
  vk::Buffer host_window_depth;   // a depth image's window depths, and the depth out before it is copied back
  vk::Buffer host_surface_depth;  // and the view depth at which the splats' alpha reached its threshold
  FrameStats stats;
  // The tile lists in the buffers: what they were built for (none after set_scene or a frame that
  // failed), and where the tile sort or binning left them.
  std::optional<ListKey> lists;
  bool lists_in_alt = false;
  uint64_t scene_generation = 0;  // counts set_scene calls
  uint64_t uploaded_bytes_reported = 0;  // vk::Context::uploaded_bytes() at the last frame's statistics
  std::optional<SubmittedFrame> submitted;  // the frame render_to_image submitted without waiting
  // Its fence and command buffer: declared last, so that it is destroyed first and waits for the
  // frame before any buffer the frame uses goes.
  vk::InFlightSubmission in_flight;
};

// How the functions of vulkan_interop.h, which are not members, reach a renderer's implementation.
struct RendererAccess {
  static Renderer::Impl& impl(Renderer& renderer) { return *renderer.impl_; }
  static std::unique_ptr<Renderer> make(std::unique_ptr<Renderer::Impl> impl) {
    return std::unique_ptr<Renderer>(new Renderer(std::move(impl)));
  }
};

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Renderer::~Renderer() = default;

std::unique_ptr<Renderer> Renderer::create(const RendererOptions& options) {
  return RendererAccess::make(std::make_unique<Impl>(options));
}

void Renderer::set_scene(const GaussianScene& scene) {
  Impl& r = *impl_;
  r.wait_for_submitted_frame();  // it reads the scene's buffers
  ++r.scene_generation;  // the tile lists in the buffers are the previous scene's
  const size_t n = scene.size();
  if (n > (1u << 30)) throw std::runtime_error("scene has " + std::to_string(n) + " Gaussians; the limit is 2^30");
  const int k = scene.sh_coefficients();
  if (scene.positions.size() != 3 * n || scene.log_scales.size() != 3 * n || scene.rotations.size() != 4 * n ||
      scene.sh.size() != n * size_t(k) * 3 || scene.sh_degree < 0 || scene.sh_degree > 3 ||
      (scene.has_normals() && scene.normals.size() != 3 * n))
    throw std::invalid_argument("set_scene: inconsistent GaussianScene array sizes");
  SceneBuffers& s = r.scene;
  auto upload = [&](vk::Buffer& dst, const std::vector<float>& src, const char* name) {
    dst = make_buffer<float>(r.ctx, src.size(), name);
    vk::upload(r.ctx, dst, src.data(), src.size() * sizeof(float));
  };
  upload(s.positions, scene.positions, "positions");
  upload(s.log_scales, scene.log_scales, "log scales");
  upload(s.rotations, scene.rotations, "rotations");
  upload(s.opacity_logits, scene.opacity_logits, "opacity logits");
  upload(s.sh, scene.sh, "spherical harmonics");
  s.sh_half.reset();  // the previous scene's half-precision copies (made again on first use)
  s.covariances_half.reset();
  // Relighting's normals are uploaded on the first lit frame (ProjectionPass::set_lighting), never for a
  // scene rendered unlit. Until then a host copy is kept, as the caller may drop its scene: 12 bytes a
  // splat of host memory, freed on upload, instead of as much device memory held by every unlit
  // scene. A file whose normals are all zero (the original trainer writes nx = ny = nz = 0) or
  // unusable keeps nothing: every splat falls back to its shortest axis, with no buffer to read.
  s.normals.reset();
  s.pending_normals.clear();
  s.pending_normals.shrink_to_fit();
  s.file_normals = std::any_of(scene.normals.begin(), scene.normals.end(), [](float v) {
    return std::isfinite(v) && std::abs(v) >= std::numeric_limits<float>::min();
  });
  if (s.file_normals) s.pending_normals = scene.normals;
  s.count = uint32_t(n);
  s.sh_degree = scene.sh_degree;

  ProjectedBuffers& p = r.projected;
  p.splats = vk::Buffer(r.ctx, n * kSplatRecordBytes, vk::MemoryUse::Device, "projected splats");
  p.rects = make_buffer<uint64_t>(r.ctx, n, "tile rects");
  p.tile_counts = make_buffer<uint32_t>(r.ctx, n, "tile counts");
  p.depth_offsets = make_buffer<uint32_t>(r.ctx, n, "tile offsets (depth order)");
  p.offsets = make_buffer<uint32_t>(r.ctx, n, "tile offsets");
  p.big_splats = make_buffer<uint32_t>(r.ctx, n, "big splats");
  p.depth_order = KeyBuffers::allocate(r.ctx, uint32_t(n), 32, "depth");
  r.ensure_key_capacity(grow_capacity(std::max<uint64_t>(kMinKeyCapacity, 4ull * n)), /*wide=*/false);
}

RenderImage Renderer::render(const Camera& camera, const RenderSettings& settings) {
  Impl& r = *impl_;
  const auto start = std::chrono::steady_clock::now();
  r.render_frame(camera, settings);
  RenderImage image;
  image.width = camera.width;
  image.height = camera.height;
  const size_t pixels = image.pixels();
  r.read_output(r.outputs.rgba, image.rgba, pixels * 4);
  if (settings.depth) r.read_output(r.outputs.depth, image.depth, pixels);
  if (settings.splat_count) r.read_output(r.outputs.count, image.splat_count, pixels);
  if (settings.host && settings.host->write_depth)
    r.read_host_depth(*settings.host, image.host_depth, pixels);
  r.stats.cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return image;
}

std::unique_ptr<Renderer> create_renderer(const ExternalVulkanDevice& device, const RendererOptions& options) {
  return RendererAccess::make(std::make_unique<Renderer::Impl>(options, device));
}

void render_to_image(Renderer& renderer, const Camera& camera, const RenderSettings& settings,
                     const ExternalImage& target) {
  Renderer::Impl& r = RendererAccess::impl(renderer);
  check_images(target, nullptr, camera, settings);
  const auto start = std::chrono::steady_clock::now();
  r.render_frame(camera, settings);
  r.ctx.submit_and_wait(
      [&](VkCommandBuffer cmd) { r.record_copies_to_images(cmd, settings, target, nullptr); });
  r.stats.cpu_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void render_to_image(Renderer& renderer, const Camera& camera, const RenderSettings& settings,
                     const ExternalImage& target, const ExternalDepthImage& depth) {
  Renderer::Impl& r = RendererAccess::impl(renderer);
  check_images(target, &depth, camera, settings);
  const auto start = std::chrono::steady_clock::now();
  r.render_frame(camera, settings, &depth);
  r.ctx.submit_and_wait(
      [&](VkCommandBuffer cmd) { r.record_copies_to_images(cmd, settings, target, &depth); });
  r.stats.cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void render_to_image(Renderer& renderer, const Camera& camera, const RenderSettings& settings,
                     const ExternalImage& target, const ExternalDepthImage* depth,
                     const HostFrameSync& sync) {
  Renderer::Impl& r = RendererAccess::impl(renderer);
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
  r.submit_frame(camera, settings, target, depth,
                 {sync.wait, sync.wait_stages, sync.wait_values, sync.signal, sync.signal_values});
}

void render_to_image(Renderer& renderer, const Camera& camera, const RenderSettings& settings,
                     const ExternalImage& target, const ExternalDepthImage* depth,
                     const HostCommandBuffer& commands) {
  Renderer::Impl& r = RendererAccess::impl(renderer);
  check_images(target, depth, camera, settings);
  if (commands.command_buffer == VK_NULL_HANDLE)
    throw std::invalid_argument("render_to_image: HostCommandBuffer has no command buffer");
  if (commands.timeline == VK_NULL_HANDLE)
    throw std::invalid_argument(
        "render_to_image: HostCommandBuffer has no timeline semaphore to say when the frame has completed");
  r.record_frame_into(commands, camera, settings, target, depth);
}

void wait_for_frame(Renderer& renderer) {
  RendererAccess::impl(renderer).wait_for_submitted_frame();
}

const FrameStats& Renderer::last_frame_stats() const { return impl_->stats; }

Renderer::SortRun Renderer::sort_keys(const std::string& strategy, const std::vector<uint64_t>& keys,
                                      uint32_t key_bits) {
  if (key_bits < 1 || key_bits > 64)
    throw std::invalid_argument("sort_keys: key_bits must be 1 to 64, not " + std::to_string(key_bits));
  if (keys.size() > (1u << 31))
    throw std::invalid_argument("sort_keys: " + std::to_string(keys.size()) + " keys, more than 2^31");
  impl_->wait_for_submitted_frame();  // the sorts' buffers are the frames'
  const uint64_t allowed = key_bits == 64 ? ~0ull : (1ull << key_bits) - 1;
  for (size_t i = 0; i < keys.size(); ++i)
    if (keys[i] & ~allowed)
      throw std::invalid_argument("sort_keys: key " + std::to_string(i) + " has bits above the " +
                                  std::to_string(key_bits) + " key bits");

  Impl& r = *impl_;
  SortStrategy& sorter = r.sort(strategy);
  const uint32_t n = uint32_t(keys.size());
  const uint32_t capacity = std::max<uint32_t>(n, 1);
  KeyBuffers kb = KeyBuffers::allocate(r.ctx, capacity, key_bits, "sort_keys");
  std::vector<uint32_t> positions(n);
  for (uint32_t i = 0; i < n; ++i) positions[i] = i;
  if (n > 0) {
    const std::vector<uint8_t> packed = kb.pack_keys(keys);
    vk::upload(r.ctx, kb.keys, packed.data(), packed.size());
    vk::upload(r.ctx, kb.values, positions.data(), VkDeviceSize(n) * sizeof(uint32_t));
  }
  vk::Buffer state(r.ctx, sizeof(SortState), vk::MemoryUse::Readback, "sort_keys state");
  SortState initial{};
  initial.count = n;
  std::memcpy(state.mapped(), &initial, sizeof(initial));

  sorter.reserve(capacity);
  const uint64_t fallbacks_before = sorter.stall_fallbacks();
  vk::CommandStream stream(r.ctx);
  r.timer.begin_frame(stream.cmd());
  SortInput input{kb, state, 0, key_bits};
  const bool in_alt = sorter.record(stream, input);
  r.timer.mark(stream.cmd(), "sort");
  stream.finish();

  SortRun run;
  r.timer.read(&run.gpu_ms);
  run.fallbacks = sorter.stall_fallbacks() - fallbacks_before;
  std::vector<uint8_t> sorted_keys;
  r.read_output(in_alt ? kb.keys_alt : kb.keys, sorted_keys, size_t(n) * kb.key_bytes());
  run.keys = kb.unpack_keys(sorted_keys.data(), n);
  r.read_output(in_alt ? kb.values_alt : kb.values, run.order, n);
  return run;
}

DeviceInfo Renderer::device_info() const {
  const auto& l = impl_->ctx.limits();
  return {impl_->ctx.device_name(), impl_->ctx.driver_name(), l.subgroup_size, l.max_storage_buffer_range,
          l.max_shared_memory,      l.timestamp_period_ns,    l.max_image_dimension_2d};
}

uint64_t Renderer::validation_messages() const { return impl_->ctx.validation_messages(); }

std::vector<std::string> sort_strategies() { return available_sort_strategies(); }
bool sort_strategy_is_exact(const std::string& name) { return sort_strategy_exact(name); }
std::vector<std::string> list_devices() { return vk::Context::list_devices(); }
std::vector<std::string> list_device_uuids() {
  return vk::Context::list_device_uuids();
}

}  // namespace tilesplat
