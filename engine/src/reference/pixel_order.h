// The float64 reference's per-pixel blending orders (ReferenceOrder, AccuracyModes::resort_window):
// each pixel's splats ordered by the depth of their density maximum along its ray, fully
// (ReferenceOrder::kRayDepth) or through the GPU composite's bounded window with its own rule, so that
// the GPU is held to the reference (docs/rendering-math.md, "Per-pixel order").
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/scene.h"

namespace tilesplat::reference {

// What a splat's depth along any ray through the camera needs: t(d) = (d . Q mu) / (d . Q d) for the
// ray d = ((x - cx) / fx, (y - cy) / fy, 1), with mu the camera-space mean and Q the adjugate of the
// camera-space covariance (any multiple of Sigma^-1 gives the same t).
struct RayDepthQuadric {
  std::array<double, 3> q_mu{};  // Q mu
  std::array<double, 6> q{};     // Q_xx, Q_xy, Q_xz, Q_yy, Q_yz, Q_zz
  double mean_depth = 0;         // where the quadratic form vanishes
};
RayDepthQuadric ray_depth_quadric(const GaussianScene& scene, size_t i, const Camera& camera);
// The ray d = (dx, dy, 1) through image point (x, y) (pixel centres at + 0.5): (dx, dy).
std::array<double, 2> pixel_direction(const Camera& camera, double x, double y);
// The depth of the density maximum along the ray with direction `d` (pixel_direction); the mean depth
// where d . Q d is not positive or t is not finite (as the GPU falls back).
double ray_depth(const RayDepthQuadric& quadric, const std::array<double, 2>& d);

// A queue of at most `capacity` items ordered by depth, as the GPU's re-sorting composite keeps its
// window (composite_resort.comp): offering an item to a full queue releases the
// nearer of the new item and the queue's nearest, the new one on a tie; equal depths keep their
// arrival order in the queue. Capacity 0: unbounded, nothing released until the end (a full sort).
template <typename Item>
class DepthQueue {
 public:
  explicit DepthQueue(size_t capacity) : capacity_(capacity) {}
  // Offers an item; `release` receives the released one, if any.
  template <typename Release>
  void offer(double t, const Item& item, Release&& release) {
    if (capacity_ == 0) {  // sorted once, at the end
      pending_.push_back({t, item});
      return;
    }
    if (pending_.size() == capacity_) {
      if (t <= pending_.front().t) {
        release(item);
        return;
      }
      release(pending_.front().item);
      pending_.erase(pending_.begin());
    }
    size_t at = pending_.size();
    while (at > 0 && pending_[at - 1].t > t) --at;  // after every pending item at most as deep
    pending_.insert(pending_.begin() + std::ptrdiff_t(at), {t, item});
  }
  // Releases what is pending, nearest first.
  template <typename Release>
  void flush(Release&& release) {
    if (capacity_ == 0)
      std::stable_sort(pending_.begin(), pending_.end(),
                       [](const Entry& a, const Entry& b) { return a.t < b.t; });
    for (const Entry& entry : pending_) release(entry.item);
    pending_.clear();
  }

 private:
  struct Entry {
    double t;
    Item item;
  };
  size_t capacity_;
  std::vector<Entry> pending_;
};

}  // namespace tilesplat::reference
