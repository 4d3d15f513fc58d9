// The frame as a plan (engine/src/frame/frame_plan.h), tested without a Vulkan device: which passes a
// frame runs in which order, its keys and variants, list reuse, the sort "auto" picks, and the
// settings a plan refuses, for every compositor, sort plan, accuracy mode and effect.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "backward/backward_plan.h"
#include "frame/frame_plan.h"
#include "frame/image_regions.h"
#include "tilesplat/reference.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {
namespace {

using P = FramePass;

Camera camera(int width = 1920, int height = 1080) {
  Camera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = 1000;
  c.cx = width / 2.0;
  c.cy = height / 2.0;
  return c;
}

const DeviceCaps kGpu{false, 0x1002, 2147483647u, uint64_t(4) << 30};  // an AMD GPU
const DeviceCaps kNvidia{false, 0x10DE, 2147483647u, uint64_t(4) << 30};
const DeviceCaps kCpuDriver{true, 0x10005, 65535, uint64_t(2) << 30};  // lavapipe's vendor (Mesa)
const SortTraits kRadix{"radix", FrameSortPlan::kDepthThenTile, false};
const SortTraits kPairs{"tile-local", FrameSortPlan::kTileDepthPairs, false};
const SortTraits kHostSort{"cpu-radix", FrameSortPlan::kDepthThenTile, true};

FrameContext context(const SortTraits& sort = kRadix, const DeviceCaps& device = kGpu) {
  FrameContext c;
  c.scene = {1, 500000, 3, false};
  c.device = device;
  c.sort = sort;
  return c;
}

TEST(FramePlan, SortedFrameIsDepthSortThenTileSort) {
  const FramePlan plan = plan_frame(camera(), {}, context());
  EXPECT_EQ(plan.passes, (std::vector<P>{P::kClearCounters, P::kProjection, P::kDepthSort, P::kPrefixSum,
                                         P::kKeyEmission, P::kTileSort, P::kTileRanges, P::kComposite}));
  EXPECT_EQ(plan.timed_passes(),
            (std::vector<std::string>{"projection", "depth_sort", "prefix_sum", "key_emission", "tile_sort",
                                      "tile_ranges", "composite"}));
  EXPECT_TRUE(plan.build_lists);
  EXPECT_TRUE(plan.depth_first);
  EXPECT_FALSE(plan.wide_keys);
  // 1920x1080: 120 x 68 tiles, ids 0..8160 in 13 bits; 32 depth bits besides.
  EXPECT_EQ(plan.tiles.tiles_x, 120u);
  EXPECT_EQ(plan.tiles.tiles_y, 68u);
  EXPECT_EQ(plan.tiles.count, 8160u);
  EXPECT_EQ(plan.tiles.tile_bits, 13u);
  EXPECT_EQ(plan.sort_bits, 32u + 13u);
  EXPECT_FALSE(plan.splits_submissions);
  EXPECT_EQ(plan.lists.sort, "radix");
}

TEST(FramePlan, StrategySortingPairsItselfUsesWideKeysAndNoDepthSort) {
  const FramePlan plan = plan_frame(camera(), {}, context(kPairs));
  EXPECT_EQ(plan.passes, (std::vector<P>{P::kClearCounters, P::kProjection, P::kPrefixSum, P::kKeyEmission,
                                         P::kTileSort, P::kTileRanges, P::kComposite}));
  EXPECT_TRUE(plan.wide_keys);
  EXPECT_FALSE(plan.depth_first);
  EXPECT_EQ(plan.sort_bits, 32u + 13u);
}

TEST(FramePlan, Depth16QuantizesAfterTheProjection) {
  RenderSettings settings;
  settings.accuracy = parse_accuracy_modes("depth16");
  const FramePlan plan = plan_frame(camera(), settings, context());
  ASSERT_GE(plan.passes.size(), 3u);
  EXPECT_EQ(plan.passes[1], P::kProjection);
  EXPECT_EQ(plan.passes[2], P::kDepthQuantize);
  EXPECT_EQ(plan.depth_key_bits, 16u);
  EXPECT_EQ(plan.sort_bits, 16u + 13u);
  EXPECT_EQ(plan.projection.depth_key_bits, 16u);
}

TEST(FramePlan, StochasticFrameBinsWithoutDepthSort) {
  RenderSettings settings;
  settings.compositor = Compositor::kStochastic;
  for (const SortTraits& sort : {kRadix, kPairs}) {
    const FramePlan plan = plan_frame(camera(), settings, context(sort));
    EXPECT_EQ(plan.passes, (std::vector<P>{P::kClearCounters, P::kProjection, P::kPrefixSum, P::kKeyEmission,
                                           P::kTileBinning, P::kTileRanges, P::kStochasticComposite}))
        << sort.name;
    EXPECT_FALSE(plan.wide_keys) << sort.name;  // 32-bit tile keys whatever the strategy
    EXPECT_EQ(plan.sort_bits, 13u) << sort.name;
    EXPECT_EQ(plan.stochastic_samples, settings.stochastic.frames);
  }
  // Past 64 samples the composite goes on in another submission.
  settings.stochastic.frames = 65;
  EXPECT_TRUE(plan_frame(camera(), settings, context()).splits_submissions);
  settings.stochastic.frames = 64;
  EXPECT_FALSE(plan_frame(camera(), settings, context()).splits_submissions);
}

TEST(FramePlan, ResortModesUseTheResortCompositeAndRayDepths) {
  RenderSettings settings;
  settings.accuracy = parse_accuracy_modes("resort8");
  const FramePlan plan = plan_frame(camera(), settings, context());
  EXPECT_EQ(plan.passes.back(), P::kResortComposite);
  EXPECT_EQ(plan.resort_window, 8u);
  EXPECT_TRUE(plan.projection.ray_depth);
  EXPECT_EQ(plan.timed_passes().back(), "composite");
}

TEST(FramePlan, HostSortSplitsTheSubmission) {
  EXPECT_TRUE(plan_frame(camera(), {}, context(kHostSort)).splits_submissions);
  // Reused lists run no sort.
  FrameContext c = context(kHostSort);
  c.lists = plan_frame(camera(), {}, c).lists;
  EXPECT_FALSE(plan_frame(camera(), {}, c).splits_submissions);
}

TEST(FramePlan, HostDepthImageIsConvertedFirstOnEveryAttempt) {
  RenderSettings settings;
  settings.host = HostDepth{};
  settings.host->write_depth = true;
  FrameContext c = context();
  c.depth_image = true;
  const FramePlan plan = plan_frame(camera(), settings, c);
  EXPECT_EQ(plan.passes.front(), P::kHostDepthIn);
  EXPECT_TRUE(plan.host.from_image);
  EXPECT_FALSE(plan.host.from_memory);
  EXPECT_TRUE(plan.host.write_depth);
  const FramePlan again = composite_only(plan);
  EXPECT_EQ(again.passes, (std::vector<P>{P::kHostDepthIn, P::kResetLongestList, P::kComposite}));
  EXPECT_FALSE(again.build_lists);
}

// The recorder reads the plan and the resources only: what it needs of the settings is in the plan.
TEST(FramePlan, CarriesWhatTheRecorderNeedsOfTheSettings) {
  RenderSettings settings;
  settings.depth = false;
  settings.background = {0.25f, 0.5f, 1.0f};
  settings.max_alpha = 0.999;
  settings.accuracy = parse_accuracy_modes("alpha-cutoff=1/64+t-cutoff=0.001");
  const FramePlan sorted = plan_frame(camera(), settings, context());
  EXPECT_FALSE(sorted.outputs.depth);
  EXPECT_TRUE(sorted.outputs.splat_count);
  EXPECT_EQ(sorted.outputs.background, settings.background);
  EXPECT_FLOAT_EQ(sorted.outputs.max_alpha, 0.999f);
  EXPECT_FLOAT_EQ(sorted.outputs.alpha_cutoff, 1.0f / 64);
  EXPECT_FLOAT_EQ(sorted.outputs.transmittance_cutoff, 0.001f);
  EXPECT_FALSE(sorted.host.enabled);

  RenderSettings stochastic;
  stochastic.compositor = Compositor::kStochastic;
  stochastic.stochastic = {8, 42, StochasticSampler::kSobol, false};
  const FramePlan binned = plan_frame(camera(), stochastic, context());
  EXPECT_EQ(binned.stochastic_samples, 8u);
  EXPECT_EQ(binned.stochastic_seed, 42u);
  EXPECT_EQ(binned.stochastic_sampler, StochasticSampler::kSobol);

  RenderSettings hosted;
  hosted.host = HostDepth{};
  hosted.host->convention = DepthConvention{0.0, 0.1};  // reversed-Z, infinite far plane
  hosted.host->alpha_threshold = 0.75f;
  hosted.host->write_depth = true;
  const FramePlan host = plan_frame(camera(), hosted, context());
  EXPECT_TRUE(host.host.enabled);
  EXPECT_TRUE(host.host.write_depth);
  EXPECT_EQ(host.host.convention, hosted.host->convention);
  EXPECT_FLOAT_EQ(host.host.surface_alpha, 0.75f);
  EXPECT_TRUE(host.host.exact_depth_order);
  hosted.accuracy.depth_key_bits = 24;
  EXPECT_FALSE(plan_frame(camera(), hosted, context()).host.exact_depth_order) << "shortened keys";
  hosted.accuracy = parse_accuracy_modes("radial");
  EXPECT_FALSE(plan_frame(camera(), hosted, context()).host.exact_depth_order) << "sorted by distance";
}

// Whether the composite keeps per-pixel state between its dispatches is the plan's to say, from the
// dispatches the last frame left (FrameContext::composite_chunks) or a re-run's.
TEST(FramePlan, DecidesTheCompositeState) {
  FrameContext c = context();
  const FramePlan one = plan_frame(camera(), {}, c);
  EXPECT_EQ(one.composite_chunks, 1u);
  EXPECT_FALSE(one.composite_state);
  const FramePlan rerun = composite_only(one, 3);
  EXPECT_EQ(rerun.composite_chunks, 3u);
  EXPECT_TRUE(rerun.composite_state) << "chunks carry their pixels' state";
  EXPECT_EQ(composite_only(rerun).composite_chunks, 3u) << "0 keeps the plan's";
  c.composite_chunks = 2;
  EXPECT_TRUE(plan_frame(camera(), {}, c).composite_state);
  c.composite_chunks = 1;
  c.part = ScenePart{0, false};
  EXPECT_TRUE(plan_frame(camera(), {}, c).composite_state) << "the next part goes on from these pixels";
  c.part = {};
  RenderSettings raster;
  raster.compositor = Compositor::kRaster;
  c.composite_chunks = 4;
  EXPECT_FALSE(plan_frame(camera(), raster, c).composite_state) << "the hardware blends";
  c.composite_chunks = 1;
  RenderSettings stochastic;
  stochastic.compositor = Compositor::kStochastic;
  stochastic.stochastic.frames = 1;
  EXPECT_FALSE(plan_frame(camera(), stochastic, c).composite_state);
  stochastic.stochastic.accumulate = true;
  EXPECT_TRUE(plan_frame(camera(), stochastic, c).composite_state) << "frames that add up across calls";
  stochastic.stochastic = {};
  EXPECT_TRUE(plan_frame(camera(), stochastic, c).composite_state) << "16 samples summed";
}

TEST(FramePlan, ListsAreReusedOnlyWhenEverythingTheyDependOnIsEqual) {
  FrameContext c = context();
  const Camera cam = camera();
  c.lists = plan_frame(cam, {}, c).lists;
  const FramePlan reused = plan_frame(cam, {}, c);
  EXPECT_FALSE(reused.build_lists);
  EXPECT_EQ(reused.passes, (std::vector<P>{P::kResetLongestList, P::kComposite}));

  // What only the composite reads may change.
  RenderSettings composite_only_changes;
  composite_only_changes.background = {1, 0, 0};
  composite_only_changes.depth = false;
  composite_only_changes.splat_count = false;
  EXPECT_FALSE(plan_frame(cam, composite_only_changes, c).build_lists);

  // Anything the lists depend on rebuilds them.
  std::vector<std::pair<std::string, RenderSettings>> changes;
  RenderSettings s;
  s.accuracy = parse_accuracy_modes("sh1");
  changes.push_back({"accuracy", s});
  s = {};
  s.antialiasing = Antialiasing::kMip;
  changes.push_back({"antialiasing", s});
  s = {};
  s.lighting.lights.push_back({});
  changes.push_back({"lighting", s});
  s = {};
  s.compositor = Compositor::kStochastic;
  changes.push_back({"compositor", s});
  s = {};
  s.near_plane = 0.01;
  changes.push_back({"near_plane", s});
  s = {};
  s.reuse_lists = false;
  changes.push_back({"reuse_lists off", s});
  for (const auto& [what, settings] : changes) EXPECT_TRUE(plan_frame(cam, settings, c).build_lists) << what;

  Camera moved = cam;
  moved.position[0] += 0.01;
  EXPECT_TRUE(plan_frame(moved, {}, c).build_lists);
  FrameContext other_sort = c;
  other_sort.sort = kPairs;
  EXPECT_TRUE(plan_frame(cam, {}, other_sort).build_lists);
  FrameContext new_scene = c;
  new_scene.scene.generation = 2;
  EXPECT_TRUE(plan_frame(cam, {}, new_scene).build_lists);
}

TEST(FramePlan, AutoSortIsCpuRadixOnCpuDriversOnesweepOnNvidiaAndRadixElsewhere) {
  EXPECT_EQ(choose_sort_strategy("auto", kCpuDriver, false), "cpu-radix");
  EXPECT_EQ(choose_sort_strategy("auto", kNvidia, false), "onesweep");
  EXPECT_EQ(choose_sort_strategy("auto", kGpu, false), "radix");
  // A frame the renderer does not wait for cannot stop for a host sort: the best device strategy.
  EXPECT_EQ(choose_sort_strategy("auto", kCpuDriver, true), "radix");
  EXPECT_EQ(choose_sort_strategy("auto", kNvidia, true), "onesweep");
  EXPECT_EQ(choose_sort_strategy("auto", kGpu, true), "radix");
  for (const char* named : {"radix", "onesweep", "bitonic", "tile-local", "cpu-radix", "cpu-radix16"}) {
    EXPECT_EQ(choose_sort_strategy(named, kCpuDriver, false), named);
    EXPECT_EQ(choose_sort_strategy(named, kGpu, true), named);
  }
}

TEST(FramePlan, RefusesWhatTheDeviceOrCompositorCannotDo) {
  // More tiles per axis than a CPU driver's loops allow, and a colour buffer beyond one allocation.
  EXPECT_THROW(plan_frame(camera(16384 * 16 + 16, 16), {}, context(kRadix, kCpuDriver)), std::runtime_error);
  DeviceCaps small = kGpu;
  small.max_allocation_size = 1 << 20;
  try {
    plan_frame(camera(1024, 1024), {}, context(kRadix, small));
    FAIL() << "a 16 MiB colour buffer on a device of 1 MiB allocations";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("largest allocation"), std::string::npos) << e.what();
  }
  Camera bad = camera();
  bad.fx = -1;
  EXPECT_THROW(plan_frame(bad, {}, context()), std::runtime_error);

  RenderSettings stochastic;
  stochastic.compositor = Compositor::kStochastic;
  for (const char* modes : {"resort4", "depth16", "depth24"}) {
    stochastic.accuracy = parse_accuracy_modes(modes);
    EXPECT_THROW(plan_frame(camera(), stochastic, context()), std::invalid_argument) << modes;
  }
  stochastic.accuracy = {};
  stochastic.stochastic.frames = 0;
  EXPECT_THROW(plan_frame(camera(), stochastic, context()), std::invalid_argument);

  RenderSettings bad_modes;
  bad_modes.accuracy.resort_window = 99;
  EXPECT_THROW(plan_frame(camera(), bad_modes, context()), std::invalid_argument);
  for (const double near_plane : {0.0, -0.5, std::numeric_limits<double>::infinity()}) {
    RenderSettings bad_near;
    bad_near.near_plane = near_plane;
    EXPECT_THROW(plan_frame(camera(), bad_near, context()), std::invalid_argument) << near_plane;
  }
  for (const double max_alpha : {0.0, 1.0, std::numeric_limits<double>::quiet_NaN()}) {
    RenderSettings bad_cap;
    bad_cap.max_alpha = max_alpha;
    EXPECT_THROW(plan_frame(camera(), bad_cap, context()), std::invalid_argument) << max_alpha;
  }
  // A lens is averaged above the plan (Renderer::render): one frame's plan takes none, nor a bad one.
  for (const double aperture : {0.1, -0.1}) {
    RenderSettings with_lens;
    with_lens.lens.aperture_diameter = aperture;
    EXPECT_THROW(plan_frame(camera(), with_lens, context()), std::invalid_argument) << aperture;
  }
}

TEST(FramePlan, EffectsReachTheProjectionVariant) {
  RenderSettings settings;
  SceneShape scene{1, 10, 2, true};
  ProjectionVariant v = projection_variant(settings, scene);
  EXPECT_EQ(v.sh_degree, 2);
  EXPECT_EQ(v.stored_sh_degree, 2);
  EXPECT_FALSE(v.lighting);
  EXPECT_FALSE(v.file_normals);  // normals are read only when lit
  EXPECT_EQ(v.dilation_tenths, 3u);
  EXPECT_FALSE(v.compensate_opacity);

  settings.lighting.lights.push_back({});
  settings.antialiasing = Antialiasing::kMip;
  settings.accuracy =
      parse_accuracy_modes("sh1+fp16-sh+fp16-cov+opacity-extent+square-tiles+alpha-cutoff=1/64");
  v = projection_variant(settings, scene);
  EXPECT_TRUE(v.lighting);
  EXPECT_TRUE(v.file_normals);
  EXPECT_EQ(v.sh_degree, 1);
  EXPECT_EQ(v.dilation_tenths, 1u);
  EXPECT_TRUE(v.compensate_opacity);
  EXPECT_TRUE(v.sh_half && v.covariance_half && v.opacity_extent && v.square_tiles);
  EXPECT_EQ(v.alpha_inv, 64.0f);
  scene.file_normals = false;
  EXPECT_FALSE(projection_variant(settings, scene).file_normals);
}

// Every accuracy mode with every sort plan and compositor: a plan clears first (or resets the longest
// list), ends in exactly one composite, sorts by depth exactly when it should, and times each pass
// once.
TEST(FramePlan, EveryModeStrategyAndCompositorGivesAWellFormedPlan) {
  const std::vector<std::string> modes = {"reference",
                                          "depth24",
                                          "depth16",
                                          "opacity-extent",
                                          "square-tiles",
                                          "sh0",
                                          "sh1",
                                          "sh2",
                                          "fp16-sh",
                                          "fp16-cov",
                                          "t-cutoff=0.001",
                                          "alpha-cutoff=1/64",
                                          "resort4",
                                          "resort16",
                                          "depth16+sh1+fp16-cov+opacity-extent"};
  int plans = 0;
  for (const std::string& mode : modes)
    for (const SortTraits& sort : {kRadix, kPairs, kHostSort})
      for (Compositor compositor : {Compositor::kSorted, Compositor::kStochastic}) {
        RenderSettings settings;
        settings.accuracy = parse_accuracy_modes(mode);
        settings.compositor = compositor;
        const std::string what = mode + " / " + sort.name + " / " + to_string(compositor);
        const bool stochastic = compositor == Compositor::kStochastic;
        if (stochastic && (settings.accuracy.resort_window > 0 || settings.accuracy.depth_key_bits != 32)) {
          EXPECT_THROW(plan_frame(camera(), settings, context(sort)), std::invalid_argument) << what;
          continue;
        }
        const FramePlan plan = plan_frame(camera(), settings, context(sort));
        ++plans;
        EXPECT_EQ(plan.passes.front(), P::kClearCounters) << what;
        const auto composites = std::count_if(plan.passes.begin(), plan.passes.end(), [](P p) {
          return p == P::kComposite || p == P::kResortComposite || p == P::kStochasticComposite;
        });
        EXPECT_EQ(composites, 1) << what;
        const bool depth_sort =
            std::find(plan.passes.begin(), plan.passes.end(), P::kDepthSort) != plan.passes.end();
        EXPECT_EQ(depth_sort, !stochastic && sort.plan == FrameSortPlan::kDepthThenTile) << what;
        const bool quantize =
            std::find(plan.passes.begin(), plan.passes.end(), P::kDepthQuantize) != plan.passes.end();
        EXPECT_EQ(quantize, settings.accuracy.depth_key_bits == 16) << what;
        std::vector<std::string> names = plan.timed_passes();
        std::sort(names.begin(), names.end());
        EXPECT_EQ(std::adjacent_find(names.begin(), names.end()), names.end()) << what;
        EXPECT_EQ(plan.splits_submissions, sort.sorts_on_host) << what;
        EXPECT_EQ(plan.projection.sh_degree, std::min(3, settings.accuracy.sh_degree_cap)) << what;
      }
  EXPECT_EQ(plans, 15 * 3 + 10 * 3);  // five of the modes change the depth order
}

// The raster frame: the Gaussians sorted by depth (whatever the strategy's own plan), then drawn; no
// tile lists. On reused lists it re-draws; re-sorting per pixel and a host's depth are refused.
TEST(FramePlan, RasterFrameSortsByDepthThenDraws) {
  RenderSettings settings;
  settings.compositor = Compositor::kRaster;
  for (const SortTraits& sort : {kRadix, kPairs, kHostSort}) {
    const FramePlan plan = plan_frame(camera(), settings, context(sort));
    EXPECT_EQ(plan.passes,
              (std::vector<P>{P::kClearCounters, P::kProjection, P::kDepthSort, P::kRasterComposite}))
        << sort.name;
    EXPECT_EQ(plan.timed_passes(),
              (std::vector<std::string>{"projection", "depth_sort", "raster_composite"}));
    EXPECT_TRUE(plan.depth_first) << sort.name;
    EXPECT_FALSE(plan.wide_keys) << sort.name;
    EXPECT_EQ(plan.sort_bits, 32u) << sort.name;
    EXPECT_EQ(plan.splits_submissions, sort.sorts_on_host) << sort.name;
  }
  settings.accuracy = parse_accuracy_modes("depth16");
  FramePlan plan = plan_frame(camera(), settings, context());
  EXPECT_EQ(plan.passes, (std::vector<P>{P::kClearCounters, P::kProjection, P::kDepthQuantize, P::kDepthSort,
                                         P::kRasterComposite}));
  EXPECT_EQ(plan.sort_bits, 16u);
  settings.accuracy = {};
  settings.reuse_lists = true;
  FrameContext reuse = context();
  reuse.lists = plan_frame(camera(), settings, reuse).lists;
  plan = plan_frame(camera(), settings, reuse);
  EXPECT_FALSE(plan.build_lists);
  EXPECT_EQ(plan.passes, (std::vector<P>{P::kRasterComposite}));
  settings.compositor = Compositor::kSorted;  // lists built for the raster frame are not tile lists
  EXPECT_TRUE(plan_frame(camera(), settings, reuse).build_lists);

  RenderSettings resort;
  resort.compositor = Compositor::kRaster;
  resort.accuracy = parse_accuracy_modes("resort8");
  EXPECT_THROW(plan_frame(camera(), resort, context()), std::invalid_argument);

  // A host's depth image is converted first, into the draw's depth attachment; the draw itself writes
  // the splats' depth out (no pass of its own).
  RenderSettings host;
  host.compositor = Compositor::kRaster;
  host.host = HostDepth{};
  FrameContext with_image = context();
  with_image.depth_image = true;
  EXPECT_EQ(plan_frame(camera(), host, with_image).passes,
            (std::vector<P>{P::kHostDepthIn, P::kClearCounters, P::kProjection, P::kDepthSort,
                            P::kRasterComposite}));
  host.host->write_depth = true;
  EXPECT_EQ(plan_frame(camera(), host, with_image).passes,
            (std::vector<P>{P::kHostDepthIn, P::kClearCounters, P::kProjection, P::kDepthSort,
                            P::kRasterComposite}));
}

// CPU drivers take the texel-buffer layouts before Mesa 25 only (vk::texel_buffers_wanted), by the
// driver's description.
// A region's frame: the tiles it meets, in the camera's grid, their pixels within the image as its outputs;
// the raster frame culls by the whole image's tiles.
TEST(FramePlan, ARegionsFrameHasTheTilesItMeets) {
  RenderSettings settings;
  settings.region = {37, 1070, 101, 10};  // columns 37..137, rows 1070..1079: tiles 2..8 of the last row
  const FramePlan plan = plan_frame(camera(), settings, context());
  EXPECT_EQ(plan.tiles.first_x, 2u);
  EXPECT_EQ(plan.tiles.first_y, 66u);
  EXPECT_EQ(plan.tiles.tiles_x, 7u);
  EXPECT_EQ(plan.tiles.tiles_y, 2u);  // rows 1056..1079: the image's last tile row is partial
  EXPECT_EQ(plan.tiles.width, 112u);
  EXPECT_EQ(plan.tiles.height, 24u);
  EXPECT_EQ(plan.tiles.count, 14u);
  EXPECT_EQ(plan.tiles.packed_first(), 2u | 66u << 16);
  EXPECT_EQ(plan.culling_tiles, plan.tiles);
  EXPECT_EQ(plan.lists.region, settings.region);
  settings.compositor = Compositor::kRaster;
  const FramePlan raster = plan_frame(camera(), settings, context());
  EXPECT_EQ(raster.culling_tiles.first_x, 0u);
  EXPECT_EQ(raster.culling_tiles.tiles_x, 120u);
  EXPECT_EQ(raster.tiles, plan.tiles);
  // The whole image is the region of the whole image.
  EXPECT_EQ(plan_frame(camera(), {}, context()).tiles.packed_first(), 0u);
}

// Bands of whole tile rows cover a region once; one band where its tiles' pixels fit.
TEST(ImageBands, CoverTheRegionInWholeTileRows) {
  const PixelRegion region{5, 21, 300, 200};  // tiles' pixels: columns 0..319, rows 16..223
  EXPECT_EQ(bands_within(region, 64, uint64_t(320) * 208 * 64), (std::vector<PixelRegion>{region}));
  const std::vector<PixelRegion> bands = bands_within(region, 64, uint64_t(320) * 208 * 64 - 1);
  ASSERT_GT(bands.size(), 1u);
  int y = region.y;
  for (size_t b = 0; b < bands.size(); ++b) {
    EXPECT_EQ(bands[b].x, region.x);
    EXPECT_EQ(bands[b].width, region.width);
    EXPECT_EQ(bands[b].y, y) << b;
    if (b > 0) {
      EXPECT_EQ(bands[b].y % kTileSize, 0) << b;  // every band after the first starts a tile row
    }
    y += bands[b].height;
  }
  EXPECT_EQ(y, region.y + region.height);
  // At least a row of tiles a band, however small the limit.
  EXPECT_EQ(bands_within(region, 64, 1).size(), 13u);  // rows 21..31, then 11 of 16, then 208..220
}

TEST(TexelLayouts, MesaMajorVersionFromTheDriverDescription) {
  EXPECT_EQ(vk::mesa_major_version("llvmpipe Mesa 22.3.6 (LLVM 15.0.6)"), 22);
  EXPECT_EQ(vk::mesa_major_version("llvmpipe Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)"), 25);
  EXPECT_EQ(vk::mesa_major_version("llvmpipe Mesa 100.1"), 100);
  EXPECT_EQ(vk::mesa_major_version("NVIDIA 580.159.04"), 0);
  EXPECT_EQ(vk::mesa_major_version("SwiftShader driver 5.0.0"), 0);
  EXPECT_EQ(vk::mesa_major_version("Mesa "), 0);
}

// The backward of a sorted frame (backward/backward_plan.h): its passes in order, what it takes of the
// forward's plan, and the forward plans it refuses to follow.
TEST(BackwardPlan, FollowsASortedFrameWithItsOwnPasses) {
  RenderSettings settings;
  settings.background = {0.1f, 0.2f, 0.3f};
  settings.max_alpha = 0.999;
  settings.antialiasing = Antialiasing::kAntialiased;
  const FrameContext c = context();
  const BackwardPlan plan = plan_backward(plan_frame(camera(), settings, c), c.scene, true);
  EXPECT_EQ(plan.passes,
            (std::vector<BackwardPass>{BackwardPass::kClearGradients, BackwardPass::kCompositeBackward,
                                       BackwardPass::kProjectionBackward}));
  EXPECT_EQ(timed_name(BackwardPass::kClearGradients), nullptr);
  EXPECT_STREQ(timed_name(BackwardPass::kCompositeBackward), "composite_backward");
  EXPECT_EQ(plan.tiles.tiles_x, 120u);
  EXPECT_EQ(plan.background, settings.background);
  EXPECT_EQ(plan.max_alpha, 0.999f);
  EXPECT_EQ(plan.antialiasing, Antialiasing::kAntialiased);
  EXPECT_EQ(plan.gaussians, 500000u);
  EXPECT_EQ(plan.sh_degree, 3);
  EXPECT_TRUE(plan.float_atomics);
}

TEST(BackwardPlan, RefusesAForwardItCannotFollow) {
  const FrameContext c = context();
  RenderSettings stochastic;
  stochastic.compositor = Compositor::kStochastic;
  EXPECT_THROW(plan_backward(plan_frame(camera(), stochastic, c), c.scene, true), std::logic_error);
  RenderSettings resort;
  resort.accuracy.resort_window = 8;
  EXPECT_THROW(plan_backward(plan_frame(camera(), resort, c), c.scene, true), std::logic_error);
  RenderSettings region;
  region.region = {512, 512, 64, 64};
  EXPECT_THROW(plan_backward(plan_frame(camera(), region, c), c.scene, true), std::logic_error);
}

}  // namespace
}  // namespace tilesplat
