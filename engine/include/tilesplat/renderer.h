/// @file
/// The GPU renderer: a Vulkan compute pipeline that turns a GaussianScene and a Camera into an image.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/export.h"
#include "tilesplat/gradients.h"
#include "tilesplat/image.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/scene.h"

namespace tilesplat {

/// How Renderer::create() sets up its device.
struct RendererOptions {
  /// Which Vulkan device: "" = the environment variable TILESPLAT_DEVICE if set, else the first
  /// discrete GPU, else the first device. Otherwise a device index ("1"), the device's UUID
  /// (list_device_uuids(); on NVIDIA the GPU UUID that CUDA, nvidia-smi and cluster schedulers report:
  /// a "GPU-" prefix, dashes and case do not matter), or a case-insensitive substring of the device
  /// name ("llvmpipe"). Vulkan ignores CUDA_VISIBLE_DEVICES: pass the UUID a scheduler assigned.
  std::string device;
  /// Enables VK_LAYER_KHRONOS_validation. Also enabled by TILESPLAT_VALIDATION=1. Messages are
  /// printed to stderr and counted in Renderer::validation_messages().
  bool validation = false;
  /// Record GPU timestamps around every pass (cheap; on by default).
  bool timestamps = true;
};

/// The GPU time of one pass of a frame.
struct PassTiming {
  std::string name;  ///< the pass ("projection", "depth_sort", "composite", ...); may change between versions
  double gpu_ms = 0;  ///< its duration on the GPU, from timestamps, in milliseconds
};

/// What the last frame did and cost (Renderer::last_frame_stats()).
struct FrameStats {
  std::vector<PassTiming> passes;  ///< GPU time of each pass, in frame order
  double gpu_ms = 0;               ///< first pass start to last pass end
  double cpu_ms = 0;               ///< wall time of render(), readback included
  uint64_t gaussians = 0;          ///< Gaussians in the scene
  uint64_t visible = 0;            ///< Gaussians touching at least one tile
  uint64_t intersections = 0;      ///< (Gaussian, tile) pairs sorted
  uint32_t sort_bits = 0;  ///< key bits sorted: 32 depth bits (per Gaussian) + the tile bits (per pair)
  /// The sort strategy that ran: RenderSettings::sort, or the one "auto" chose for this device.
  std::string sort_strategy;
  int retries = 0;         ///< re-renders after growing the intersection buffers
  /// Command buffers the frame took: 1, more for a strategy that sorts on the host; 0 when recorded
  /// into a host's (HostCommandBuffer).
  int submissions = 0;
  uint64_t sort_fallbacks = 0;  ///< onesweep look-backs that gave up waiting and counted keys themselves
  uint64_t device_bytes = 0;    ///< device memory held by the renderer's buffers
  /// True when the frame ran only its composite, on the tile lists the previous frame left in the
  /// buffers: the scene (no set_scene since), the camera, the sort strategy, the accuracy modes, the
  /// antialiasing, the lighting and the compositor were all the previous frame's (the background, the
  /// outputs requested and the stochastic frames and seed may differ), and RenderSettings::reuse_lists
  /// was on. `passes` then lists the composite alone, sort_bits is 0, and visible and intersections
  /// describe the reused lists. (For the stochastic compositor the lists are binned, not sorted.)
  bool reused_sorted_lists = false;
  /// Bytes the host transferred into device buffers since the previous frame's statistics: the camera
  /// and light parameters of this frame (a few hundred bytes, none when the lists are reused), the
  /// normals on a scene's first lit frame, and everything a set_scene() since the previous frame
  /// uploaded. A host sort strategy (cpu-radix) moves the pairs through host memory besides.
  uint64_t uploaded_bytes = 0;
  /// False for a frame that render_to_image submitted without waiting (HostFrameSync) and that needed
  /// more (tile, Gaussian) pairs or composite chunks than the buffers held: it was drawn without those
  /// that did not fit, and the buffers grew for the next frame. Frames that wait re-render instead.
  bool complete = true;
  /// Pinhole frames averaged into this one: 1, or the lens's samples times the shutter's
  /// (RenderSettings::lens, shutter). Over several, gpu_ms and passes are the sums, visible and
  /// intersections the largest of any sample.
  int samples = 1;
  /// The stochastic compositor's frames in this image's mean: StochasticSettings::frames, plus the
  /// earlier calls' when StochasticSettings::accumulate continued them; 0 for the other compositors.
  uint32_t accumulated_frames = 0;
  /// The lens and shutter samples in this image's mean under RenderSettings::accumulate_samples: this
  /// call's and the earlier calls' it continued; 0 otherwise.
  uint32_t accumulated_samples = 0;
  /// Parts the scene was rendered in (Renderer::render(scene, camera, settings) under
  /// RenderSettings::memory_budget): 1 for a whole scene. Over several, gpu_ms, passes, visible,
  /// intersections, retries, submissions and uploaded_bytes are the sums over the parts.
  int scene_parts = 1;
  /// Bands of rows the image was rendered in, one after another (each a RenderSettings::region): 1, or
  /// more for an image whose per-pixel buffers would pass the device's largest allocation or a quarter
  /// of its memory (docs/big-scenes.md, "Images past the device"). Over several, gpu_ms, passes,
  /// intersections, retries, submissions and uploaded_bytes are the sums over the bands.
  int image_bands = 1;
  /// The most device memory the renderer's buffers held at the end of any part (device_bytes is the
  /// last part's); the same as device_bytes for a whole scene.
  uint64_t peak_device_bytes = 0;
  /// Host time spent ordering the scene by depth before its parts (on the host's cores; 0 for a whole
  /// scene). Over several bands or samples, the sum.
  double depth_order_ms = 0;
  /// Finite values that the frame's outputs could not hold, each stored as the largest finite value of its
  /// type with its sign instead of an infinity: render_to_image into an R16G16B16A16_SFLOAT image counts the
  /// colours past half's range (channel "host image RGBA"); a frame of accumulated samples
  /// (RenderSettings::accumulate_samples) counts the linear colours, of a sample or of the samples' mean, past
  /// float's range (channel "linear sample mean RGB"). Otherwise render() returns floats, which hold every
  /// value, and leaves it empty. Files are written after the frame: write_exr() returns its own counts, which
  /// tilesplat-render adds here for --stats.
  SaturatedValues saturated;
};

/// The Vulkan device a renderer runs on, and the limits that shape its passes.
struct DeviceInfo {
  std::string name;                       ///< VkPhysicalDeviceProperties::deviceName
  std::string driver;                     ///< driver name and version
  uint32_t subgroup_size = 0;             ///< compute subgroup size (8 on lavapipe, 32 on NVIDIA)
  uint64_t max_storage_buffer_range = 0;  ///< the largest storage buffer binding, in bytes
  uint32_t max_shared_memory = 0;         ///< workgroup shared memory, in bytes
  double timestamp_period_ns = 0;         ///< nanoseconds per timestamp tick
  uint32_t max_image_dimension = 0;  ///< the largest width or height a frame may have (maxImageDimension2D)
  /// A CPU implementation of Vulkan (lavapipe, SwiftShader: VK_PHYSICAL_DEVICE_TYPE_CPU), where "auto"
  /// sorts with cpu-radix.
  bool cpu = false;
  uint32_t vendor_id =
      0;  ///< VkPhysicalDeviceProperties::vendorID, the PCI vendor (0x10DE NVIDIA, 0x1002 AMD, ...)
  /// The largest buffer the device allocates, in bytes (maxMemoryAllocationSize): a frame whose
  /// largest buffer would be larger is rendered in parts (Renderer::render(scene, camera, settings)).
  uint64_t max_allocation_size = 0;
  /// The memory device buffers draw on, in bytes: VK_EXT_memory_budget's budget for this process where
  /// the driver has it, else the device-local heap's size (the host's physical memory for a CPU driver,
  /// whose device memory is the host's). A frame without a memory budget takes at most 3/4 of it.
  uint64_t device_memory = 0;
};

struct SceneInstances;        // tilesplat/scene_description.h
class LodSet;                 // tilesplat/lod_set.h
class SceneInParts;           // tilesplat/scene_in_parts.h (MappedPly, its earlier name)
struct ExternalVulkanDevice;  // tilesplat/vulkan_interop.h
struct ExternalImage;
struct ExternalDepthImage;
struct HostFrameSync;
struct HostCommandBuffer;

/// Names of the available sort strategies: the built-in ones, then those registered at run time.
/// RenderSettings::sort also takes "auto", which picks one of them per device.
TILESPLAT_API std::vector<std::string> sort_strategies();
/// Whether a strategy gives the exact order that all exact strategies share (and so bit-identical
/// images); false for one that sorts by approximated keys (cpu-radix16: 16-bit quantized depths).
/// True for "auto", which picks only exact strategies. Throws std::invalid_argument for an unknown name.
TILESPLAT_API bool sort_strategy_is_exact(const std::string& name);

/// Lists the Vulkan devices this machine has, in the order RendererOptions::device indexes them.
TILESPLAT_API std::vector<std::string> list_devices();
/// The devices' UUIDs (VkPhysicalDeviceIDProperties::deviceUUID) as 8-4-4-4-12 lower-case hex, in the
/// order of list_devices(). RendererOptions::device accepts them.
TILESPLAT_API std::vector<std::string> list_device_uuids();

/// The engine's internal access to a Renderer's implementation (engine/src/renderer.cpp): not part of the
/// API.
struct RendererAccess;

/// The GPU renderer: a Vulkan device, the scene in device memory, and the compute passes of a frame
/// (projection, key emission, sorts, tile ranges, composite). Not thread-safe: use one renderer from
/// one thread at a time (any thread); several renderers may render at once (docs/embedding.md).
class TILESPLAT_API Renderer {
 public:
  /// Creates its own headless VkInstance and VkDevice. Throws std::runtime_error when no usable
  /// device exists (the message says why).
  static std::unique_ptr<Renderer> create(const RendererOptions& options = {});
  /// Releases the device memory, pipelines and (for create()) the device and instance. No GPU work
  /// is in flight: every call returns after the work it submitted has finished.
  ~Renderer();
  Renderer(const Renderer&) = delete;             ///< not copyable: it owns a device
  Renderer& operator=(const Renderer&) = delete;  ///< not copyable: it owns a device

  /// Copies the scene into device memory (the caller may destroy or change it afterwards); the
  /// previous scene is released. Throws std::invalid_argument for a scene whose arrays disagree in
  /// size, std::runtime_error for one beyond the device's memory or 2^30 Gaussians.
  void set_scene(const GaussianScene& scene);
  /// Sets a scene file's placed copies (load_scene_instances): merged and copied as set_scene(scene) does.
  /// Copies that move (SceneInstances::moves) are kept, and each frame places them where its shutter
  /// sees them: render(camera, settings) under an open shutter (settings.shutter: close > open, with or
  /// without an end camera) blurs them as render(scene, camera, settings) does, one time sample a call with
  /// settings.accumulate_samples (render_to_image too); a closed shutter sees them at time 0. Take the
  /// scene by std::move to keep no second copy of its files. Throws as set_scene(scene) does.
  void set_scene(SceneInstances scene);

  /// Renders one frame of the scene last set and reads it back; the GPU work has finished when it
  /// returns. Throws std::runtime_error for a camera it cannot render (invalid, see validate(), or
  /// beyond the device's limits) and std::invalid_argument for invalid settings (accuracy modes,
  /// lights, compositor) or an unknown sort strategy. The renderer stays usable after either.
  RenderImage render(const Camera& camera, const RenderSettings& settings = {});

  /// Renders one frame of `scene`, which replaces the scene last set, within settings.memory_budget or,
  /// without one, the device's memory: whole (as set_scene and render(camera, settings)) when its frame
  /// fits; else in parts that follow the frame's depth order (docs/big-scenes.md), each part's Gaussians
  /// uploaded, sorted and composited in turn with every pixel's state carried to the next, into the
  /// image the whole scene renders, bit for bit. The scene is read during the call only. After a frame
  /// in parts the renderer holds no whole scene: render(camera, settings) needs a set_scene first.
  /// Parts take the sorted compositor, 24- or 32-bit depth keys, an exact sort strategy and no
  /// per-pixel re-sorting (std::invalid_argument otherwise, and for a budget too small for one
  /// Gaussian); otherwise it throws as set_scene and render do.
  RenderImage render(const GaussianScene& scene, const Camera& camera, const RenderSettings& settings = {});
  /// The same for a scene file's placed copies (load_scene_instances): in parts, each part's Gaussians are
  /// placed as they are drawn, so the merged scene is never held; whole, it is merged and set. Copies that
  /// move (SceneInstances::moves) under an open shutter (settings.shutter: close > open, with or without
  /// an end camera) blur: the frame is the linear mean (a rolling shutter's bands, the stitch) of the
  /// frames at the shutter's times, each with every copy where it is then (merge_instances(scene, t)) seen
  /// from the camera then. A closed shutter renders the copies where they are at time 0.
  RenderImage render(const SceneInstances& scene, const Camera& camera, const RenderSettings& settings = {});
  /// The same for a binary PLY, an SPZ, a SOG or a .ksplat opened part by part (SceneInParts::open): in parts, each
  /// part's Gaussians are decoded as the part is drawn (from the PLY's file, the SPZ's packed bytes, the
  /// SOG's texels), so the scene is never held whole as floats on the host (only its positions); whole, it is
  /// loaded (SceneInParts::load) and set. The frame is the one the scene load_scene reads renders, bit for
  /// bit.
  RenderImage render(const SceneInParts& scene, const Camera& camera, const RenderSettings& settings = {});
  /// Whether render(scene, camera, settings) renders this frame in parts: with settings.memory_budget,
  /// when the whole frame would need more; without one, when it would not fit the device (a buffer
  /// larger than DeviceInfo::max_allocation_size, or all of them more than 3/4 of
  /// DeviceInfo::device_memory). An application that renders a scene that fits many times sets it once
  /// (set_scene) and renders it with render(camera, settings) instead. Throws as render does for an
  /// unknown sort strategy.
  bool renders_in_parts(const GaussianScene& scene, const Camera& camera,
                        const RenderSettings& settings = {});
  /// The same for a scene file's placed copies, measured as their merged scene.
  bool renders_in_parts(const SceneInstances& scene, const Camera& camera,
                        const RenderSettings& settings = {});
  /// The same for a binary PLY, an SPZ, a SOG or a .ksplat opened part by part.
  bool renders_in_parts(const SceneInParts& scene, const Camera& camera, const RenderSettings& settings = {});
  /// A level-of-detail set from this camera: under RenderSettings::splat_budget the levels select_lod_levels
  /// chooses for it, else level 0 whole; then as render(scene, camera, settings), in parts under a memory
  /// budget. FrameStats::gaussians is what it drew. Throws SceneError for a chunk file it cannot read.
  RenderImage render(const LodSet& set, const Camera& camera, const RenderSettings& settings = {});

  /// The gradient of a loss through the frame render(camera, settings) draws of the scene last set
  /// (docs/gradients.md): given dL/d(each output pixel), dL/d(each Gaussian's parameter), with the screen
  /// gradients densification reads. The forward frame is drawn again first, unless the buffers hold its
  /// tile lists already (with RenderSettings::reuse_lists, after a render() of the same camera and
  /// settings: a training step's forward); the backward passes then walk each pixel's splats back to front
  /// on the device and carry each splat's gradient through its projection. Sums use float atomic adds where
  /// the device has them (VK_EXT_shader_atomic_float), so the last bits may differ from run to run; the
  /// float64 reference_backward is the ground truth they are tested against. last_frame_stats() then lists
  /// the forward's passes (none where its lists were reused: reused_sorted_lists) and "composite_backward"
  /// and "projection_backward". A scene set as placed copies (set_scene(SceneInstances)) is differentiated as
  /// its merged scene. Throws NotDifferentiable for what the backward does not cover (check_differentiable),
  /// std::invalid_argument for gradients of the wrong size or not finite, and otherwise as render() does;
  /// also std::runtime_error for an image the device renders only in bands or a tile list longer than one
  /// composite dispatch takes on this device.
  SceneGradients backward(const Camera& camera, const RenderSettings& settings,
                          const FrameGradients& gradients);

  /// What the last render() (or render_to_image()) did and cost. The reference is valid until the
  /// next frame. A frame render_to_image submitted without waiting (HostFrameSync) is described once
  /// it has been waited for: by wait_for_frame(), or by the next call on the renderer.
  const FrameStats& last_frame_stats() const;

  /// Sorts key/value pairs with a sort strategy outside any frame, the values being the input
  /// positions, and times the sort alone on the GPU (no transfers into or out of the key buffers; a
  /// strategy that sorts on the host counts its own transfers and host time). For the sort
  /// micro-benchmark and tests. Only the low key_bits bits (1 to 64) may be set; throws
  /// std::invalid_argument otherwise.
  struct SortRun {
    std::vector<uint64_t> keys;   ///< ascending
    std::vector<uint32_t> order;  ///< input position of each sorted key; equal keys in input order
    double gpu_ms = 0;            ///< GPU time of the sort, in milliseconds
    uint64_t fallbacks = 0;       ///< see FrameStats::sort_fallbacks
  };
  /// Runs the sort described at SortRun. Throws std::invalid_argument for an unknown strategy or a
  /// key with bits above key_bits.
  SortRun sort_keys(const std::string& strategy, const std::vector<uint64_t>& keys, uint32_t key_bits);

  /// The strategy a frame with RenderSettings::sort = `requested` runs on this renderer's device (when
  /// the renderer waits for the frame): `requested` itself, or for "auto" the strategy it picks here.
  std::string sort_strategy_for(const std::string& requested) const;

  /// The device this renderer runs on.
  DeviceInfo device_info() const;
  /// Validation-layer messages seen so far (0 unless validation is on).
  uint64_t validation_messages() const;

  /// The Vulkan context, buffers and passes (engine/src/renderer.cpp): not part of the API.
  struct Impl;

 private:
  explicit Renderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
  friend struct RendererAccess;  // the engine's one way in (the interop functions of vulkan_interop.h)
};

}  // namespace tilesplat
