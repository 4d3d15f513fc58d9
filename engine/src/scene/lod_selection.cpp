// Choosing a level per chunk of a LOD set for one camera under a splat budget (select_lod_levels).
//
// The rule is the streaming viewers' (PlayCanvas, Spark): spend the budget where the drawn Gaussians
// are spread thinnest on screen. A chunk's need is its box's projected area in pixels over the
// Gaussians it draws at its current level; the chunk in most need moves one level finer while the
// total stays within the budget. Greedy and deterministic: needs are compared exactly, ties go to the
// lower chunk index. The projected area is a sphere's around the box (its half diagonal), clipped to
// the image: cheap, monotone in distance and size, and the same for every orientation of the camera.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <queue>
#include <vector>

#include "tilesplat/lod_set.h"

namespace tilesplat {

namespace {

// Whether the box lies wholly on the outer side of one of the pinhole's five planes (the image's four
// edges through the centre, and z = 0). Each plane's test holds for points behind the camera too.
bool outside_view(const Camera& camera, const LodChunk& chunk) {
  std::array<std::array<double, 3>, 8> corners;
  for (size_t i = 0; i < 8; ++i)
    corners[i] =
        camera.to_camera({(i & 1) ? chunk.max[0] : chunk.min[0], (i & 2) ? chunk.max[1] : chunk.min[1],
                          (i & 4) ? chunk.max[2] : chunk.min[2]});
  const auto all = [&corners](auto outside) { return std::all_of(corners.begin(), corners.end(), outside); };
  const double right = camera.width - camera.cx;
  const double bottom = camera.height - camera.cy;
  return all([](const auto& p) { return p[2] <= 0; }) ||
         all([&](const auto& p) { return camera.fx * p[0] + camera.cx * p[2] < 0; }) ||
         all([&](const auto& p) { return camera.fx * p[0] - right * p[2] > 0; }) ||
         all([&](const auto& p) { return camera.fy * p[1] + camera.cy * p[2] < 0; }) ||
         all([&](const auto& p) { return camera.fy * p[1] - bottom * p[2] > 0; });
}

// Pixels the chunk's bounding sphere covers, at most the whole image (a camera inside it: the image).
double projected_pixels(const Camera& camera, const LodChunk& chunk) {
  const double image = double(camera.width) * double(camera.height);
  double radius2 = 0, distance2 = 0;
  for (size_t a = 0; a < 3; ++a) {
    const double half = 0.5 * (chunk.max[a] - chunk.min[a]);
    const double centre = 0.5 * (chunk.max[a] + chunk.min[a]);
    radius2 += half * half;
    distance2 += (centre - camera.position[a]) * (centre - camera.position[a]);
  }
  if (distance2 <= radius2) return image;
  // The sphere's silhouette: a cone of half-angle asin(r / d); tan of it is r / sqrt(d^2 - r^2).
  const double tan_half = std::sqrt(radius2 / (distance2 - radius2));
  const double pixels = std::numbers::pi * camera.fx * camera.fy * tan_half * tan_half;
  return std::min(pixels, image);
}

struct Need {
  double pixels_per_splat;
  size_t chunk;
  bool operator<(const Need& other) const {  // std::priority_queue: the largest need on top, then lower index
    if (pixels_per_splat != other.pixels_per_splat) return pixels_per_splat < other.pixels_per_splat;
    return chunk > other.chunk;
  }
};

}  // namespace

LodSelection select_lod_levels(const LodSet& set, const Camera& camera, uint64_t splat_budget) {
  const std::vector<LodChunk>& chunks = set.chunks();
  const int coarsest = set.levels() - 1;
  LodSelection selection;
  selection.chunk_levels.assign(chunks.size(), -1);
  selection.splats = set.environment_size();
  const bool culls = camera.model == CameraModel::kPinhole;
  std::vector<double> pixels(chunks.size(), 0);
  for (size_t c = 0; c < chunks.size(); ++c) {
    if (culls && outside_view(camera, chunks[c])) continue;
    selection.chunk_levels[c] = coarsest;
    selection.splats += chunks[c].levels[size_t(coarsest)].count;
    pixels[c] = projected_pixels(camera, chunks[c]);
  }
  selection.coarsest_splats = selection.splats;

  const auto need = [&](size_t c) {
    const uint64_t drawn = chunks[c].levels[size_t(selection.chunk_levels[c])].count;
    return Need{pixels[c] / double(std::max<uint64_t>(drawn, 1)), c};
  };
  std::priority_queue<Need> queue;
  for (size_t c = 0; c < chunks.size(); ++c)
    if (selection.chunk_levels[c] > 0) queue.push(need(c));
  while (!queue.empty()) {
    const size_t c = queue.top().chunk;
    queue.pop();
    const int level = selection.chunk_levels[c];
    const uint64_t now = chunks[c].levels[size_t(level)].count;
    const uint64_t finer = chunks[c].levels[size_t(level - 1)].count;
    const uint64_t total = selection.splats - now + finer;
    if (finer > now && total > splat_budget) continue;  // this chunk stays; a smaller step elsewhere may fit
    selection.chunk_levels[c] = level - 1;
    selection.splats = total;
    if (level - 1 > 0) queue.push(need(c));
  }
  // Over only where the coarsest levels were (a finer level of fewer Gaussians than a coarser one, which
  // an index may hold, is taken whatever the budget: it only lowers the count).
  selection.over_budget = selection.splats > splat_budget;
  return selection;
}

}  // namespace tilesplat
