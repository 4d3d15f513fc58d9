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
#include "tilesplat/image.h"
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

/// The approximations of the reference a frame may make, each a named mode. The defaults are the
/// reference behaviour (docs/rendering-math.md). `tilesplat-bench --accuracy` measures what each mode
/// costs in error against the float64 reference and what it saves in time (docs/accuracy.md).
struct AccuracyModes {
  /// Bits of the per-Gaussian depth key the depth sort orders by: 32 = the float bits of the view
  /// depth (reference); 24 = their top 24 bits (one radix digit fewer); 16 = the depth quantized
  /// linearly over the frame's visible depth range (two digits fewer; near-coincident splats tie
  /// and fall back to index order, which pops).
  int depth_key_bits = 32;
  /// How far from its mean a splat reaches, in standard deviations of its major axis.
  enum class Extent {
    kSigma3,        ///< 3 sigma (reference)
    kOpacityAware,  ///< sqrt(2 ln(opacity / alpha_cutoff)) sigma, at most 3.33: where alpha falls below the
                    ///< cut-off
  };
  Extent extent = Extent::kSigma3;  ///< the splat's reach (reference: 3 sigma)
  /// Which tiles of the extent's square get the splat.
  enum class TileTest {
    kEllipse,  ///< only those the alpha >= alpha_cutoff ellipse reaches: the same image as kSquare, fewer
               ///< pairs
    kSquare,   ///< every tile of the square (the reference as written; shows what the ellipse test saves)
  };
  TileTest tile_test = TileTest::kEllipse;  ///< which tiles get the splat (the same image either way)
  int sh_degree_cap = 3;                    ///< 0..3: evaluate SH only to min(scene degree, cap)
  bool fp16_sh = false;                     ///< SH coefficients stored as 16-bit floats on the GPU
  bool fp16_covariance = false;             ///< the 3D covariance precomputed and stored as six 16-bit floats
  float transmittance_cutoff = 1e-4f;       ///< a pixel stops blending when T would fall below this
  float alpha_cutoff = 1.0f / 255.0f;       ///< splats fainter than this at a pixel are skipped
  /// Higher accuracy than the reference: each pixel re-sorts a window of this many splats by the
  /// depth of their density maximum along the pixel's ray (in the spirit of StopThePop), instead of
  /// blending in the order of the splats' centre depths. 0 = off (reference). 2 to 16.
  int resort_window = 0;

  /// Member-wise equality.
  bool operator==(const AccuracyModes&) const = default;
};

/// "reference", or the modes that differ from it joined by '+', e.g. "depth16+sh1+t-cutoff=0.001".
TILESPLAT_API std::string to_string(const AccuracyModes& modes);
/// The inverse of to_string. Tokens: reference, depth24, depth16, opacity-extent, square-tiles,
/// sh0..sh3, fp16-sh, fp16-cov, t-cutoff=X, alpha-cutoff=X (X a number or a fraction like 1/64),
/// resortN or resort=N. Throws std::invalid_argument naming the bad token.
TILESPLAT_API AccuracyModes parse_accuracy_modes(const std::string& text);
/// Throws std::invalid_argument when a value is out of range (naming it).
TILESPLAT_API void validate(const AccuracyModes& modes);

/// How a splat's 2D footprint is filtered (docs/rendering-math.md, section 2). An asset is trained for one
/// mode and renders correctly only in that mode.
enum class Antialiasing {
  kClassic,      ///< the original 3DGS: 0.3 px^2 added to the 2D covariance
  kAntialiased,  ///< gsplat's "antialiased": the same dilation, opacity * sqrt(det before / det after)
  kMip,          ///< Mip-Splatting's 2D filter: 0.1 px^2 and the same opacity compensation
};
TILESPLAT_API std::string to_string(Antialiasing mode);  ///< "classic", "antialiased", "mip"

/// Relighting (a scene effect): splats lit by lights through per-splat normals. Off when `lights`
/// is empty: the projection then never reads a normal and no normal buffer exists.
///
/// The model, per splat, evaluated in the projection after the SH colour (the unlit colour acts as
/// the albedo; Lambert, no shadows, no occlusion between splats):
///   colour_lit = colour * (ambient + sum_l color_l intensity_l max(0, n . w_l) falloff_l)
/// with colour = max(SH + 0.5, 0) and, per light, w_l the unit vector toward it:
///   directional: w = -direction / |direction|, falloff 1;
///   point: w = (position - x) / |position - x|, falloff 1 / |position - x|^2; a splat exactly at the
///   light (|position - x| = 0) gets nothing from it.
/// The normal n: the scene's (GaussianScene::normals, the PLY's nx ny nz) when finite and non-zero, else
/// (files of the original trainer hold zeros) the Gaussian's shortest axis, the rotation's column of its
/// smallest scale (the first on ties). Either way turned toward the camera: a splat shows its lit side.
/// A lit colour beyond the float range culls the splat, as a non-finite SH colour does.
struct Light {
  /// A light at infinity or at a point.
  enum class Type {
    kDirectional,  ///< parallel light travelling along `direction`
    kPoint,        ///< light from `position`, falling off with the squared distance
  };
  Type type = Type::kDirectional;              ///< which of the two
  std::array<float, 3> direction = {0, 1, 0};  ///< directional: where the light travels (any non-zero length)
  std::array<float, 3> position = {0, 0, 0};   ///< point: world position
  std::array<float, 3> color = {1, 1, 1};      ///< RGB factor on the trained colour (docs/colour.md), >= 0
  float intensity = 1;                         ///< >= 0
  /// Member-wise equality.
  bool operator==(const Light&) const = default;
};
/// The lights of a frame and its ambient light (the model is described at Light).
struct Lighting {
  std::vector<Light> lights;                 ///< none: the frame is unlit and relighting costs nothing
  std::array<float, 3> ambient = {0, 0, 0};  ///< light reaching every splat whatever its normal, >= 0
  /// Whether there is any light, which is what turns relighting on.
  bool enabled() const { return !lights.empty(); }
  /// Member-wise equality.
  bool operator==(const Lighting&) const = default;
};
/// Throws std::invalid_argument naming the light and field ("lighting.lights[1].intensity: ...") for
/// a non-finite value, a negative colour, intensity or ambient, or a zero direction. The renderer and
/// the reference call it on every frame with lights.
TILESPLAT_API void validate(const Lighting& lighting);

/// How the sorted splats become pixels.
enum class Compositor {
  kSorted,      ///< front-to-back blending of each tile's depth-sorted list (the reference)
  kStochastic,  ///< sort-free: each splat kept per pixel with probability alpha, nearest kept wins; averaged
};
TILESPLAT_API std::string to_string(Compositor compositor);  ///< "sorted", "stochastic"
/// The stochastic compositor draws, per pixel and frame, each splat of its tile with probability
/// alpha (the sorted composite's alpha and cut-off) from a hash of (pixel, splat index, frame, seed)
/// and shows the nearest drawn splat (by view depth, then index), or the background. Its expectation
/// is the sorted front-to-back blend without the transmittance early-out, so the mean of `frames`
/// frames converges to the sorted image, with an error falling as 1/sqrt(frames). One render() runs
/// them all, with no depth sort, and writes their means: rgb; alpha = the fraction of frames that drew
/// a splat; depth = the mean depth of the drawn splats over those frames; splat_count = the splats
/// each pixel tested (its tile's list length). AccuracyModes::transmittance_cutoff does not apply; the
/// modes that change the depth order (resort_window, depth_key_bits != 32) and frames outside 1..4096
/// throw std::invalid_argument.
struct StochasticSettings {
  uint32_t frames = 16;  ///< frames averaged by one render() call, 1 to 4096
  uint32_t seed = 1;     ///< the hashed thresholds' seed: equal seeds give bit-identical images
  /// Member-wise equality.
  bool operator==(const StochasticSettings&) const = default;
};

/// Splats inside a host's 3D world (docs/embedding.md): the host's depth image in, and a depth the
/// host can test its later geometry against out. Only the sorted compositor without per-pixel
/// re-sorting honours it (other compositors throw std::invalid_argument).
struct HostDepth {
  /// How the host's depth values relate to view depth (DepthConvention::from_projection of the
  /// projection it drew with).
  DepthConvention convention;
  /// The host's depth image: width x height window depths, row-major, row 0 the top row of the image
  /// (as RenderImage), of the surface the host drew at each pixel, or its cleared far value. A splat
  /// blends into a pixel only when its view depth (as a float) is less than the surface's: the surface
  /// is opaque. Empty: no depth in, every splat blends. Not owned: it must stay valid during the
  /// render. A NaN, or a size other than width x height, throws std::invalid_argument.
  std::span<const float> depth;
  /// Fill RenderImage::host_depth: per pixel, in the host's convention, the depth of the splat at which
  /// the accumulated alpha (1 - T) first reaches `alpha_threshold` (0.5: the median depth of the 3DGS
  /// papers), or, where it never does, the host's own depth (its far value without a depth image).
  bool write_depth = false;
  float alpha_threshold = 0.5f;  ///< in (0, 1]
};

/// Everything that changes how one frame is rendered.
struct RenderSettings {
  std::array<float, 3> background = {0, 0, 0};         ///< RGB behind the splats, in the splats' display values (docs/colour.md): C + T * background
  std::string sort = "radix";                          ///< the key sort strategy (see sort_strategies())
  bool depth = true;                                   ///< produce the expected-depth channel
  bool splat_count = true;                             ///< produce the per-pixel blended-splat count
  AccuracyModes accuracy;                              ///< approximations (default: none, the reference)
  Antialiasing antialiasing = Antialiasing::kClassic;  ///< the footprint filter the asset was trained with
  Lighting lighting;                                   ///< relighting; off (no lights) by default
  Compositor compositor = Compositor::kSorted;         ///< how the splats become pixels
  StochasticSettings stochastic;                       ///< used by Compositor::kStochastic
  /// Run only the composite when the frame's tile lists would equal those the previous frame left in
  /// the buffers (FrameStats::reused_sorted_lists). false: always build them, as a benchmark timing
  /// whole frames of one camera needs.
  bool reuse_lists = true;
  /// Depth-test the splats against a host's depth image, and give the host a depth back. Unset (the
  /// default): neither, and the composite is the one without them (a specialization constant).
  std::optional<HostDepth> host;
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
};

struct ExternalVulkanDevice;  // tilesplat/vulkan_interop.h
struct ExternalImage;
struct ExternalDepthImage;
struct HostFrameSync;
struct HostCommandBuffer;

/// Names of the available sort strategies, default first.
TILESPLAT_API std::vector<std::string> sort_strategies();
/// Whether a strategy gives the exact order that all exact strategies share (and so bit-identical
/// images); false for one that sorts by approximated keys (cpu-radix16: 16-bit quantized depths).
/// Throws std::invalid_argument for an unknown name.
TILESPLAT_API bool sort_strategy_is_exact(const std::string& name);

/// Lists the Vulkan devices this machine has, in the order RendererOptions::device indexes them.
TILESPLAT_API std::vector<std::string> list_devices();
/// The devices' UUIDs (VkPhysicalDeviceIDProperties::deviceUUID) as 8-4-4-4-12 lower-case hex, in the
/// order of list_devices(). RendererOptions::device accepts them.
TILESPLAT_API std::vector<std::string> list_device_uuids();

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

  /// Renders one frame of the scene last set and reads it back; the GPU work has finished when it
  /// returns. Throws std::runtime_error for a camera it cannot render (invalid, see validate(), or
  /// beyond the device's limits) and std::invalid_argument for invalid settings (accuracy modes,
  /// lights, compositor) or an unknown sort strategy. The renderer stays usable after either.
  RenderImage render(const Camera& camera, const RenderSettings& settings = {});

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

  /// The device this renderer runs on.
  DeviceInfo device_info() const;
  /// Validation-layer messages seen so far (0 unless validation is on).
  uint64_t validation_messages() const;

  /// The Vulkan context, buffers and passes (engine/src/renderer.cpp): not part of the API.
  struct Impl;

 private:
  explicit Renderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
  friend std::unique_ptr<Renderer> create_renderer(const ExternalVulkanDevice&, const RendererOptions&);
  friend void render_to_image(Renderer&, const Camera&, const RenderSettings&, const ExternalImage&);
  friend void render_to_image(Renderer&, const Camera&, const RenderSettings&, const ExternalImage&,
                              const ExternalDepthImage&);
  friend void render_to_image(Renderer&, const Camera&, const RenderSettings&, const ExternalImage&,
                              const ExternalDepthImage*, const HostFrameSync&);
  friend void render_to_image(Renderer&, const Camera&, const RenderSettings&, const ExternalImage&,
                              const ExternalDepthImage*, const HostCommandBuffer&);
  friend void wait_for_frame(Renderer&);
};

}  // namespace tilesplat
