#include "frame/frame_plan.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "camera/camera_models.h"
#include "frame/image_regions.h"
#include "host_depth.h"
#include "passes/stochastic_composite_pass.h"
#include "passes/tile_coverage.h"
#include "settings_checks.h"
#include "sort/sort_strategy.h"
#include "shader_io.h"
#include "tilesplat/reference.h"

namespace tilesplat {

static_assert(kTileSize == int(shader_io::TILE_SIZE), "the public tile size is the shaders'");

namespace {

// A camera this device cannot render is a runtime_error (render() documents it so), bad settings an
// invalid_argument.
void check_camera(const Camera& camera, const RenderSettings& settings, const DeviceCaps& device) {
  try {
    validate(camera);  // size, intrinsics, pose; then what this device can hold
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
  auto fail = [](const std::string& why) { throw std::runtime_error("invalid camera: " + why); };
  // Tile rects pack each coordinate in 16 bits, and the composite dispatches one workgroup per tile.
  // On CPU drivers a shader invocation may loop over a row or column of tiles, and llvmpipe cuts
  // loops short after 65535 iterations (key_emission_big.comp): there 16384 tiles per axis.
  const uint64_t max_tiles =
      device.cpu_driver ? 16384 : std::min<uint64_t>(0xffff, device.max_workgroup_count_x);
  const uint64_t tiles_x = (uint64_t(camera.width) + kTileSize - 1) / kTileSize;
  const uint64_t tiles_y = (uint64_t(camera.height) + kTileSize - 1) / kTileSize;
  if (tiles_x > max_tiles || tiles_y > std::min<uint64_t>(max_tiles, 0xffff))
    fail("image size " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
         " exceeds the renderer's limit of " + std::to_string(max_tiles) + " tiles (of 16 pixels) per axis");
  check_region(settings, camera);
  // Renderer::render splits such an image into bands of rows by itself (Renderer::Impl::image_bands).
  const PixelRegion& region = settings.region;
  const PixelRegion tiles = tile_aligned(region, camera.width, camera.height);
  const uint64_t rgba_bytes = uint64_t(tiles.width) * uint64_t(tiles.height) * 16;
  if (rgba_bytes > device.max_allocation_size)
    fail("image size " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
         (region.whole() ? std::string() : " (region " + to_string(region) + ")") + " needs " +
         std::to_string(rgba_bytes >> 20) +
         " MiB for its colour buffer, more than the device's largest allocation (" +
         std::to_string(device.max_allocation_size >> 20) + " MiB)");
}

// Why `compositor` cannot draw in `modes`, or nothing: the one rule of compositor_draws and
// validate_compositor. The raster compositor blends in the Gaussians' depth order, each splat over whole
// pixels; the stochastic one sorts nothing.
std::optional<std::string> modes_refusal(Compositor compositor, const AccuracyModes& modes) {
  if (compositor != Compositor::kRaster && modes.fp16_blend)
    return to_string(compositor) +
           " compositor: fp16-blend is the raster compositor's 16-bit colour attachment; this compositor "
           "blends in float32 registers: use --compositor raster or leave fp16-blend out";
  if (compositor == Compositor::kSorted) return std::nullopt;
  const std::string resort = "per-pixel re-sorting (resort" + std::to_string(modes.resort_window) + ")";
  if (compositor == Compositor::kRaster) {
    if (modes.resort_window > 0)
      return "raster compositor: " + resort +
             " re-orders each tile's list, and this compositor draws no tile lists: use the sorted "
             "compositor";
    return std::nullopt;
  }
  if (modes.resort_window > 0)
    return "stochastic compositor: " + resort +
           " re-orders depth-sorted lists, and this compositor sorts nothing: use the sorted compositor";
  if (modes.sort_depth == AccuracyModes::SortDepth::kDistance)
    return "stochastic compositor: radial sorting orders the depth sort, which this compositor does not "
           "run (it keeps the nearest drawn splat by view depth): leave radial out";
  if (modes.depth_key_bits != 32)
    return "stochastic compositor: " + std::to_string(modes.depth_key_bits) +
           "-bit depth keys approximate the depth sort, which this compositor does not run (it compares full "
           "view depths): use 32-bit depth keys";
  return std::nullopt;
}

// Settings the compositors cannot honour.
constexpr uint32_t kMaxStochasticFrames = 4096;
void validate_compositor(const RenderSettings& settings) {
  if (const auto why = modes_refusal(settings.compositor, settings.accuracy))
    throw std::invalid_argument(*why);
  if (settings.compositor != Compositor::kStochastic) return;
  auto fail = [](const std::string& why) { throw std::invalid_argument("stochastic compositor: " + why); };
  if (settings.stochastic.frames < 1 || settings.stochastic.frames > kMaxStochasticFrames)
    fail("stochastic.frames must be 1 to " + std::to_string(kMaxStochasticFrames) + ", not " +
         std::to_string(settings.stochastic.frames));
  if (settings.stochastic.accumulate && settings.stochastic.sampler == StochasticSampler::kStratified)
    fail(
        "stochastic.accumulate adds frames to an open-ended mean, and the stratified sampler needs the count "
        "in advance: accumulate with the hash sampler");
}

}  // namespace

bool compositor_draws(Compositor compositor, const AccuracyModes& modes) {
  return !modes_refusal(compositor, modes).has_value();
}

// Each part's lists are exact only for an order every part agrees on.
void validate_scene_parts(const RenderSettings& settings, const std::string& sort_name) {
  auto fail = [](const std::string& why) {
    throw std::invalid_argument("a scene rendered in parts (memory budget): " + why);
  };
  if (settings.compositor != Compositor::kSorted)
    fail(std::string(settings.compositor == Compositor::kRaster ? "the raster" : "the stochastic") +
         " compositor has no per-pixel state to carry from part to part: use the sorted compositor");
  if (settings.accuracy.resort_window > 0)
    fail("per-pixel re-sorting (resort" + std::to_string(settings.accuracy.resort_window) +
         ") re-orders within a window that would stop at each part's end: render without it");
  if (settings.accuracy.depth_key_bits == 16)
    fail(
        "16-bit depth keys are quantized over each frame's visible depth range, which differs from part to "
        "part: use 24- or 32-bit keys");
  if (!sort_strategy_exact(sort_name))
    fail("the sort strategy '" + sort_name +
         "' quantizes depths per frame, which differs from part to part: " + "use an exact strategy");
}

namespace {

TileGrid tile_grid(const Camera& camera, const PixelRegion& region) {
  const PixelRegion tiles = tile_aligned(region, camera.width, camera.height);
  TileGrid grid;
  grid.width = uint32_t(tiles.width);
  grid.height = uint32_t(tiles.height);
  grid.first_x = uint32_t(tiles.x / kTileSize);
  grid.first_y = uint32_t(tiles.y / kTileSize);
  grid.tiles_x = (grid.width + kTileSize - 1) / kTileSize;
  grid.tiles_y = (grid.height + kTileSize - 1) / kTileSize;
  grid.count = grid.tiles_x * grid.tiles_y;
  grid.tile_bits = uint32_t(std::bit_width(grid.count));
  return grid;
}

// The raster frame: projection -> depth sort -> the splats drawn in that order (a host's depth image
// converted first, into the draw's depth attachment). It builds no tile lists; "reusing its lists"
// re-draws the sorted splats.
std::vector<FramePass> raster_frame_passes(const FramePlan& plan) {
  std::vector<FramePass> passes;
  if (plan.host.from_image) passes.push_back(FramePass::kHostDepthIn);  // the depth attachment's source
  if (plan.build_lists) {
    passes.push_back(FramePass::kClearCounters);
    passes.push_back(FramePass::kProjection);
    if (plan.depth_key_bits == 16) passes.push_back(FramePass::kDepthQuantize);
    passes.push_back(FramePass::kDepthSort);
  }
  passes.push_back(FramePass::kRasterComposite);
  return passes;
}

// The frame's passes in order. The lists are built as
//   sorted:     projection -> depth sort -> prefix sum (depth order) -> key emission -> tile sort
//               (stable, so each tile's run stays front to back) -> tile ranges
//   sorted, a strategy sorting (tile, depth) pairs itself: projection -> prefix sum (index order) ->
//               key emission -> tile sort of 64-bit keys -> tile ranges
//   stochastic: projection -> prefix sum (index order) -> key emission -> tile binning -> tile ranges
// The stochastic frame never sorts by depth: its composite needs each tile's splats, in any order.
// Its tile binning is the strategy's sort over the tile bits of 32-bit keys, used only to group the
// pairs by tile. A frame on reused lists runs the composite alone.
std::vector<FramePass> composited_frame_passes(const FramePlan& plan) {
  if (plan.compositor == Compositor::kRaster) return raster_frame_passes(plan);
  std::vector<FramePass> passes;
  if (plan.host.from_image) passes.push_back(FramePass::kHostDepthIn);  // every attempt converts it first
  const bool stochastic = plan.compositor == Compositor::kStochastic;
  if (plan.build_lists) {
    passes.push_back(FramePass::kClearCounters);
    passes.push_back(FramePass::kProjection);
    if (plan.depth_key_bits == 16) passes.push_back(FramePass::kDepthQuantize);
    if (!stochastic && plan.depth_first) passes.push_back(FramePass::kDepthSort);
    passes.push_back(FramePass::kPrefixSum);
    passes.push_back(FramePass::kKeyEmission);
    passes.push_back(stochastic ? FramePass::kTileBinning : FramePass::kTileSort);
    passes.push_back(FramePass::kTileRanges);
  } else {
    passes.push_back(FramePass::kResetLongestList);  // the composite's chunk 0 raises it from zero again
  }
  passes.push_back(stochastic               ? FramePass::kStochasticComposite
                   : plan.resort_window > 0 ? FramePass::kResortComposite
                                            : FramePass::kComposite);
  return passes;
}

// The composited frame, then for a sample of an accumulated lens or shutter frame the mean of the samples.
std::vector<FramePass> frame_passes(const FramePlan& plan) {
  std::vector<FramePass> passes = composited_frame_passes(plan);
  if (plan.sample_sums) passes.push_back(FramePass::kAccumulateSamples);
  return passes;
}

bool splits_submissions(const FramePlan& plan) {
  return (plan.build_lists && plan.sort.sorts_on_host) ||
         plan.stochastic_samples > StochasticCompositePass::kSamplesPerSubmission;
}

}  // namespace

const char* timed_name(FramePass pass) {
  switch (pass) {
    case FramePass::kHostDepthIn:
      return "host_depth_in";
    case FramePass::kClearCounters:
      return nullptr;
    case FramePass::kResetLongestList:
      return nullptr;
    case FramePass::kProjection:
      return "projection";
    case FramePass::kDepthQuantize:
      return "depth_quantize";
    case FramePass::kDepthSort:
      return "depth_sort";
    case FramePass::kPrefixSum:
      return "prefix_sum";
    case FramePass::kKeyEmission:
      return "key_emission";
    case FramePass::kTileSort:
      return "tile_sort";
    case FramePass::kTileBinning:
      return "tile_binning";
    case FramePass::kTileRanges:
      return "tile_ranges";
    case FramePass::kComposite:
      return "composite";
    case FramePass::kResortComposite:
      return "composite";
    case FramePass::kStochasticComposite:
      return "stochastic_composite";
    case FramePass::kRasterComposite:
      return "raster_composite";
    case FramePass::kAccumulateSamples:
      return "sample_accumulate";
  }
  return nullptr;
}

std::vector<std::string> FramePlan::timed_passes() const {
  std::vector<std::string> names;
  for (FramePass pass : passes)
    if (const char* name = timed_name(pass)) names.emplace_back(name);
  return names;
}

std::string choose_sort_strategy(const std::string& requested, const DeviceCaps& device,
                                 bool without_waiting) {
  if (requested != "auto") return requested;
  if (device.cpu_driver) return without_waiting ? "radix" : "cpu-radix";
  return device.vendor_id == kVendorNvidia ? "onesweep" : "radix";
}

ProjectionVariant projection_variant(const RenderSettings& settings, const SceneShape& scene,
                                     CameraModel camera_model) {
  const AccuracyModes& modes = settings.accuracy;
  ProjectionVariant v;
  v.camera_model = uint32_t(camera_model);
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
  v.distance_key = camera_models::radial_replaces_depth(camera_model, modes.sort_depth);
  v.ray_depth = modes.resort_window > 0;
  v.lighting = settings.lighting.enabled();
  v.file_normals = v.lighting && scene.file_normals;
  return v;
}

namespace {

// Whether the composite keeps per-pixel state between its dispatches (FrameResources::composite_state):
// the stochastic one for more than one sample or chunk, or frames that add up across calls; the sorted
// ones for more than one chunk, or a part of a scene whose pixels go on in the next part; the raster one
// never (the hardware blends).
bool needs_composite_state(const FramePlan& plan) {
  switch (plan.compositor) {
    case Compositor::kStochastic:
      return StochasticCompositePass::needs_state(plan.stochastic_samples, plan.composite_chunks) ||
             plan.stochastic_accumulate;
    case Compositor::kRaster:
      return false;
    case Compositor::kSorted:
      break;
  }
  return plan.composite_chunks > 1 || !plan.part.whole();
}

}  // namespace

FramePlan plan_frame(const Camera& camera, const RenderSettings& settings, const FrameContext& context) {
  check_camera(camera, settings, context.device);
  validate(settings.accuracy);
  validate_compositor(settings);
  validate_host_depth(settings, camera);
  check_near_plane(settings.near_plane);
  check_max_alpha(settings);
  check_single_frame(settings);
  check_camera_model(settings, camera);
  if (!context.part.whole()) validate_scene_parts(settings, context.sort.name);

  FramePlan plan;
  plan.sort = context.sort;
  plan.lists = {context.scene.generation, camera,
                context.sort.name,        settings.accuracy,
                settings.antialiasing,    settings.lighting,
                settings.compositor,      settings.near_plane,
                settings.region};
  plan.part = context.part;
  // A part's lists are never whole-scene lists: always built, and never reused (renderer_parts.cpp).
  plan.build_lists =
      !(settings.reuse_lists && context.part.whole() && context.lists && *context.lists == plan.lists);
  plan.projection = projection_variant(settings, context.scene, camera_models::drawn_model(camera));
  plan.splat_records = context.scene.count * plan.projection.seam_copies();
  plan.tiles = tile_grid(camera, settings.region);
  plan.culling_tiles = settings.compositor == Compositor::kRaster ? tile_grid(camera, {}) : plan.tiles;
  plan.compositor = settings.compositor;
  plan.depth_key_bits = uint32_t(settings.accuracy.depth_key_bits);
  const bool stochastic = settings.compositor == Compositor::kStochastic;
  const bool raster = settings.compositor == Compositor::kRaster;
  // The raster frame sorts the Gaussians by depth alone, with any strategy.
  plan.depth_first = raster || context.sort.plan == FrameSortPlan::kDepthThenTile;
  // The stochastic frame only bins by tile, in 32-bit keys whatever the strategy.
  plan.wide_keys = !stochastic && !plan.depth_first;
  // In 64-bit keys the tile id sits above bit 32 whatever the depth key's width.
  plan.sort_bits = stochastic ? plan.tiles.tile_bits
                   : raster   ? plan.depth_key_bits
                              : plan.depth_key_bits + plan.tiles.tile_bits;
  plan.resort_window = stochastic ? 0 : uint32_t(settings.accuracy.resort_window);
  plan.stochastic_samples = stochastic ? settings.stochastic.frames : 0;
  if (stochastic) {
    plan.stochastic_seed = settings.stochastic.seed;
    plan.stochastic_sampler = settings.stochastic.sampler;
  }
  plan.stochastic_accumulate = stochastic && settings.stochastic.accumulate;
  if (plan.stochastic_accumulate && !plan.build_lists)
    plan.stochastic_first_sample = context.stochastic_frames_before;
  plan.outputs = {settings.depth,
                  settings.splat_count,
                  settings.background,
                  settings.accuracy.alpha_cutoff,
                  settings.accuracy.transmittance_cutoff,
                  float(settings.max_alpha),
                  settings.accuracy.fp16_blend};
  if (settings.host) {
    plan.host.enabled = true;
    plan.host.from_memory = !settings.host->depth.empty();
    plan.host.from_image = context.depth_image;
    plan.host.write_depth = settings.host->write_depth;
    plan.host.convention = settings.host->convention;
    plan.host.surface_alpha = settings.host->alpha_threshold;
    // A pixel may stop at its first splat behind the host's surface only when the splats come in exact
    // view depth order: not with shortened keys, nor sorted by distance.
    plan.host.exact_depth_order = settings.accuracy.depth_key_bits == 32 &&
                                  settings.accuracy.sort_depth == AccuracyModes::SortDepth::kView;
  }
  if (context.samples_before)
    plan.sample_sums =
        SampleSums{*context.samples_before, settings.background != std::array<float, 3>{0, 0, 0}};

  plan.composite_chunks = std::max(context.composite_chunks, 1u);
  plan.composite_state = needs_composite_state(plan);
  plan.passes = frame_passes(plan);
  plan.splits_submissions = splits_submissions(plan);
  return plan;
}

FramePlan composite_only(FramePlan plan, uint32_t composite_chunks) {
  plan.build_lists = false;
  plan.stochastic_first_sample = 0;
  if (composite_chunks > 0) plan.composite_chunks = composite_chunks;
  plan.composite_state = needs_composite_state(plan);
  plan.passes = frame_passes(plan);
  plan.splits_submissions = splits_submissions(plan);
  return plan;
}

}  // namespace tilesplat
