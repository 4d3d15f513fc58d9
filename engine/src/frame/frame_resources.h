// The buffers a frame's passes read and write, and how they grow. The scene's attributes arrive with
// set_scene (upload_scene); everything else is sized from a FramePlan before the frame is recorded
// (prepare), grows when a frame wanted more pairs than the key buffers held (grow_keys_for), and is
// released when a frame does without it. device_bytes() is the memory report's part of them.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "frame/frame_plan.h"
#include "passes/composite_pass.h"
#include "passes/frame_counters.h"
#include "passes/key_buffers.h"
#include "passes/projection_pass.h"
#include "tilesplat/image.h"
#include "tilesplat/scene.h"
#include "vulkan/buffer.h"
#include "vulkan/context.h"

namespace tilesplat {

// Pairs a frame may sort: key buffer positions and the prefix sum's offsets are 32-bit.
constexpr uint64_t kMaxKeyCapacity = 1ull << 31;

class FrameResources {
 public:
  explicit FrameResources(vk::Context& ctx);

  // The scene's attributes on the device and the per-Gaussian buffers of its size. Throws
  // std::invalid_argument for inconsistent arrays, std::runtime_error for more than 2^30 Gaussians.
  // reuse_buffers (a part of a scene rendered in parts): the attributes go into the buffers already
  // there where they are large enough, and the per-Gaussian buffers are left to the frame.
  void upload_scene(const GaussianScene& scene, bool reuse_buffers = false);
  // Releases the scene's buffers and everything sized by it (projected records, pairs): before the
  // first part of a scene rendered in parts, which sizes them anew.
  void release_scene();
  // Key buffers for exactly `pairs` (tile, Gaussian) pairs (at least the minimum), made anew only when
  // their capacity differs: a frame under a memory budget holds no headroom.
  void reserve_pairs(uint64_t pairs, bool wide);
  SceneShape scene_shape(uint64_t generation) const {
    return {generation, scene.count, scene.sh_degree, scene.file_normals};
  }

  // Sizes the outputs and the host's depth buffers for the plan, uploading HostDepth::depth when the
  // plan reads it from memory (before the frame is recorded, outside any command buffer).
  void prepare_outputs(const FramePlan& plan, const std::optional<HostDepth>& host);
  // Sizes what the lists and the composite need: the key buffers' width, the re-sorting data, and
  // the composite's per-pixel state when it carries any between dispatches.
  void prepare_frame(const FramePlan& plan, bool needs_composite_state);

  // A frame that wanted more pairs than the key buffers hold: they grow, within kMaxKeyCapacity
  // (std::runtime_error naming the frame's needs beyond it, or when the device has no room), with
  // headroom for the next frames, or (tight, under a memory budget) to what this frame needs.
  void grow_keys_for(const FrameCounters& frame, const Camera& camera, bool tight = false);
  // The error of a frame whose pairs are beyond kMaxKeyCapacity.
  static std::runtime_error beyond_key_limit(const FrameCounters& frame, const Camera& camera);
  // "frame needs N tile intersections (pairs of V visible Gaussians and the WxH image's tiles)".
  static std::string intersections_needed(const FrameCounters& frame, const Camera& camera);

  FrameCounters frame_counters() const;  // what the last frame wrote (host-visible)
  uint64_t device_bytes() const;

  // What the composite of a frame without a host's depth, or with one, is given of it.
  CompositePass::HostSurface host_surface(const HostDepthPlan& host) const;

  SceneBuffers scene;
  ProjectedBuffers projected;
  KeyBuffers keys;    // the (tile, Gaussian) pairs
  vk::Buffer ranges;  // each tile's [start, end) in the sorted pairs
  OutputBuffers outputs;
  vk::Buffer counters;            // FrameCounters, read back after the frame
  vk::Buffer composite_state;     // per-pixel state between a composite's dispatches (chunks, samples)
  vk::Buffer packed_colour;       // render_to_image: the frame in the host image's texel format
  vk::Buffer sample_sums;  // RenderSettings::accumulate_samples: the samples' sums (SampleAccumulatePass)
  vk::Buffer host_view_depth;     // RenderSettings::host: the host's surfaces as view depth, per pixel
  vk::Buffer host_window_depth;   // a depth image's window depths, and the depth out before it is copied back
  vk::Buffer host_surface_depth;  // and the view depth at which the splats' alpha reached its threshold
  bool lists_in_alt = false;      // the tile lists ended in keys.values_alt (else keys.values)
  bool depth_order_in_alt = false;  // the depth sort's order ended in projected.depth_order.values_alt

 private:
  void ensure_key_capacity(uint32_t capacity, bool wide);
  void ensure_projected_records(uint32_t records);
  vk::Context& ctx_;
};

}  // namespace tilesplat
