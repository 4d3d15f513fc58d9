#include "frame/frame_resources.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "host_depth.h"
#include "passes/sample_accumulate_pass.h"
#include "passes/stochastic_composite_pass.h"

namespace tilesplat {

namespace {

constexpr uint32_t kMinKeyCapacity = 1u << 16;

uint32_t grow_capacity(uint64_t needed) {
  // Headroom so that a moving camera does not re-grow every frame.
  uint64_t target = std::max<uint64_t>(kMinKeyCapacity, needed + needed / 4);
  return uint32_t(std::min<uint64_t>(std::bit_ceil(target), kMaxKeyCapacity));
}

template <typename T>
vk::Buffer make_buffer(vk::Context& ctx, size_t count, const char* name) {
  return vk::Buffer(ctx, VkDeviceSize(count) * sizeof(T), vk::MemoryUse::Device, name);
}

}  // namespace

FrameResources::FrameResources(vk::Context& ctx)
    : counters(ctx, sizeof(FrameCounters), vk::MemoryUse::Readback, "frame counters"), ctx_(ctx) {}

void FrameResources::upload_scene(const GaussianScene& source, bool reuse_buffers) {
  const size_t n = source.size();
  if (n > (1u << 30))
    throw std::runtime_error("scene has " + std::to_string(n) + " Gaussians; the limit is 2^30");
  const int k = source.sh_coefficients();
  if (source.positions.size() != 3 * n || source.log_scales.size() != 3 * n ||
      source.rotations.size() != 4 * n || source.sh.size() != n * size_t(k) * 3 || source.sh_degree < 0 ||
      source.sh_degree > 3 || (source.has_normals() && source.normals.size() != 3 * n))
    throw std::invalid_argument("set_scene: inconsistent GaussianScene array sizes");
  SceneBuffers& s = scene;
  auto upload = [&](vk::Buffer& dst, const std::vector<float>& src, const char* name) {
    if (!reuse_buffers || dst.size() < src.size() * sizeof(float))
      dst = make_buffer<float>(ctx_, src.size(), name);
    vk::upload(ctx_, dst, src.data(), src.size() * sizeof(float));
  };
  upload(s.positions, source.positions, "positions");
  upload(s.log_scales, source.log_scales, "log scales");
  upload(s.rotations, source.rotations, "rotations");
  upload(s.opacity_logits, source.opacity_logits, "opacity logits");
  upload(s.sh, source.sh, "spherical harmonics");
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
  s.file_normals = std::any_of(source.normals.begin(), source.normals.end(), [](float v) {
    return std::isfinite(v) && std::abs(v) >= std::numeric_limits<float>::min();
  });
  if (s.file_normals) s.pending_normals = source.normals;
  s.count = uint32_t(n);
  s.sh_degree = source.sh_degree;

  if (reuse_buffers) return;  // a part of a scene: the frame sizes the rest (prepare_frame, reserve_pairs)
  projected = ProjectedBuffers();  // the previous scene's, released before this one's are made
  ensure_projected_records(uint32_t(n));
  ensure_key_capacity(grow_capacity(std::max<uint64_t>(kMinKeyCapacity, 4ull * n)), /*wide=*/false);
}

void FrameResources::release_scene() {
  scene = SceneBuffers();
  projected = ProjectedBuffers();
  keys = KeyBuffers();
}

void FrameResources::reserve_pairs(uint64_t pairs, bool wide) {
  constexpr uint64_t kMinPartPairs = 1024;  // a part's own minimum: kMinKeyCapacity would be a MiB
  const uint32_t capacity = uint32_t(std::clamp<uint64_t>(pairs, kMinPartPairs, kMaxKeyCapacity));
  if (keys.capacity != capacity || keys.wide_keys != wide) {
    keys = KeyBuffers();  // released before the new ones are made: the budget holds one set
    keys = KeyBuffers::allocate(ctx_, capacity, wide ? 64 : 32, "sort");
  }
}

// The projection's per-record buffers for at least `records` records (ProjectedBuffers): the scene's
// count, twice it for the equirectangular camera's seam copies.
void FrameResources::ensure_projected_records(uint32_t records) {
  ProjectedBuffers& p = projected;
  if (p.records >= records && p.splats) return;
  const size_t n = records;
  p.splats = vk::Buffer(ctx_, n * kSplatRecordBytes, vk::MemoryUse::Device, "projected splats");
  p.rects = make_buffer<uint64_t>(ctx_, n, "tile rects");
  p.tile_counts = make_buffer<uint32_t>(ctx_, n, "tile counts");
  p.depth_offsets = make_buffer<uint32_t>(ctx_, n, "tile offsets (depth order)");
  p.offsets = make_buffer<uint32_t>(ctx_, n, "tile offsets");
  p.big_splats = make_buffer<uint32_t>(ctx_, n, "big splats");
  p.depth_order = KeyBuffers::allocate(ctx_, records, 32, "depth");
  p.records = records;
}

// The host's buffers (RenderSettings::host): the host's surfaces as view depths (+inf where it drew
// nothing) in host_view_depth, uploaded from HostDepth::depth or converted on the device from a depth
// image (host_window_depth holds its window depths, and the depth out before it is copied back); room
// for the surface depth the composite writes. Then the output images of this frame's size: colour
// always, depth and counts only while frames ask for them (an output not asked for holds no memory).
void FrameResources::prepare_outputs(const FramePlan& plan, const std::optional<HostDepth>& host) {
  const uint32_t width = plan.tiles.width, height = plan.tiles.height;
  const size_t pixels = size_t(width) * height;
  const VkDeviceSize depth_bytes = pixels * sizeof(float);
  auto ensure = [&](vk::Buffer& buffer, bool wanted, const char* name) {
    if (!wanted)
      buffer.reset();
    else if (buffer.size() != depth_bytes)
      buffer = vk::Buffer(ctx_, depth_bytes, vk::MemoryUse::Device, name);
  };
  ensure(host_view_depth, plan.host.from_memory || plan.host.from_image, "host view depth");
  ensure(host_window_depth, plan.host.from_image, "host window depth (depth image)");
  ensure(host_surface_depth, plan.host.write_depth, "host surface depth");
  if (plan.host.from_memory) {
    const std::vector<float> view_depth = host_view_depths(*host);
    vk::upload(ctx_, host_view_depth, view_depth.data(), depth_bytes);
  }

  if (outputs.width != width || outputs.height != height) {
    outputs.rgba = vk::Buffer(ctx_, pixels * 16, vk::MemoryUse::Device, "output rgba");
    outputs.depth.reset();
    outputs.count.reset();
    outputs.width = width;
    outputs.height = height;
    ranges = vk::Buffer(ctx_, VkDeviceSize(plan.tiles.count) * 8, vk::MemoryUse::Device, "tile ranges");
  }
  outputs.first_tile = plan.tiles.packed_first();
  if (!plan.sample_sums)
    sample_sums.reset();
  else if (sample_sums.size() != SampleAccumulatePass::sums_bytes(pixels))
    sample_sums = vk::Buffer(ctx_, SampleAccumulatePass::sums_bytes(pixels), vk::MemoryUse::Device,
                             "sample sums (accumulated lens and shutter samples)");
  if (!plan.outputs.depth)
    outputs.depth.reset();
  else if (outputs.depth.size() == 0)
    outputs.depth = vk::Buffer(ctx_, pixels * 4, vk::MemoryUse::Device, "output depth");
  if (!plan.outputs.splat_count)
    outputs.count.reset();
  else if (outputs.count.size() == 0)
    outputs.count = vk::Buffer(ctx_, pixels * 4, vk::MemoryUse::Device, "output splat count");
}

void FrameResources::prepare_frame(const FramePlan& plan, bool needs_composite_state) {
  // One buffer serves every composite: the state they carry between their dispatches (chunks,
  // samples) lives only within a frame.
  // A scene rendered in parts carries the state from part to part in two halves.
  const VkDeviceSize state_bytes =
      plan.part.whole() ? std::max(CompositePass::state_bytes(plan.tiles.width, plan.tiles.height),
                                   StochasticCompositePass::state_bytes(plan.tiles.width, plan.tiles.height))
                        : CompositePass::part_state_bytes(plan.tiles.width, plan.tiles.height);
  if (needs_composite_state && composite_state.size() < state_bytes)
    composite_state =
        vk::Buffer(ctx_, state_bytes, vk::MemoryUse::Device, "composite state (chunks, samples)");
  else if (!needs_composite_state && composite_state.size() > 0)
    composite_state = vk::Buffer();  // 32 bytes a pixel that a one-dispatch composite does not use
  if (!plan.build_lists) return;
  ensure_projected_records(plan.splat_records);
  const VkDeviceSize ray_depth_bytes = VkDeviceSize(scene.count) * kRayDepthBytes;
  if (plan.projection.ray_depth && projected.ray_depth.size() < ray_depth_bytes)
    projected.ray_depth = vk::Buffer(ctx_, std::max<VkDeviceSize>(kRayDepthBytes, ray_depth_bytes),
                                     vk::MemoryUse::Device, "ray depth (re-sorting)");
  ensure_key_capacity(keys.capacity, plan.wide_keys);
}

// The pair keys are 32-bit tile ids, or 64-bit (tile, depth) keys for a strategy that sorts those
// itself (FrameSortPlan::kTileDepthPairs).
void FrameResources::ensure_key_capacity(uint32_t capacity, bool wide) {
  if (keys.capacity < capacity || keys.wide_keys != wide)
    keys = KeyBuffers::allocate(ctx_, std::max(capacity, keys.capacity), wide ? 64 : 32, "sort");
}

std::string FrameResources::intersections_needed(const FrameCounters& frame, const Camera& camera) {
  return "frame needs " + std::to_string(frame.wanted_intersections()) + " tile intersections (pairs of " +
         std::to_string(frame.visible) + " visible Gaussians and the " + std::to_string(camera.width) + "x" +
         std::to_string(camera.height) + " image's 16x16 tiles)";
}

std::runtime_error FrameResources::beyond_key_limit(const FrameCounters& frame, const Camera& camera) {
  return std::runtime_error(intersections_needed(frame, camera) + ", more than the renderer's limit of " +
                            std::to_string(kMaxKeyCapacity) + " (2^31)");
}

void FrameResources::grow_keys_for(const FrameCounters& frame, const Camera& camera, bool tight) {
  if (frame.wanted_intersections() > kMaxKeyCapacity) throw beyond_key_limit(frame, camera);
  try {  // larger key and sort buffers, which the device may not have room for
    const uint64_t wanted = frame.wanted_intersections();
    if (tight)
      reserve_pairs(wanted + wanted / 16, keys.wide_keys);
    else
      ensure_key_capacity(grow_capacity(wanted), keys.wide_keys);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(intersections_needed(frame, camera) + ": " + e.what());
  }
}

FrameCounters FrameResources::frame_counters() const {
  FrameCounters result;
  std::memcpy(&result, counters.mapped(), sizeof(result));
  return result;
}

uint64_t FrameResources::device_bytes() const {
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
                              &sample_sums,
                              &counters})
    bytes += b->size();
  return bytes + projected.depth_order.bytes() + keys.bytes();
}

CompositePass::HostSurface FrameResources::host_surface(const HostDepthPlan& host) const {
  CompositePass::HostSurface surface;
  if (!host.enabled) return surface;
  if (host_view_depth.size() > 0) surface.view_depth = &host_view_depth;
  if (host_surface_depth.size() > 0) surface.surface_depth = &host_surface_depth;
  surface.surface_alpha = host.surface_alpha;
  surface.exact_depth_order = host.exact_depth_order;
  return surface;
}

}  // namespace tilesplat
