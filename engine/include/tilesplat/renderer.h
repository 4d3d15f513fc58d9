// The GPU renderer: a Vulkan compute pipeline that turns a GaussianScene and a Camera into an image.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/scene.h"

namespace tilesplat {

struct RendererOptions {
  // Which Vulkan device: "" = the environment variable TILESPLAT_DEVICE if set, else the first
  // discrete GPU, else the first device. Otherwise a device index ("1") or a case-insensitive
  // substring of the device name ("llvmpipe").
  std::string device;
  // Enables VK_LAYER_KHRONOS_validation. Also enabled by TILESPLAT_VALIDATION=1. Messages go to
  // the callback below (or stderr) and are counted in validation_messages().
  bool validation = false;
  // Record GPU timestamps around every pass (cheap; on by default).
  bool timestamps = true;
};

// The approximations of the reference a frame may make, each a named mode. The defaults are the
// reference behaviour (DESIGN-NOTES section 1). `tilesplat-bench --accuracy` measures what each mode
// costs in error against the float64 reference and what it saves in time (docs/accuracy.md).
struct AccuracyModes {
  // Bits of the per-Gaussian depth key the depth sort orders by: 32 = the float bits of the view
  // depth (reference); 24 = their top 24 bits (one radix digit fewer); 16 = the depth quantized
  // linearly over the frame's visible depth range (two digits fewer; near-coincident splats tie
  // and fall back to index order, which pops).
  int depth_key_bits = 32;
  // How far from its mean a splat reaches, in standard deviations of its major axis.
  enum class Extent {
    kSigma3,        // 3 sigma (reference)
    kOpacityAware,  // sqrt(2 ln(opacity / alpha_cutoff)) sigma, at most 3.33: where alpha falls below the cut-off
  };
  Extent extent = Extent::kSigma3;
  // Which tiles of the extent's square get the splat.
  enum class TileTest {
    kEllipse,  // only those the alpha >= alpha_cutoff ellipse reaches: the same image as kSquare, fewer pairs
    kSquare,   // every tile of the square (the reference as written; shows what the ellipse test saves)
  };
  TileTest tile_test = TileTest::kEllipse;
  int sh_degree_cap = 3;          // 0..3: evaluate SH only to min(scene degree, cap)
  bool fp16_sh = false;           // SH coefficients stored as 16-bit floats on the GPU
  bool fp16_covariance = false;   // the 3D covariance precomputed and stored as six 16-bit floats
  float transmittance_cutoff = 1e-4f;    // a pixel stops blending when T would fall below this
  float alpha_cutoff = 1.0f / 255.0f;    // splats fainter than this at a pixel are skipped
  // Higher accuracy than the reference: each pixel re-sorts a window of this many splats by the
  // depth of their density maximum along the pixel's ray (in the spirit of StopThePop), instead of
  // blending in the order of the splats' centre depths. 0 = off (reference). 2 to 16.
  int resort_window = 0;

  bool operator==(const AccuracyModes&) const = default;
};

// "reference", or the modes that differ from it joined by '+', e.g. "depth16+sh1+t-cutoff=0.001".
std::string to_string(const AccuracyModes& modes);
// The inverse of to_string. Tokens: reference, depth24, depth16, opacity-extent, square-tiles,
// sh0..sh3, fp16-sh, fp16-cov, t-cutoff=X, alpha-cutoff=X (X a number or a fraction like 1/64),
// resortN or resort=N. Throws std::invalid_argument naming the bad token.
AccuracyModes parse_accuracy_modes(const std::string& text);
// Throws std::invalid_argument when a value is out of range (naming it).
void validate(const AccuracyModes& modes);

// How a splat's 2D footprint is filtered (DESIGN-NOTES section 1). An asset is trained for one mode
// and renders correctly only in that mode.
enum class Antialiasing {
  kClassic,      // the original 3DGS: 0.3 px^2 added to the 2D covariance
  kAntialiased,  // gsplat's "antialiased": the same dilation, opacity * sqrt(det before / det after)
  kMip,          // Mip-Splatting's 2D filter: 0.1 px^2 and the same opacity compensation
};
std::string to_string(Antialiasing mode);  // "classic", "antialiased", "mip"

// Everything that changes how one frame is rendered.
struct RenderSettings {
  std::array<float, 3> background = {0, 0, 0};
  std::string sort = "radix";  // the key sort strategy (see sort_strategies())
  bool depth = true;           // produce the expected-depth channel
  bool splat_count = true;     // produce the per-pixel blended-splat count
  AccuracyModes accuracy;      // approximations (default: none, the reference)
  Antialiasing antialiasing = Antialiasing::kClassic;
};

struct PassTiming {
  std::string name;
  double gpu_ms = 0;
};

struct FrameStats {
  std::vector<PassTiming> passes;  // GPU time of each pass, in frame order
  double gpu_ms = 0;               // first pass start to last pass end
  double cpu_ms = 0;               // wall time of render(), readback included
  uint64_t gaussians = 0;
  uint64_t visible = 0;            // Gaussians touching at least one tile
  uint64_t intersections = 0;      // (Gaussian, tile) pairs sorted
  uint32_t sort_bits = 0;          // key bits sorted: 32 depth bits (per Gaussian) + the tile bits (per pair)
  int retries = 0;                 // re-renders after growing the intersection buffers
  int submissions = 0;             // command buffers the frame took: 1, more for a strategy that sorts on the host
  uint64_t sort_fallbacks = 0;     // onesweep look-backs that gave up waiting and counted keys themselves
  uint64_t device_bytes = 0;       // device memory held by the renderer's buffers
};

struct DeviceInfo {
  std::string name;
  std::string driver;
  uint32_t subgroup_size = 0;
  uint64_t max_storage_buffer_range = 0;
  uint32_t max_shared_memory = 0;
  double timestamp_period_ns = 0;
  uint32_t max_image_dimension = 0;
};

struct ExternalVulkanDevice;  // tilesplat/vulkan_interop.h
struct ExternalImage;

// Names of the available sort strategies, default first.
std::vector<std::string> sort_strategies();
// Whether a strategy gives the exact order that all exact strategies share (and so bit-identical
// images); false for one that sorts by approximated keys (cpu-radix16: 16-bit quantized depths).
// Throws std::invalid_argument for an unknown name.
bool sort_strategy_is_exact(const std::string& name);

// Lists the Vulkan devices this machine has, in the order RendererOptions::device indexes them.
std::vector<std::string> list_devices();

class Renderer {
 public:
  // Creates its own headless VkInstance and VkDevice. Throws std::runtime_error when no usable
  // device exists (the message says why).
  static std::unique_ptr<Renderer> create(const RendererOptions& options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Uploads the scene; the previous scene is released.
  void set_scene(const GaussianScene& scene);

  // Renders one frame and reads it back. Throws std::runtime_error (for example when the
  // camera's size exceeds the device's limits).
  RenderImage render(const Camera& camera, const RenderSettings& settings = {});

  const FrameStats& last_frame_stats() const;

  // Sorts key/value pairs with a sort strategy outside any frame, the values being the input
  // positions, and times the sort alone on the GPU (no transfers into or out of the key buffers; a
  // strategy that sorts on the host counts its own transfers and host time). For the sort
  // micro-benchmark and tests. Only the low key_bits bits (1 to 64) may be set; throws
  // std::invalid_argument otherwise.
  struct SortRun {
    std::vector<uint64_t> keys;   // ascending
    std::vector<uint32_t> order;  // input position of each sorted key; equal keys in input order
    double gpu_ms = 0;
    uint64_t fallbacks = 0;  // see FrameStats::sort_fallbacks
  };
  SortRun sort_keys(const std::string& strategy, const std::vector<uint64_t>& keys, uint32_t key_bits);

  DeviceInfo device_info() const;
  // Validation-layer messages seen so far (0 unless validation is on).
  uint64_t validation_messages() const;

  struct Impl;  // the Vulkan context, buffers and passes (engine/src/renderer.cpp)

 private:
  explicit Renderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
  friend std::unique_ptr<Renderer> create_renderer(const ExternalVulkanDevice&, const RendererOptions&);
  friend void render_to_image(Renderer&, const Camera&, const RenderSettings&, const ExternalImage&);
};

}  // namespace tilesplat
