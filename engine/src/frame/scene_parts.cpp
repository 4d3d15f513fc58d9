#include "frame/scene_parts.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>
#include <string>

#include "camera/camera_models.h"
#include "frame/image_regions.h"
#include "host_resources.h"
#include "passes/projection_pass.h"
#include "scene/part_rows.h"
#include "sort/parallel_radix_sort.h"
#include "tilesplat/reference.h"
#include "tilesplat/sort.h"

namespace tilesplat {

namespace {

// The depth the projection sorts by: the distance for the models that project by direction (fisheye,
// panorama) and in radial sorting, the view z otherwise (projection.comp, project_centre and DISTANCE_KEY).
bool sorts_by_distance(const Camera& camera, AccuracyModes::SortDepth sort_depth) {
  return camera_models::depth_is_distance(camera_models::drawn_model(camera)) ||
         sort_depth == AccuracyModes::SortDepth::kDistance;
}

// A depth's key as the projection forms it: the float's bits (positive floats order as integers),
// their top 24 for 24-bit keys. Depths at or below 0 (lower bounds only) are key 0.
uint32_t depth_key(double depth, int key_bits) {
  const float f = depth > 0 ? float(depth) : 0.0f;
  return std::bit_cast<uint32_t>(f) >> (32 - key_bits);
}

}  // namespace

PartSource::PartSource(const GaussianScene& scene) : scene_(&scene), size_(scene.size()) {}

PartSource::PartSource(const SceneInParts& scene) : mapped_(scene.rows_.get()), size_(scene.size()) {}

PartSource::PartSource(const SceneInstances& scene, double time) : instances_(&scene) {
  for (const SceneInstances::Instance& instance : scene.instances) {
    first_.push_back(size_);
    size_ += scene.files.at(instance.file).size();
    transforms_.push_back(instance.at(time));
    placements_.emplace_back(transforms_.back());
  }
  first_.push_back(size_);
}

int PartSource::sh_degree() const {
  return scene_ ? scene_->sh_degree : mapped_ ? mapped_->sh_degree() : instances_->sh_degree;
}
bool PartSource::has_normals() const {
  return scene_ ? scene_->has_normals() : mapped_ ? mapped_->has_normals() : instances_->normals;
}

std::array<float, 3> PartSource::position(size_t i) const {
  if (scene_) return {scene_->positions[3 * i], scene_->positions[3 * i + 1], scene_->positions[3 * i + 2]};
  if (mapped_) return mapped_->position(i);
  const size_t k = size_t(std::upper_bound(first_.begin(), first_.end(), i) - first_.begin()) - 1;
  const GaussianScene& file = instances_->files[instances_->instances[k].file];
  const size_t local = i - first_[k];
  return placements_[k].place(&file.positions[3 * local], local);
}

GaussianScene PartSource::gather(std::span<const uint32_t> indices) const {
  if (scene_) return gather_gaussians(*scene_, indices);
  if (mapped_) return mapped_->gather(indices);
  // Instance by instance (the indices ascend): its Gaussians gathered, placed as transform_scene places
  // them and appended as the merged scene appends them.
  GaussianScene part;
  detail::reserve_merged(part, indices.size(), instances_->sh_degree, instances_->normals);
  std::vector<uint32_t> local;
  for (size_t next = 0; next < indices.size();) {
    const size_t k =
        size_t(std::upper_bound(first_.begin(), first_.end(), size_t(indices[next])) - first_.begin()) - 1;
    local.clear();
    for (; next < indices.size() && indices[next] < first_[k + 1]; ++next)
      local.push_back(uint32_t(indices[next] - first_[k]));
    const SceneInstances::Instance& instance = instances_->instances[k];
    detail::append_merged(
        part, transform_scene(gather_gaussians(instances_->files[instance.file], local), transforms_[k]),
        instances_->normals);
  }
  return part;
}

namespace {

struct DepthBounds {
  double depth, margin;
};

// Gaussian i's depth, and how far the GPU's may lie from it: computed again where needed rather than
// stored (16 bytes a Gaussian of a scene that may be 100M). Each thread of the depth order works on a copy
// of its own: read through references into the caller's stack, the camera shares cache lines with the
// caller's own loop variables, and the threads slow each other down (measured: four times slower on two
// threads than on one).
class GaussianDepths {
 public:
  GaussianDepths(const PartSource& scene, const Camera& camera, AccuracyModes::SortDepth sort_depth,
                 double relative_margin)
      : scene_(&scene),
        camera_(camera),
        distance_(sorts_by_distance(camera, sort_depth)),
        centre_size_(std::abs(camera.position[0]) + std::abs(camera.position[1]) +
                     std::abs(camera.position[2])),
        relative_margin_(relative_margin) {}

  DepthBounds operator()(size_t i) const {
    const std::array<float, 3> position = scene_->position(i);
    const std::array<double, 3> world = {double(position[0]), double(position[1]), double(position[2])};
    const std::array<double, 3> t = camera_.to_camera(world);
    const double rel = std::abs(world[0] - camera_.position[0]) + std::abs(world[1] - camera_.position[1]) +
                       std::abs(world[2] - camera_.position[2]);
    return DepthBounds{distance_ ? std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]) : t[2],
                       relative_margin_ * (rel + centre_size_)};
  }

 private:
  const PartSource* scene_;
  Camera camera_;
  bool distance_;
  double centre_size_;
  double relative_margin_;
};

}  // namespace

DepthOrder::DepthOrder(const PartSource& scene, const Camera& camera, double near_plane,
                       const AccuracyModes& modes, double relative_margin, unsigned threads) {
  const int depth_key_bits = modes.depth_key_bits;
  if (depth_key_bits != 24 && depth_key_bits != 32)
    throw std::invalid_argument("a scene in parts sorts by 24- or 32-bit depth keys, not " +
                                std::to_string(depth_key_bits));
  const size_t n = scene.size();
  const GaussianDepths depths(scene, camera, modes.sort_depth, relative_margin);
  // Tens of millions of Gaussians take seconds of host time here, before the first part: the work is
  // spread over the host's cores in contiguous ranges (host_resources.h), each kept in order, so the
  // order and the bounds are one thread's, bit for bit.
  if (threads == 0) threads = detail::host_threads_for(n);
  {
    // Each range writes its kept Gaussians' keys from its own start; the gaps the culled left are then
    // closed range by range (each block moves down, never over one not yet moved).
    std::vector<uint32_t> keys(n), values(n);
    std::vector<size_t> kept(threads);
    detail::for_each_range(n, threads, [&](unsigned r, size_t begin, size_t end) {
      const GaussianDepths depths_here = depths;  // on this thread's stack
      const double near = near_plane;
      uint32_t* const range_keys = keys.data();
      uint32_t* const range_values = values.data();
      size_t out = begin;
      for (size_t i = begin; i < end; ++i) {
        const DepthBounds b = depths_here(i);
        // The GPU culls at or below the near plane (and non-finite depths): only a Gaussian it surely
        // culls is left out.
        if (!std::isfinite(b.depth) || b.depth + b.margin <= near) continue;
        range_keys[out] = depth_key(b.depth, 32);
        range_values[out] = uint32_t(i);
        ++out;
      }
      kept[r] = out - begin;
    });
    size_t m = 0;
    for (unsigned r = 0; r < threads; ++r) {
      const size_t begin = detail::range_begin(n, threads, r);
      std::copy_n(keys.begin() + std::ptrdiff_t(begin), kept[r], keys.begin() + std::ptrdiff_t(m));
      std::copy_n(values.begin() + std::ptrdiff_t(begin), kept[r], values.begin() + std::ptrdiff_t(m));
      m += kept[r];
    }
    keys.resize(m);
    values.resize(m);
    std::vector<uint32_t> key_scratch(m), value_scratch(m);
    // Stable: equal keys stay in scene order.
    if (detail::parallel_radix_sort(std::span(keys), std::span(values), std::span(key_scratch),
                                    std::span(value_scratch), 32, threads))
      values.swap(value_scratch);
    order_ = std::move(values);
  }

  // The running maximum of the upper keys from the front and the running minimum of the lower keys from
  // the back: per range first, then each range joined with the ranges before (after) it.
  const size_t m = order_.size();
  upper_max_.resize(m);
  lower_min_.resize(m);
  std::vector<uint32_t> range_max(threads, 0), range_min(threads, ~0u);
  detail::for_each_range(m, threads, [&](unsigned r, size_t begin, size_t end) {
    const GaussianDepths depths_here = depths;  // on this thread's stack
    const int key_bits = depth_key_bits;
    const uint32_t* const order = order_.data();
    uint32_t* const upper = upper_max_.data();
    uint32_t* const lower = lower_min_.data();
    uint32_t running = 0;
    for (size_t k = begin; k < end; ++k) {
      const DepthBounds b = depths_here(order[k]);
      running = std::max(running, depth_key(b.depth + b.margin, key_bits));
      upper[k] = running;
      lower[k] = depth_key(b.depth - b.margin, key_bits);
    }
    range_max[r] = running;
    running = ~0u;
    for (size_t k = end; k-- > begin;) {
      running = std::min(running, lower[k]);
      lower[k] = running;
    }
    range_min[r] = running;
  });
  detail::for_each_range(m, threads, [&](unsigned r, size_t begin, size_t end) {
    // The ranges before this one and after it (not this one's own totals, which hold its later keys).
    const uint32_t before = std::accumulate(range_max.begin(), range_max.begin() + r, 0u,
                                            [](uint32_t a, uint32_t b) { return std::max(a, b); });
    const uint32_t after = std::accumulate(range_min.begin() + r + 1, range_min.end(), ~0u,
                                           [](uint32_t a, uint32_t b) { return std::min(a, b); });
    uint32_t* const upper = upper_max_.data();
    uint32_t* const lower = lower_min_.data();
    for (size_t k = begin; k < end; ++k) {
      upper[k] = std::max(upper[k], before);
      lower[k] = std::min(lower[k], after);
    }
  });
}

bool DepthOrder::boundary(size_t i) const {
  if (i >= order_.size()) return true;
  return i > 0 && upper_max_[i - 1] < lower_min_[i];
}

size_t DepthOrder::part_end(size_t begin, size_t most) const {
  const size_t n = order_.size();
  const size_t wanted = std::min(n, begin + std::max<size_t>(most, 1));
  for (size_t end = wanted; end > begin; --end)
    if (boundary(end)) return end;
  for (size_t end = wanted + 1; end < n; ++end)
    if (boundary(end)) return end;
  return n;
}

std::vector<uint32_t> DepthOrder::part_indices(size_t begin, size_t end) const {
  std::vector<uint32_t> indices(order_.begin() + std::ptrdiff_t(begin), order_.begin() + std::ptrdiff_t(end));
  // A radix sort of the indices themselves (4 passes at most): a tenth of std::sort's time on 250k.
  std::vector<uint32_t> unused(indices.size()), scratch(indices.size()), unused_scratch(indices.size());
  if (cpu_radix_sort(std::span(indices), std::span(unused), std::span(scratch), std::span(unused_scratch),
                     32))
    indices.swap(scratch);
  return indices;
}

GaussianScene gather_gaussians(const GaussianScene& scene, std::span<const uint32_t> indices) {
  GaussianScene part;
  part.sh_degree = scene.sh_degree;
  const size_t n = indices.size();
  auto gather = [&](const std::vector<float>& from, std::vector<float>& to, size_t per) {
    to.resize(n * per);
    for (size_t k = 0; k < n; ++k)
      std::copy_n(from.begin() + std::ptrdiff_t(indices[k] * per), per, to.begin() + std::ptrdiff_t(k * per));
  };
  gather(scene.positions, part.positions, 3);
  gather(scene.log_scales, part.log_scales, 3);
  gather(scene.rotations, part.rotations, 4);
  gather(scene.opacity_logits, part.opacity_logits, 1);
  gather(scene.sh, part.sh, size_t(scene.sh_coefficients()) * 3);
  if (scene.has_normals()) gather(scene.normals, part.normals, 3);
  return part;
}

PartCosts part_costs(const PartSource& scene, const Camera& camera, const RenderSettings& settings,
                     uint32_t seam_copies, bool wide_keys) {
  // The outputs: the image's, or the tiles' of a region (RenderSettings::region).
  const PixelRegion outputs = tile_aligned(settings.region, camera.width, camera.height);
  const uint64_t pixels = uint64_t(outputs.width) * uint64_t(outputs.height);
  const uint64_t tiles = ((uint64_t(outputs.width) + kTileSize - 1) / kTileSize) *
                         ((uint64_t(outputs.height) + kTileSize - 1) / kTileSize);
  PartCosts costs;
  // Colour, depth and counts out; the composite state's two halves of 32 bytes; the tile ranges.
  costs.fixed = pixels * (16 + (settings.depth ? 4 : 0) + (settings.splat_count ? 4 : 0) + 64) + tiles * 8;
  if (settings.host) costs.fixed += pixels * 4 * (settings.host->write_depth ? 2 : 1);
  const uint64_t k = uint64_t((scene.sh_degree() + 1) * (scene.sh_degree() + 1));
  const AccuracyModes& modes = settings.accuracy;
  costs.per_gaussian = 4 * (3 + 3 + 4 + 1 + 3 * k);  // the attributes
  if (settings.lighting.enabled() && scene.has_normals()) costs.per_gaussian += 12;
  if (modes.fp16_sh) costs.per_gaussian += 6 * k;
  if (modes.fp16_covariance) costs.per_gaussian += 12;
  // Per projected record: the splat, its tile rect, four counts and offsets, the depth sort's pairs.
  costs.per_gaussian += uint64_t(seam_copies) * (kSplatRecordBytes + 8 + 4 * 4 + 16);
  costs.per_pair = wide_keys ? 2 * (8 + 4) : 2 * (4 + 4);  // keys and values, and their ping-pong copies
  // The largest single buffers: the spherical harmonics (or their normals, rotations), the projected
  // splats (kSplatRecordBytes a record); a key buffer.
  costs.largest_per_gaussian = std::max<uint64_t>({4 * 3 * k, 16, uint64_t(seam_copies) * kSplatRecordBytes});
  costs.largest_per_pair = wide_keys ? 8 : 4;
  // The projection's dispatch and those after it: a record an invocation.
  costs.invocations_per_gaussian = seam_copies;
  return costs;
}

size_t part_capacity(uint64_t budget, const PartCosts& costs, uint64_t overhead, double pairs_per_gaussian,
                     const DeviceCapacity& device) {
  const uint64_t largest_allocation = device.largest_allocation;
  const double per_gaussian = double(costs.per_gaussian) + pairs_per_gaussian * double(costs.per_pair);
  const uint64_t before = costs.fixed + overhead;
  // Each buffer within the device's largest allocation: the largest per-Gaussian buffer, and the key
  // buffers reserved for the part's pairs (FrameResources::reserve_pairs).
  double most_by_device = double(SIZE_MAX);
  if (costs.largest_per_gaussian > 0)
    most_by_device = std::floor(double(largest_allocation) / double(costs.largest_per_gaussian));
  if (costs.largest_per_pair > 0)
    most_by_device = std::min(
        most_by_device,
        std::floor((double(largest_allocation) / double(costs.largest_per_pair) - 1) / pairs_per_gaussian));
  if (most_by_device < 1)
    throw std::invalid_argument("the device's largest allocation (" + std::to_string(largest_allocation) +
                                " bytes) cannot hold the buffers of one Gaussian");
  // And each dispatch within the device's workgroup count.
  if (costs.invocations_per_gaussian > 0 && device.max_workgroups < UINT64_MAX)
    most_by_device =
        std::min(most_by_device, std::floor(double(device.max_workgroups) * double(kWorkgroupSize) /
                                             double(costs.invocations_per_gaussian)));
  if (budget <= before || double(budget - before) < per_gaussian) {
    auto mib = [](uint64_t bytes) {
      char text[32];
      std::snprintf(text, sizeof(text), "%.2f MiB", double(bytes) / double(1 << 20));
      return std::string(text);
    };
    throw std::invalid_argument(
        "memory budget of " + mib(budget) + " leaves no room for a Gaussian: this frame holds " +
        mib(before) +
        " before any (its images, the per-pixel state carried between parts and the sort's buffers) and " +
        std::to_string(uint64_t(per_gaussian)) +
        " bytes per Gaussian: raise the budget or render a smaller image");
  }
  return size_t(std::min(double(budget - before) / per_gaussian, most_by_device));
}

uint64_t device_frame_budget(const DeviceCapacity& device) {
  return uint64_t(kDeviceMemoryShare * double(device.total));
}

bool whole_frame_fits(const PartCosts& costs, size_t gaussians, double pairs_per_gaussian,
                      const DeviceCapacity& device) {
  const double n = double(gaussians);
  const double pairs = pairs_per_gaussian * n;
  // The whole frame's key buffers hold a power of two of pairs with a quarter's headroom (set_scene).
  const double key_capacity = double(std::bit_ceil(uint64_t(std::max(1.0, 1.25 * pairs))));
  const double bytes = double(costs.fixed) + n * double(costs.per_gaussian) + pairs * double(costs.per_pair);
  return n * double(costs.largest_per_gaussian) <= double(device.largest_allocation) &&
         n * double(costs.invocations_per_gaussian) <=
             double(device.max_workgroups) * double(kWorkgroupSize) &&
         key_capacity * double(costs.largest_per_pair) <= double(device.largest_allocation) &&
         bytes <= double(device_frame_budget(device));
}

}  // namespace tilesplat
