// A scene rendered in parts that follow the frame's depth order (Renderer::render(scene, camera,
// settings) under RenderSettings::memory_budget; renderer_parts.cpp runs them). The host sorts the
// Gaussians once by the depth the GPU sorts them by (view z, or the distance for the fisheye and the
// panorama and in radial sorting); each part is then a run of consecutive Gaussians of that order, uploaded
// in scene order, projected, sorted and composited like a frame, with each pixel's state carried from part to
// part.
//
// The GPU sorts each part again by its own float keys and breaks ties by scene index, so a part may
// end only where the host's order and the GPU's cannot disagree: where every Gaussian before the
// boundary has a smaller key than every Gaussian after it, however the GPU rounds its depth (within a
// margin of the depth's magnitude, kDepthMarginFloat64 or kDepthMarginFloat32). Then each tile's lists,
// concatenated over the parts, are the whole frame's list, and the image is the whole frame's, bit for bit.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "scene/scene_merge.h"
#include "tilesplat/camera.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"
#include "tilesplat/scene_in_parts.h"

namespace tilesplat {

// How far the GPU's view depth of a Gaussian may lie from the host's float64 one, relative to the
// magnitudes it is computed from (|x - camera| and |camera|). The projection computes in float64
// where the device has it (the last bits may differ, by FMA contraction and summation order), else in
// float32, within a few 1e-7 of them: the margins are far above either.
constexpr double kDepthMarginFloat64 = 1e-12;
constexpr double kDepthMarginFloat32 = 2e-6;

// The Gaussians a scene in parts draws from: one GaussianScene; the placed copies of a SceneInstances,
// numbered as in their merged scene (merge_instances), whose parts it places one Gaussian at a time (so
// that a scene of many copies is never held whole), each copy where it is at `time`
// (SceneInstances::Instance::at); or a SceneInParts, whose parts are decoded from its file (a PLY) or packed
// bytes (an SPZ).
class PartSource {
 public:
  explicit PartSource(const GaussianScene& scene);
  explicit PartSource(const SceneInParts& scene);
  explicit PartSource(const SceneInstances& scene, double time = 0);

  size_t size() const { return size_; }
  int sh_degree() const;
  bool has_normals() const;
  // Gaussian i's position, as the merged scene holds it and the GPU reads it.
  std::array<float, 3> position(size_t i) const;
  // The Gaussians `indices` (ascending) as a scene of their own: the merged scene's Gaussians, bit for bit.
  GaussianScene gather(std::span<const uint32_t> indices) const;

 private:
  const GaussianScene* scene_ = nullptr;
  const SceneInstances* instances_ = nullptr;
  const detail::PartRows* mapped_ = nullptr;
  std::vector<size_t>
      first_;  // instances: each instance's first Gaussian in the merged scene, then the total
  std::vector<ModelTransform> transforms_;  // instances: each one's at the time
  std::vector<detail::PositionPlacement> placements_;
  size_t size_ = 0;
};

class DepthOrder {
 public:
  // The Gaussians the GPU may draw (those clearly behind the near plane, or with non-finite depths,
  // are left out), front to back by the frame's sort depth (`modes.sort_depth`) in its depth keys
  // (`modes.depth_key_bits`: 24 or 32; std::invalid_argument otherwise); relative_margin
  // kDepthMarginFloat64 or kDepthMarginFloat32, as the device projects. `threads`: the host threads it
  // computes on; 0 for as many as the scene's size calls for, up to the host's cores (the result is the
  // same for any).
  DepthOrder(const PartSource& scene, const Camera& camera, double near_plane, const AccuracyModes& modes,
             double relative_margin, unsigned threads = 0);
  // The view depth order in `depth_key_bits`-bit keys.
  DepthOrder(const PartSource& scene, const Camera& camera, double near_plane, int depth_key_bits,
             double relative_margin, unsigned threads = 0)
      : DepthOrder(scene, camera, near_plane, AccuracyModes{.depth_key_bits = depth_key_bits},
                   relative_margin, threads) {}

  size_t size() const { return order_.size(); }
  // The scene index of the Gaussian at `position` (< size()) of the order.
  uint32_t index(size_t position) const { return order_[position]; }
  // The end of the part that starts at `begin` (< size()) and should hold at most `most` (>= 1)
  // Gaussians: the last boundary where a part may end in (begin, begin + most], else the first after
  // it (a part larger than asked, where the keys leave no gap sooner), else size().
  size_t part_end(size_t begin, size_t most) const;
  // Whether a part may end before position i (0 < i < size(); size() always).
  bool boundary(size_t i) const;
  // The scene indices of positions [begin, end), ascending: the order the GPU breaks ties in.
  std::vector<uint32_t> part_indices(size_t begin, size_t end) const;

 private:
  std::vector<uint32_t> order_;      // scene indices, front to back
  std::vector<uint32_t> upper_max_;  // upper_max_[i]: the largest key any of positions [0, i] may get
  std::vector<uint32_t> lower_min_;  // lower_min_[i]: the smallest key any of positions [i, size) may get
};

// The Gaussians `indices` of `scene`, in that order, as a scene of their own.
GaussianScene gather_gaussians(const GaussianScene& scene, std::span<const uint32_t> indices);

// What a part holds on the device, for sizing parts under a memory budget: the frame's buffers that do
// not depend on the part (outputs, the carried state, tile ranges, a host's depth), and the bytes per
// Gaussian (attributes and projected records) and per (tile, Gaussian) pair (key buffers). The sort
// strategy's own buffers are measured as the parts run (renderer_parts.cpp). A device also caps each
// buffer (its largest allocation): the largest buffer that grows with the Gaussians takes
// largest_per_gaussian bytes for each (their spherical harmonics, or their projected records), the
// largest that grows with the pairs largest_per_pair (0: no such cap is reckoned). And it caps a
// dispatch's workgroups: the dispatches over the Gaussians have invocations_per_gaussian for each (their
// projected records), kWorkgroupSize to a workgroup.
struct PartCosts {
  uint64_t fixed = 0;
  uint64_t per_gaussian = 0;
  uint64_t per_pair = 0;
  uint64_t largest_per_gaussian = 0;
  uint64_t largest_per_pair = 0;
  uint64_t invocations_per_gaussian = 0;
};
// The workgroup size of the passes that run an invocation per record (projection, key emission, ...).
constexpr uint64_t kWorkgroupSize = 256;
PartCosts part_costs(const PartSource& scene, const Camera& camera, const RenderSettings& settings,
                     uint32_t seam_copies, bool wide_keys);

// What a device holds at most: its largest allocation (VkPhysicalDeviceMaintenance3Properties), its
// memory (vk::DeviceLimits::device_memory), and the workgroups of one dispatch (maxComputeWorkGroupCount).
struct DeviceCapacity {
  uint64_t largest_allocation = UINT64_MAX;
  uint64_t total = UINT64_MAX;
  uint64_t max_workgroups = UINT64_MAX;
};

// The most Gaussians a part may hold when `budget` bytes are to cover costs.fixed, `overhead` bytes
// measured besides, and each Gaussian with `pairs_per_gaussian` pairs, no buffer being larger than the
// device's largest allocation and no dispatch larger than its workgroup count (device.total is not
// read: the budget stands for it). Throws std::invalid_argument when not even one fits, naming the
// budget and what the frame needs before any Gaussian.
size_t part_capacity(uint64_t budget, const PartCosts& costs, uint64_t overhead, double pairs_per_gaussian,
                     const DeviceCapacity& device = {});
// The share of the device's memory a frame without a budget may take: the rest is left to the host
// application, the pipelines, and (on a CPU driver, whose device memory is the host's) the scene itself.
constexpr double kDeviceMemoryShare = 0.75;
uint64_t device_frame_budget(const DeviceCapacity& device);
// Whether a whole frame of `gaussians` (with `pairs_per_gaussian` pairs each, and the key buffers' growth
// headroom) fits the device: each buffer within its largest allocation, each dispatch within its
// workgroup count, and all of the buffers within device_frame_budget. A frame that does not is rendered
// in parts under that budget.
bool whole_frame_fits(const PartCosts& costs, size_t gaussians, double pairs_per_gaussian,
                      const DeviceCapacity& device);

}  // namespace tilesplat
