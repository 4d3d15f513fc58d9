// The float64 CPU reference renderer: docs/rendering-math.md, step by step, tiles and all.
// Everything is computed in double from the scene's float inputs; only the per-tile sort key is
// rounded to float32, because the GPU sorts by float_bits(depth) and the reference must order
// splats exactly as it does.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "camera/camera_models.h"
#include "frame/averaged_frames.h"
#include "frame/image_regions.h"
#include "host_depth.h"
#include "lighting.h"
#include "reference/parallel_chunks.h"
#include "reference/pixel_order.h"
#include "reference/reference_frame.h"
#include "reference/reference_projection.h"
#include "tilesplat/reference.h"
#include "tilesplat/scene_description.h"

namespace tilesplat {
namespace {

using reference::BlendRules;
using reference::PixelBlend;
using reference::Splat;

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
  reference::check_frame(scene, camera, settings, "render_reference");
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

  reference::ProjectedRecords projected = reference::project_records(scene, camera, settings);
  const std::vector<uint32_t> order = reference::depth_order(projected);
  const std::vector<Splat> splats = reference::splats_in_order(projected, order);
  // The per-pixel orders' depths along any ray (one record per Gaussian: they are pinhole only).
  std::vector<reference::RayDepthQuadric> quadrics(rule.by_ray_depth ? order.size() : 0);
  reference::parallel_chunks(quadrics.size(), 4096, [&](size_t begin, size_t end) {
    for (size_t s = begin; s < end; ++s) quadrics[s] = reference::ray_depth_quadric(scene, order[s], camera);
  });
  const reference::TileLists lists =
      reference::bin_into_tiles(projected.records, order, camera, rules.raster);
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
  reference::parallel_chunks(size_t(lists.grid_y), 1, [&](size_t row_begin, size_t row_end) {
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
