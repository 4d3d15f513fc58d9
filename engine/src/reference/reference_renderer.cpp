// The float64 CPU reference renderer: docs/rendering-math.md, step by step, tiles and all.
// Everything is computed in double from the scene's float inputs; only the per-tile sort key is
// rounded to float32, because the GPU sorts by float_bits(depth) and the reference must order
// splats exactly as it does.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "camera/camera_models.h"
#include "frame/averaged_frames.h"
#include "frame/image_regions.h"
#include "host_depth.h"
#include "lighting.h"
#include "reference/pixel_order.h"
#include "reference/reference_projection.h"
#include "settings_checks.h"
#include "tilesplat/reference.h"
#include "tilesplat/scene_description.h"

namespace tilesplat {
namespace {

// The blending rules the GPU's composite shares (docs/rendering-math.md); the cap on alpha is
// RenderSettings::max_alpha.
constexpr double kMinAlpha = 1.0 / 255.0;
constexpr double kMinTransmittance = 1e-4;

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

unsigned worker_count(size_t work_items) {
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  return static_cast<unsigned>(std::min<size_t>(hardware, std::max<size_t>(1, work_items)));
}

// Runs body(begin, end) over [0, count) in chunks handed out by an atomic counter, so threads that
// draw cheap chunks (empty tiles, culled Gaussians) take more of them.
template <typename Body>
void parallel_chunks(size_t count, size_t chunk, const Body& body) {
  if (count == 0) return;
  const size_t chunks = (count + chunk - 1) / chunk;
  std::atomic<size_t> next_chunk{0};
  auto worker = [&] {
    for (size_t c = next_chunk.fetch_add(1); c < chunks; c = next_chunk.fetch_add(1))
      body(c * chunk, std::min(count, (c + 1) * chunk));
  };
  const unsigned threads = worker_count(chunks);
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& thread : pool) thread.join();
}

void check_scene(const GaussianScene& scene) {
  const size_t n = scene.size();
  if (scene.sh_degree < 0 || scene.sh_degree > 3)
    throw std::invalid_argument("render_reference: sh_degree must be 0..3, got " +
                                std::to_string(scene.sh_degree));
  const size_t k = static_cast<size_t>(scene.sh_coefficients());
  if (scene.positions.size() != 3 * n || scene.log_scales.size() != 3 * n ||
      scene.rotations.size() != 4 * n || scene.sh.size() != n * k * 3)
    throw std::invalid_argument("render_reference: scene arrays have inconsistent sizes");
}

// What the blending loop needs of a visible Gaussian, packed densely in front-to-back order.
struct Splat {
  double mean[2];
  double conic[3];
  double opacity;
  double color[3];
  double depth;
};

// The order each pixel blends in (ReferenceOrder and AccuracyModes::resort_window): the tile's list
// (window 0), or through a window of splats ordered by depth along the pixel's ray, as
// composite_resort.comp keeps it (the exact order where the window is unbounded).
struct PixelRule {
  bool by_ray_depth = false;
  size_t window = 0;  // 0: unbounded
};

PixelRule pixel_rule(const RenderSettings& settings, ReferenceOrder order) {
  if (order == ReferenceOrder::kRayDepth) return {true, 0};
  if (settings.accuracy.resort_window > 0) return {true, size_t(settings.accuracy.resort_window)};
  return {};
}

// What render_reference refuses before any work: a camera, region, scene, host depth or setting it
// cannot draw, and a per-pixel order on what has no rays (it follows the pinhole's) or no tile lists.
void check_reference_frame(const GaussianScene& scene, const Camera& camera, const RenderSettings& settings,
                           const PixelRule& rule) {
  validate(camera);
  check_region(settings, camera);
  check_scene(scene);
  validate_host_depth(settings, camera);
  check_near_plane(settings.near_plane);
  check_max_alpha(settings);
  check_single_frame(settings);
  check_camera_model(settings, camera);
  if (!rule.by_ray_depth) return;
  // The rays of the per-pixel orders are the pinhole's; the raster rule and a host's depth have none.
  if (camera_models::drawn_model(camera) != CameraModel::kPinhole)
    throw std::invalid_argument("render_reference: the per-pixel depth order needs a pinhole camera, not " +
                                std::string(camera_model_name(camera.model)));
  if (settings.compositor == Compositor::kRaster)
    throw std::invalid_argument("render_reference: the raster compositor blends in the tile lists' order");
  if (settings.host)
    throw std::invalid_argument("render_reference: the per-pixel depth order does not test a host's depth");
}

// Every Gaussian projected: one record each, two for the equirectangular camera (its seam copies, records
// n..2n - 1), with what each record sorts by, as the projection keys it (projection.comp's sort_depth):
// the view depth (a fisheye's or panorama's distance), or in radial sorting the pinhole's and OpenCV
// camera's distance.
struct ProjectedRecords {
  std::vector<ProjectedGaussian> records;
  std::vector<float> sort_depth;
};

ProjectedRecords project_records(const GaussianScene& scene, const Camera& camera,
                                 const RenderSettings& settings) {
  const size_t n = scene.size();
  const PreparedLighting lighting = prepare_lighting(settings.lighting);  // validates
  if (settings.lighting.enabled()) reference::check_normals(scene);
  const camera_models::ModelLimits limits =
      camera_models::model_limits(camera);  // a copy: model_limits' lasts until this thread asks again
  const size_t records = n * camera_models::seam_copies(camera.model);
  ProjectedRecords projected{std::vector<ProjectedGaussian>(records), std::vector<float>(records)};
  const bool radial =
      camera_models::radial_replaces_depth(camera_models::drawn_model(camera), settings.accuracy.sort_depth);
  parallel_chunks(records, 4096, [&](size_t begin, size_t end) {
    for (size_t r = begin; r < end; ++r) {
      const size_t i = r % std::max<size_t>(n, 1);
      projected.records[r] = reference::project(scene, i, camera, limits, settings.antialiasing, lighting,
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

// The visible records front to back by the float32 depth the GPU sorts on, ties by record index.
std::vector<uint32_t> depth_order(const ProjectedRecords& projected) {
  std::vector<uint32_t> order;
  for (size_t i = 0; i < projected.records.size(); ++i)
    if (projected.records[i].visible) order.push_back(static_cast<uint32_t>(i));
  std::stable_sort(order.begin(), order.end(), [&](uint32_t lhs, uint32_t rhs) {
    return projected.sort_depth[lhs] < projected.sort_depth[rhs];
  });
  return order;
}

// The splats (indices into `order`) of each tile, front to back: a counting sort, whose filling in
// front-to-back order keeps every list sorted. The raster rule lists a splat wherever its alpha can pass
// the cut-off (bin_by_alpha_ellipse), the others where the projection's tile rectangle says.
struct TileLists {
  int grid_x = 0, grid_y = 0;
  std::vector<size_t> offsets;  // tile t's splats are splats[offsets[t], offsets[t + 1])
  std::vector<uint32_t> splats;
};

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

// What every pixel's blend follows: the frame's rules and the host's surfaces.
struct BlendRules {
  double max_alpha = 0;
  bool raster = false;  // the raster rule: no early-out
  // A host's surfaces, as view depths: a splat blends only in front of them (RenderSettings::host).
  std::vector<float> host_z;
  bool surface_out = false;  // RenderImage::host_depth: the depth at which 1 - T reaches surface_alpha
  double surface_alpha = 0;
};

// One pixel's front-to-back blend (docs/rendering-math.md): its sums as its splats come.
struct PixelBlend {
  double pixel_x = 0, pixel_y = 0;
  float surface_z = 0;  // the host's surface at this pixel (with host depth)
  double transmittance = 1.0;
  double color[3] = {0, 0, 0};
  double depth_sum = 0, weight_sum = 0;
  double surface = 0;  // the depth at which 1 - T reached the host's threshold; 0: never
  uint32_t blended = 0;

  // The splat's alpha at this pixel, or -1 where it is skipped.
  double alpha_at(const Splat& splat, const BlendRules& rules) const {
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
  // Blends the splat; false once the pixel is done (this splat not blended).
  bool blend(const Splat& splat, double alpha, const BlendRules& rules) {
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
};

// One pixel blended through its tile's list [begin, end): in the list's order, or through the rule's
// window of splats ordered by depth along the pixel's ray.
void blend_list(PixelBlend& pixel, const uint32_t* begin, const uint32_t* end,
                const std::vector<Splat>& splats, const std::vector<reference::RayDepthQuadric>& quadrics,
                const PixelRule& rule, const BlendRules& rules, const Camera& camera) {
  if (!rule.by_ray_depth) {
    for (const uint32_t* it = begin; it != end; ++it) {
      const double alpha = pixel.alpha_at(splats[*it], rules);
      if (alpha >= 0 && !pixel.blend(splats[*it], alpha, rules)) break;
    }
    return;
  }
  const std::array<double, 2> direction = reference::pixel_direction(camera, pixel.pixel_x, pixel.pixel_y);
  bool done = false;
  auto release = [&](const std::pair<uint32_t, double>& entry) {
    done = done || !pixel.blend(splats[entry.first], entry.second, rules);
  };
  reference::DepthQueue<std::pair<uint32_t, double>> queue(rule.window);
  for (const uint32_t* it = begin; it != end && !done; ++it) {
    const double alpha = pixel.alpha_at(splats[*it], rules);
    if (alpha >= 0) queue.offer(reference::ray_depth(quadrics[*it], direction), {*it, alpha}, release);
  }
  queue.flush(release);
}

}  // namespace

RenderImage render_reference(const GaussianScene& scene, const Camera& camera,
                             const RenderSettings& settings) {
  return render_reference(scene, camera, settings, ReferenceOrder::kSettings);
}

RenderImage render_reference(const SceneInstances& scene, const Camera& camera,
                             const RenderSettings& settings) {
  if (!blurs_moving_models(scene, settings))
    return render_reference(merge_instances(scene), camera, settings);
  // Each time sample of the scene where it is then, as Renderer::render(instances, ...) samples them.
  return render_averaged(
      camera, shutter_over_moving_models(settings, camera),
      TimedSampleRenderer(
          [&](const Camera& sample_camera, const RenderSettings& sample_settings, double time) {
            return render_reference(merge_instances(scene, time), sample_camera, sample_settings);
          }));
}

RenderImage render_reference(const GaussianScene& scene, const Camera& camera, const RenderSettings& settings,
                             ReferenceOrder reference_order) {
  refuse_accumulated_samples(settings, "render_reference");
  if (averages_samples(settings)) {
    // Depth of field, motion blur: the reference's own sample frames, averaged as the GPU's are.
    return render_averaged(camera, settings,
                           [&](const Camera& sample_camera, const RenderSettings& sample_settings) {
                             return render_reference(scene, sample_camera, sample_settings, reference_order);
                           });
  }
  const PixelRule rule = pixel_rule(settings, reference_order);
  check_reference_frame(scene, camera, settings, rule);
  BlendRules rules;
  rules.max_alpha = settings.max_alpha;
  rules.raster = settings.compositor == Compositor::kRaster;
  rules.host_z = settings.host ? host_view_depths(*settings.host) : std::vector<float>{};
  rules.surface_out = settings.host && settings.host->write_depth;
  rules.surface_alpha = rules.surface_out ? settings.host->alpha_threshold : 0.0;

  ProjectedRecords projected = project_records(scene, camera, settings);
  const std::vector<uint32_t> order = depth_order(projected);
  std::vector<Splat> splats(order.size());
  for (size_t s = 0; s < order.size(); ++s) {
    const ProjectedGaussian& g = projected.records[order[s]];
    splats[s] = {{g.mean[0], g.mean[1]},
                 {g.conic[0], g.conic[1], g.conic[2]},
                 g.opacity,
                 {g.color[0], g.color[1], g.color[2]},
                 g.depth};
  }
  // The per-pixel orders' depths along any ray (one record per Gaussian: they are pinhole only).
  std::vector<reference::RayDepthQuadric> quadrics(rule.by_ray_depth ? order.size() : 0);
  parallel_chunks(quadrics.size(), 4096, [&](size_t begin, size_t end) {
    for (size_t s = begin; s < end; ++s) quadrics[s] = reference::ray_depth_quadric(scene, order[s], camera);
  });
  const TileLists lists = bin_into_tiles(projected.records, order, camera, rules.raster);
  projected = {};

  // The pixels composited: the whole image's, or a region's (the tiles' lists are the whole image's).
  const PixelRegion region = resolved_region(settings.region, camera.width, camera.height);
  RenderImage image;
  image.width = region.width;
  image.height = region.height;
  image.rgba.assign(image.pixels() * 4, 0.0f);
  if (settings.depth) image.depth.assign(image.pixels(), 0.0f);
  if (settings.splat_count) image.splat_count.assign(image.pixels(), 0);
  if (rules.surface_out) image.host_depth.assign(image.pixels(), 0.0f);

  const double background[3] = {settings.background[0], settings.background[1], settings.background[2]};
  const size_t width = size_t(camera.width);
  const size_t x0 = size_t(region.x), y0 = size_t(region.y);
  const size_t x1 = x0 + size_t(region.width), y1 = y0 + size_t(region.height);
  parallel_chunks(size_t(lists.grid_y), 1, [&](size_t row_begin, size_t row_end) {
    for (size_t ty = std::max(row_begin, y0 / kTileSize); ty < row_end && ty * kTileSize < y1; ++ty)
      for (size_t tx = x0 / kTileSize; tx * kTileSize < x1; ++tx) {
        const size_t tile = ty * size_t(lists.grid_x) + tx;
        const uint32_t* list_begin = lists.splats.data() + lists.offsets[tile];
        const uint32_t* list_end = lists.splats.data() + lists.offsets[tile + 1];
        const size_t y_end = std::min(y1, (ty + 1) * kTileSize);
        const size_t x_end = std::min(x1, (tx + 1) * kTileSize);
        for (size_t py = std::max(y0, ty * kTileSize); py < y_end; ++py)
          for (size_t px = std::max(x0, tx * kTileSize); px < x_end; ++px) {
            PixelBlend pixel;
            pixel.pixel_x = double(px) + 0.5;
            pixel.pixel_y = double(py) + 0.5;
            pixel.surface_z = rules.host_z.empty() ? 0.0f : rules.host_z[py * width + px];
            blend_list(pixel, list_begin, list_end, splats, quadrics, rule, rules, camera);
            const size_t out = (py - y0) * size_t(region.width) + (px - x0);
            for (size_t ch = 0; ch < 3; ++ch)
              image.rgba[out * 4 + ch] =
                  static_cast<float>(pixel.color[ch] + pixel.transmittance * background[ch]);
            image.rgba[out * 4 + 3] = static_cast<float>(1.0 - pixel.transmittance);
            if (settings.depth)
              image.depth[out] =
                  pixel.weight_sum > 0 ? static_cast<float>(pixel.depth_sum / pixel.weight_sum) : 0.0f;
            if (settings.splat_count) image.splat_count[out] = pixel.blended;
            if (rules.surface_out) image.host_depth[out] = host_depth_out(*settings.host, pixel.surface, out);
          }
      }
  });
  return image;
}

}  // namespace tilesplat
