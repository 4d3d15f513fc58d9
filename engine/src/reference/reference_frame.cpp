// The float64 reference's frame steps (reference_frame.h): projection of every record, the depth order,
// the tiles' lists and the per-pixel blend.
#include "reference/reference_frame.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "camera/camera_models.h"
#include "host_depth.h"
#include "lighting.h"
#include "reference/parallel_chunks.h"
#include "reference/reference_projection.h"
#include "settings_checks.h"

namespace tilesplat::reference {
namespace {

// The raster rule's reach (Compositor::kRaster): the tiles that the bounding box of the splat's
// alpha >= kMinAlpha ellipse meets, with a pixel's margin, in place of the projection's tile
// rectangle. Alpha = opacity exp(-m^2 / 2) >= kMinAlpha inside the Mahalanobis radius m^2 = 2 ln(opacity /
// kMinAlpha), whose box has half-widths m sqrt(cov a) and m sqrt(cov c). Pixels the box holds beyond
// the ellipse are skipped by the alpha test, so the box's size changes no pixel, only the work.
void bin_by_alpha_ellipse(ProjectedGaussian& g, int grid_x, int grid_y) {
  const double m2 = 2.0 * std::log(g.opacity / kMinAlpha);
  if (!(m2 > 0)) {
    g.tile_min[0] = g.tile_max[0] = g.tile_min[1] = g.tile_max[1] = 0;  // never reaches the cut-off
    return;
  }
  const double half[2] = {std::sqrt(m2 * g.cov2d[0]) + 1.0, std::sqrt(m2 * g.cov2d[2]) + 1.0};
  const int grid[2] = {grid_x, grid_y};
  for (int axis = 0; axis < 2; ++axis) {
    const double low = std::floor((g.mean[axis] - half[axis]) / kTileSize);
    const double high = std::floor((g.mean[axis] + half[axis]) / kTileSize) + 1;
    g.tile_min[axis] = int(std::clamp(low, 0.0, double(grid[axis])));
    g.tile_max[axis] = int(std::clamp(high, 0.0, double(grid[axis])));
  }
}

}  // namespace

void check_scene(const GaussianScene& scene, const char* caller) {
  const size_t n = scene.size();
  if (scene.sh_degree < 0 || scene.sh_degree > 3)
    throw std::invalid_argument(std::string(caller) + ": sh_degree must be 0..3, got " +
                                std::to_string(scene.sh_degree));
  const size_t k = static_cast<size_t>(scene.sh_coefficients());
  if (scene.positions.size() != 3 * n || scene.log_scales.size() != 3 * n ||
      scene.rotations.size() != 4 * n || scene.sh.size() != n * k * 3)
    throw std::invalid_argument(std::string(caller) + ": scene arrays have inconsistent sizes");
}

void check_frame(const GaussianScene& scene, const Camera& camera, const RenderSettings& settings,
                 const char* caller) {
  validate(camera);
  check_region(settings, camera);
  check_scene(scene, caller);
  validate_host_depth(settings, camera);
  check_near_plane(settings.near_plane);
  check_max_alpha(settings);
  check_single_frame(settings);
  check_camera_model(settings, camera);
}

ProjectedRecords project_records(const GaussianScene& scene, const Camera& camera,
                                 const RenderSettings& settings) {
  const size_t n = scene.size();
  const PreparedLighting lighting = prepare_lighting(settings.lighting);  // validates
  if (settings.lighting.enabled()) check_normals(scene);
  const camera_models::ModelLimits limits =
      camera_models::model_limits(camera);  // a copy: model_limits' lasts until this thread asks again
  const size_t records = n * camera_models::seam_copies(camera.model);
  ProjectedRecords projected{std::vector<ProjectedGaussian>(records), std::vector<float>(records)};
  const bool radial =
      camera_models::radial_replaces_depth(camera_models::drawn_model(camera), settings.accuracy.sort_depth);
  parallel_chunks(records, 4096, [&](size_t begin, size_t end) {
    for (size_t r = begin; r < end; ++r) {
      const size_t i = r % std::max<size_t>(n, 1);
      projected.records[r] = project(scene, i, camera, limits, settings.antialiasing, lighting,
                                     settings.near_plane, uint32_t(r / std::max<size_t>(n, 1)));
      double depth = projected.records[r].depth;
      if (radial) {
        const std::array<double, 3> t =
            camera.to_camera({double(scene.positions[3 * i]), double(scene.positions[3 * i + 1]),
                              double(scene.positions[3 * i + 2])});
        depth = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
      }
      projected.sort_depth[r] = float(depth);
    }
  });
  return projected;
}

std::vector<uint32_t> depth_order(const ProjectedRecords& projected) {
  std::vector<uint32_t> order;
  for (size_t i = 0; i < projected.records.size(); ++i)
    if (projected.records[i].visible) order.push_back(static_cast<uint32_t>(i));
  std::stable_sort(order.begin(), order.end(), [&](uint32_t lhs, uint32_t rhs) {
    return projected.sort_depth[lhs] < projected.sort_depth[rhs];
  });
  return order;
}

std::vector<Splat> splats_in_order(const ProjectedRecords& projected, const std::vector<uint32_t>& order) {
  std::vector<Splat> splats(order.size());
  for (size_t s = 0; s < order.size(); ++s) {
    const ProjectedGaussian& g = projected.records[order[s]];
    splats[s] = {{g.mean[0], g.mean[1]},
                 {g.conic[0], g.conic[1], g.conic[2]},
                 g.opacity,
                 {g.color[0], g.color[1], g.color[2]},
                 g.depth};
  }
  return splats;
}

TileLists bin_into_tiles(std::vector<ProjectedGaussian>& projected, const std::vector<uint32_t>& order,
                         const Camera& camera, bool raster) {
  TileLists lists;
  lists.grid_x = (camera.width + kTileSize - 1) / kTileSize;
  lists.grid_y = (camera.height + kTileSize - 1) / kTileSize;
  if (raster)
    for (uint32_t index : order) bin_by_alpha_ellipse(projected[index], lists.grid_x, lists.grid_y);
  const size_t tiles = size_t(lists.grid_x) * size_t(lists.grid_y);
  lists.offsets.assign(tiles + 1, 0);
  for (uint32_t index : order) {
    const ProjectedGaussian& g = projected[index];
    for (int ty = g.tile_min[1]; ty < g.tile_max[1]; ++ty)
      for (int tx = g.tile_min[0]; tx < g.tile_max[0]; ++tx)
        ++lists.offsets[size_t(ty) * size_t(lists.grid_x) + size_t(tx) + 1];
  }
  std::partial_sum(lists.offsets.begin(), lists.offsets.end(), lists.offsets.begin());
  lists.splats.resize(lists.offsets.back());
  std::vector<size_t> cursor(lists.offsets.begin(), lists.offsets.end() - 1);
  for (size_t s = 0; s < order.size(); ++s) {
    const ProjectedGaussian& g = projected[order[s]];
    for (int ty = g.tile_min[1]; ty < g.tile_max[1]; ++ty)
      for (int tx = g.tile_min[0]; tx < g.tile_max[0]; ++tx)
        lists.splats[cursor[size_t(ty) * size_t(lists.grid_x) + size_t(tx)]++] = static_cast<uint32_t>(s);
  }
  return lists;
}

double PixelBlend::alpha_at(const Splat& splat, const BlendRules& rules) const {
  const double dx = splat.mean[0] - pixel_x;
  const double dy = splat.mean[1] - pixel_y;
  const double power =
      -0.5 * (splat.conic[0] * dx * dx + splat.conic[2] * dy * dy) - splat.conic[1] * dx * dy;
  if (power > 0) return -1.0;
  const double alpha = std::min(rules.max_alpha, splat.opacity * std::exp(power));
  if (alpha < kMinAlpha) return -1.0;
  // Behind (or at) the host's opaque surface; compared as the float depths the GPU sorts on.
  if (!rules.host_z.empty() && !(static_cast<float>(splat.depth) < surface_z)) return -1.0;
  return alpha;
}

bool PixelBlend::blend(const Splat& splat, double alpha, const BlendRules& rules) {
  const double next_transmittance = transmittance * (1 - alpha);
  // The raster rule has no early-out: the hardware blend cannot skip a fragment.
  if (!rules.raster && next_transmittance < kMinTransmittance) return false;
  const double weight = alpha * transmittance;
  for (int ch = 0; ch < 3; ++ch) color[ch] += splat.color[ch] * weight;
  depth_sum += weight * splat.depth;
  weight_sum += weight;
  transmittance = next_transmittance;
  if (rules.surface_out && surface == 0 && 1 - transmittance >= rules.surface_alpha) surface = splat.depth;
  ++blended;
  return true;
}

}  // namespace tilesplat::reference
