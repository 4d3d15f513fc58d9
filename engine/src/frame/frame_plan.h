// The frame as a plan: everything decided about a frame before any Vulkan call. plan_frame() turns
// the scene's shape, the camera, the settings, what the device can do and what the buffers hold into
// a FramePlan, a plain value: which passes run in which order, the pipeline variants they use, the
// key widths and tile bits, and whether the tile lists are built or reused. FrameRecorder records a
// plan; plans are tested without a device (tests/test_frame_plan.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "passes/projection_variant.h"
#include "passes/tile_grid.h"
#include "sort/frame_sort_plan.h"
#include "tilesplat/camera.h"
#include "tilesplat/render_settings.h"

namespace tilesplat {

// One step of a frame, in the order FramePlan::passes lists them. Each is one host-side class's
// record() (or, for the first two, a fill of the counters).
enum class FramePass {
  kHostDepthIn,          // the host's depth image converted to view depths (render_to_image with one)
  kClearCounters,        // counters and tile ranges to zero: the lists are built from scratch
  kResetLongestList,     // only the longest-list counter to zero: the composite runs on reused lists
  kProjection,           // Gaussians -> splats, tile counts, depth keys
  kDepthQuantize,        // 16-bit depth keys over the visible depth range (depth16)
  kDepthSort,            // the Gaussians by depth key
  kPrefixSum,            // where each Gaussian's (tile, Gaussian) pairs start
  kKeyEmission,          // the pairs, front to back (or in index order for the stochastic frame)
  kTileSort,             // the pairs by tile, stably
  kTileBinning,          // the pairs grouped by tile, in any order (the stochastic frame)
  kTileRanges,           // each tile's [start, end) in the sorted pairs
  kComposite,            // front-to-back blending (composite.comp)
  kResortComposite,      // blending with per-pixel re-sorting (composite_resort.comp)
  kStochasticComposite,  // the sort-free composite (composite_stochastic.comp)
  kRasterComposite,      // the depth-sorted splats drawn as quads and blended by the hardware
  kAccumulateSamples,  // a lens or shutter sample added to the earlier samples' sums, the outputs their mean
};
// The pass's name in FrameStats::passes and the benchmark, or nullptr for a step that is not timed.
const char* timed_name(FramePass pass);

// What the device offers that shapes a frame (vk::Context's limits), without the device.
struct DeviceCaps {
  bool cpu_driver = false;  // lavapipe and the like: different loop limits and pass variants
  uint32_t vendor_id = 0;   // VkPhysicalDeviceProperties::vendorID: which GPU strategy "auto" picks
  uint32_t max_workgroup_count_x = 65535;
  uint64_t max_allocation_size = uint64_t(1) << 31;
};

// The shape of the scene on the device (what set_scene uploaded), which the projection's variant
// depends on.
struct SceneShape {
  uint64_t generation = 0;  // counts set_scene calls: lists built for an earlier scene are stale
  uint32_t count = 0;
  int sh_degree = 0;
  bool file_normals = false;  // the scene has a usable normal (SceneBuffers::file_normals)
};

// What a frame needs of its sort strategy, read off the strategy (or written out by a test).
struct SortTraits {
  std::string name;
  FrameSortPlan plan = FrameSortPlan::kDepthThenTile;
  bool sorts_on_host = false;
};

// RenderSettings::sort "auto": the fastest exact strategy for the device, by the rule tilesplat-bench
// measured (docs/benchmarks.md, "The default sort"):
//   - a CPU driver: cpu-radix, whose host sort replaces the per-digit passes that cost most there
//     (383 against 478 ms a 1080p frame of the 500k playbot on lavapipe); radix for a frame that goes
//     on without the renderer waiting for it (render_to_image with HostFrameSync or HostCommandBuffer),
//     since a host sort would stop it mid-frame and a host's command buffer cannot hold one;
//   - NVIDIA (vendor 0x10DE): onesweep, whose single-pass digits with decoupled look-back beat radix's
//     (1.74 against 2.53 ms on an H200);
//   - any other GPU: radix, which needs no forward-progress guarantee between workgroups.
// Any other name is returned as it is.
constexpr uint32_t kVendorNvidia = 0x10DE;
std::string choose_sort_strategy(const std::string& requested, const DeviceCaps& device,
                                 bool without_waiting);

// Everything a frame's tile lists depend on. When it equals the key of the lists in the buffers,
// a frame runs the composite alone: the background, the outputs requested, the stochastic frames
// and seed, and the transmittance cut-off change only the composite (the whole AccuracyModes is
// compared anyway, to keep this simple and safe).
struct ListKey {
  uint64_t scene_generation = 0;
  Camera camera;
  std::string sort;  // the strategy that ran ("auto" resolved)
  AccuracyModes accuracy;
  Antialiasing antialiasing = Antialiasing::kClassic;
  Lighting lighting;
  Compositor compositor = Compositor::kSorted;  // sorted and binned-only lists differ
  double near_plane = kDefaultNearPlane;
  PixelRegion region;  // the tiles listed

  bool operator==(const ListKey&) const = default;
};

// One part of a scene rendered in depth-ordered parts (Renderer::render(scene, camera, settings) under
// RenderSettings::memory_budget, renderer_parts.cpp): part `index`, the last or not. Each part's lists
// are built and composited like a frame's, each pixel's composite state going on from part to part
// (CompositePass::Carry); only the last part writes the images. A whole scene is the one part 0.
struct ScenePart {
  uint32_t index = 0;
  bool last = true;
  bool whole() const { return index == 0 && last; }
  bool carries_in() const { return index > 0; }
  bool carries_out() const { return !last; }
  bool state_high() const { return index % 2 == 1; }  // the composite state's halves alternate
  bool operator==(const ScenePart&) const = default;
};

// A frame's use of RenderSettings::host.
struct HostDepthPlan {
  bool enabled = false;      // RenderSettings::host is set
  bool from_memory = false;  // HostDepth::depth uploaded as view depths
  bool from_image = false;   // a depth image converted on the device (kHostDepthIn)
  bool write_depth = false;  // the composite writes the surface depth
  DepthConvention convention;  // of the host's depths (HostDepth::convention)
  float surface_alpha = 0.5f;  // HostDepth::alpha_threshold
  // The splats come in exact view-depth order (32-bit keys of view depth): a pixel may stop at its first
  // splat behind the host's surface.
  bool exact_depth_order = false;
};

// What a frame writes and how its composite blends, from the settings: the recorder and the buffers
// read these, never the settings.
struct FrameOutputs {
  bool depth = true;                            // RenderSettings::depth: the expected-depth image
  bool splat_count = true;                      // RenderSettings::splat_count
  std::array<float, 3> background = {0, 0, 0};  // RenderSettings::background
  float alpha_cutoff = 1.0f / 255.0f;           // AccuracyModes::alpha_cutoff
  float transmittance_cutoff = 1e-4f;           // AccuracyModes::transmittance_cutoff
  float max_alpha = 0.99f;                      // RenderSettings::max_alpha
  bool half_colour = false;  // AccuracyModes::fp16_blend: the raster compositor's 16-bit attachment
};

// RenderSettings::accumulate_samples: the frame is one sample of a lens or shutter frame, added to the
// sums of the samples rendered before it (kAccumulateSamples), its outputs then the mean of all.
struct SampleSums {
  uint32_t before = 0;  // samples in the sums already (0: this frame starts them)
  bool opaque = false;  // blended over a background: colours averaged as opaque (LinearFrameMean)
  bool operator==(const SampleSums&) const = default;
};

// Everything decided about one frame before any Vulkan call (plan_frame); FrameRecorder records it.
struct FramePlan {
  ListKey lists;            // what this frame's tile lists are built for
  bool build_lists = true;  // false: the composite alone, on the lists the previous frame left
  SortTraits sort;          // the strategy that runs ("auto" resolved)
  ProjectionVariant projection;
  uint32_t splat_records = 0;  // projected records: the scene's count times projection.seam_copies()
  TileGrid tiles;
  // The tiles a splat must meet to be drawn (the projection's clamp): the frame's, except for the raster
  // frame of a region, whose quads reach past a splat's tile rect (the rect's 3 sigmas against the
  // quad's opacity-aware extent): there the whole image's, so that a region draws the whole frame's splats.
  TileGrid culling_tiles;
  // Keys: the per-Gaussian depth key's bits (AccuracyModes::depth_key_bits); whether the pairs are
  // 64-bit (tile, depth) keys, for a strategy that sorts those itself; and the bits the frame's sorts
  // order by (FrameStats::sort_bits: depth + tile bits, or the tile bits alone for the stochastic
  // frame, which sorts no depth).
  uint32_t depth_key_bits = 32;
  bool wide_keys = false;
  uint32_t sort_bits = 0;
  bool depth_first = true;  // depth sort, then a tile sort of 32-bit keys (FrameSortPlan::kDepthThenTile)
  Compositor compositor = Compositor::kSorted;
  uint32_t resort_window = 0;       // kResortComposite's window (AccuracyModes::resort_window)
  uint32_t stochastic_samples = 0;  // kStochasticComposite's averaged samples (StochasticSettings::frames)
  uint32_t stochastic_seed = 0;     // StochasticSettings::seed
  StochasticSampler stochastic_sampler = StochasticSampler::kHash;
  // StochasticSettings::accumulate: the samples already in the composite state's sums (when the frame
  // reuses the lists of the frame that left them: FrameContext::stochastic_frames_before), and that the
  // sums stay for the next.
  uint32_t stochastic_first_sample = 0;
  bool stochastic_accumulate = false;
  // The composite's dispatches per tile list (CompositePass::Chunks: FrameContext::composite_chunks, or a
  // re-run's, composite_only), and whether it keeps per-pixel state between its dispatches: chunks or
  // stochastic samples that add up, the parts of a scene in parts, accumulated stochastic frames.
  uint32_t composite_chunks = 1;
  bool composite_state = false;
  FrameOutputs outputs;
  HostDepthPlan host;
  std::optional<SampleSums> sample_sums;  // a sample of an accumulated lens or shutter frame
  ScenePart part;                 // of a scene rendered in parts (or the whole scene)
  std::vector<FramePass> passes;  // in order
  // The frame ends its command buffer and goes on in another where the host must act: a host sort
  // (SortTraits::sorts_on_host), and the stochastic composite after every 64 samples
  // (StochasticCompositePass::kSamplesPerSubmission, so that no submission runs long enough for a watchdog).
  bool splits_submissions = false;

  // The names of the timed passes in order: what FrameStats::passes lists for a frame without retries.
  std::vector<std::string> timed_passes() const;
};

// Inputs of plan_frame that are not settings: what the buffers and the device hold.
struct FrameContext {
  SceneShape scene;
  DeviceCaps device;
  SortTraits sort;               // of choose_sort_strategy(settings.sort, ...)
  std::optional<ListKey> lists;  // the lists in the buffers, if whole
  bool depth_image = false;      // render_to_image with a host depth image
  ScenePart part;                // the part of the scene in the buffers
  // A sample of an accumulated lens or shutter frame (RenderSettings::accumulate_samples): the samples
  // already in the sums.
  std::optional<uint32_t> samples_before;
  // StochasticSettings::accumulate: the stochastic frames in the composite state's sums that this frame
  // continues if it reuses the lists they were rendered on (FrameAccumulator::stochastic_frames_before).
  uint32_t stochastic_frames_before = 0;
  // The composite's dispatches per tile list for this compositor, as the last frame left them
  // (FrameRecorder::composite_chunks).
  uint32_t composite_chunks = 1;
};

// Validates the camera for this device, the accuracy modes, the compositor's settings and the host
// depth (throwing std::runtime_error for a camera the device cannot render, std::invalid_argument
// for settings, as render() documents), then decides the frame.
FramePlan plan_frame(const Camera& camera, const RenderSettings& settings, const FrameContext& context);

// Refuses (std::invalid_argument) settings a scene rendered in depth-ordered parts cannot render
// exactly: another compositor, per-pixel re-sorting, 16-bit depth keys or an approximate sort.
void validate_scene_parts(const RenderSettings& settings, const std::string& sort_name);

// The same frame's composite alone, on the lists its first attempt built: the re-run of a composite
// that needed more dispatches than it had (FrameRecorder::composite_chunks), with `composite_chunks` of
// them (0: as many as the plan had). Its first attempt added to any accumulated stochastic sums already,
// so the re-run starts their mean anew.
FramePlan composite_only(FramePlan plan, uint32_t composite_chunks = 0);

// The projection a frame's accuracy modes and effects call for, on a scene of this shape.
ProjectionVariant projection_variant(const RenderSettings& settings, const SceneShape& scene,
                                     CameraModel camera_model = CameraModel::kPinhole);

}  // namespace tilesplat
