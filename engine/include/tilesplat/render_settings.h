/// @file
/// What describes one frame: RenderSettings and the settings it is made of (accuracy modes, antialiasing,
/// relighting, the compositor, a host's depth). A plain header without the renderer, so that what only
/// describes frames (the float64 reference, scene files, effects) does not depend on the GPU renderer.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/export.h"
#include "tilesplat/lens.h"
#include "tilesplat/shutter.h"

namespace tilesplat {

/// The approximations of the reference a frame may make, each a named mode. The defaults are the
/// reference behaviour (docs/rendering-math.md). `tilesplat-bench --accuracy` measures what each mode
/// costs in error against the float64 reference and what it saves in time (docs/accuracy.md).
struct AccuracyModes {
  /// Bits of the per-Gaussian depth key the depth sort orders by: 32 = the float bits of the view
  /// depth (reference); 24 = their top 24 bits (one radix digit fewer); 16 = the depth quantized
  /// linearly over the frame's visible depth range (two digits fewer; near-coincident splats tie
  /// and fall back to index order, which pops).
  int depth_key_bits = 32;
  /// What the depth sort orders the splats by.
  enum class SortDepth {
    kView,      ///< the centre's view depth z (reference; the fisheye and panorama cameras: its distance)
    kDistance,  ///< the centre's distance from the camera (radial, as Spark sorts): a camera turning in place
                ///< keeps every distance, so the blending order cannot pop under a turn
  };
  /// The depth the splats sort by (reference: view depth). kDistance changes the pinhole and OpenCV cameras'
  /// order only (the fisheye and panorama cameras already sort by distance); the orthographic camera, at
  /// no finite distance, refuses it, and so does the stochastic compositor, which sorts nothing. Depth
  /// images still average view depth.
  SortDepth sort_depth = SortDepth::kView;
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
  /// The raster compositor (Compositor::kRaster) blends the colour and 1 - T in a 16-bit float (RGBA16F)
  /// attachment instead of a 32-bit one: half the attachment's bytes, at half precision's rounding per
  /// blend. The other compositors blend in float32 registers and refuse it.
  bool fp16_blend = false;

  /// Member-wise equality.
  bool operator==(const AccuracyModes&) const = default;
};

/// "reference", or the modes that differ from it joined by '+', e.g. "depth16+sh1+t-cutoff=0.001".
TILESPLAT_API std::string to_string(const AccuracyModes& modes);
/// The inverse of to_string. Tokens: reference, depth24, depth16, radial, opacity-extent, square-tiles,
/// sh0..sh3, fp16-sh, fp16-cov, t-cutoff=X, alpha-cutoff=X (X a number or a fraction like 1/64),
/// resortN or resort=N, fp16-blend. Throws std::invalid_argument naming the bad token.
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
  /// Sorted billboards through the graphics pipeline: the Gaussians in depth order, each drawn as a
  /// quad around its alpha >= alpha_cutoff ellipse and blended front to back by the hardware, with no
  /// tiles and no transmittance early-out (render_reference's raster rule: every splat whose alpha at
  /// a pixel passes the cut-off blends there). Needs a queue that draws and RGBA32F blending.
  kRaster,
};
TILESPLAT_API std::string to_string(Compositor compositor);  ///< "sorted", "stochastic", "raster"
/// The compositor of a name to_string gives; throws std::invalid_argument listing the names.
TILESPLAT_API Compositor parse_compositor(const std::string& name);
/// Whether `compositor` draws frames in the accuracy `modes`: the sorted compositor every mode, the raster
/// one all but per-pixel re-sorting (it draws no tile lists), the stochastic one neither re-sorting nor
/// depth keys below 32 bits (it sorts nothing). Renderer::render throws std::invalid_argument, saying
/// why, for the others.
TILESPLAT_API bool compositor_draws(Compositor compositor, const AccuracyModes& modes);
/// Whether `camera` draws frames in the accuracy `modes`: per-pixel re-sorting (AccuracyModes::resort_window)
/// follows the pinhole's rays, so it needs a pinhole camera (an OpenCV camera without distortion is one);
/// radial sorting (AccuracyModes::SortDepth::kDistance) measures from the camera's centre, which an
/// orthographic camera does not have. Renderer::render and render_reference throw std::invalid_argument,
/// saying why, for the others.
TILESPLAT_API bool camera_draws(const Camera& camera, const AccuracyModes& modes);
/// How the stochastic compositor draws each splat's threshold u at a pixel (it keeps the splat when
/// u < alpha). Both are uniform on [0, 1) for each splat, pixel and frame, independent between splats,
/// so both converge to the sorted image; they differ in how the frames of one render() spread.
enum class StochasticSampler {
  /// A hash of (pixel, splat, frame, seed): independent frames, error falling as 1/sqrt(frames).
  kHash,
  /// Stratified over the frames (a Latin hypercube per pixel): over the N frames of one render(), each
  /// splat's thresholds at a pixel fall in distinct strata of [0, 1), one per frame: the N strata
  /// [k/N, (k+1)/N) when N is a power of two, else N of the 2^b of the next power of two. The order is
  /// permuted per (pixel, splat, seed) and each threshold jittered within its stratum. Each splat's own
  /// coverage is then exact to about 1/N; what is left is the interplay between splats.
  /// docs/compositors.md has its curve.
  kStratified,
  /// The effects' progressive sequence (tilesplat/effect_samples.h) in one dimension: frame k's threshold
  /// is the radical inverse of k's nested shuffle, Owen-scrambled, both keyed per (pixel, splat, seed)
  /// by the same hash (so that two splats' thresholds do not run in step). Any 2^m consecutive frames
  /// take each stratum [j/2^m, (j+1)/2^m) once, whatever the count, so that it converges like
  /// kStratified at powers of two and, unlike it, continues across calls (StochasticSettings::accumulate).
  kSobol,
};
/// "hash", "stratified", "sobol".
TILESPLAT_API std::string to_string(StochasticSampler sampler);
/// The inverse of to_string; throws std::invalid_argument naming the text and the choices.
TILESPLAT_API StochasticSampler parse_stochastic_sampler(const std::string& name);

/// The stochastic compositor draws, per pixel and frame, each splat of its tile with probability
/// alpha (the sorted composite's alpha and cut-off), by a threshold of (pixel, splat index, frame,
/// seed) that StochasticSampler draws, and shows the nearest drawn splat (by view depth, then index),
/// or the background. Its expectation is the sorted front-to-back blend without the transmittance
/// early-out, so the mean of `frames` frames converges to the sorted image, with an error falling as
/// 1/sqrt(frames) with the hash (faster with the stratified sampler). One render() runs
/// them all, with no depth sort, and writes their means: rgb; alpha = the fraction of frames that drew
/// a splat; depth = the mean depth of the drawn splats over those frames; splat_count = the splats
/// each pixel tested (its tile's list length). AccuracyModes::transmittance_cutoff does not apply; the
/// modes that change the depth order (resort_window, depth_key_bits != 32) and frames outside 1..4096
/// throw std::invalid_argument.
struct StochasticSettings {
  uint32_t frames = 16;  ///< frames averaged by one render() call, 1 to 4096
  uint32_t seed = 1;     ///< the hashed thresholds' seed: equal seeds give bit-identical images
  StochasticSampler sampler = StochasticSampler::kHash;  ///< how the thresholds are drawn
  /// Add this render()'s frames to the mean of the previous ones, so that repeated calls on a view at
  /// rest converge (a viewer's progressive refinement): it continues while each call reuses the
  /// previous call's lists (same scene, camera and list settings, RenderSettings::reuse_lists) with the
  /// same background, outputs, seed and sampler, and starts anew otherwise.
  /// FrameStats::accumulated_frames counts the frames in the mean; with the hash, N calls of 1 frame
  /// give the image of one call of N frames, to the bit. Not with StochasticSampler::kStratified (its
  /// strata need the count in advance: std::invalid_argument).
  bool accumulate = false;
  /// Member-wise equality.
  bool operator==(const StochasticSettings&) const = default;
};

/// Splats inside a host's 3D world (docs/embedding.md): the host's depth image in, and a depth the
/// host can test its later geometry against out. The sorted and the raster compositors honour it, without
/// per-pixel re-sorting (the stochastic compositor and resortN throw std::invalid_argument); the raster
/// compositor's depth out needs VK_EXT_rasterization_order_attachment_access (else std::runtime_error).
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
  /// Equal when they view the same depth memory (not equal values) with equal other fields.
  bool operator==(const HostDepth& other) const {
    return convention == other.convention && depth.data() == other.depth.data() &&
           depth.size() == other.depth.size() && write_depth == other.write_depth &&
           alpha_threshold == other.alpha_threshold;
  }
};

/// The view depth at or below which a Gaussian is culled (RenderSettings::near_plane): the 3DGS
/// trainer's and its rasterizer's.
inline constexpr double kDefaultNearPlane = 0.2;
/// The default RenderSettings::max_alpha: the cap the 3DGS trainer and its rasterizer put on a splat's alpha.
inline constexpr double kDefaultMaxAlpha = 0.99;

/// A rectangle of a camera's pixels: columns [x, x + width) and rows [y, y + height). The default,
/// 0 x 0, is the whole image.
struct PixelRegion {
  int x = 0;       ///< the first column
  int y = 0;       ///< the first row
  int width = 0;   ///< columns; 0 (with height 0): the whole image
  int height = 0;  ///< rows; 0 (with width 0): the whole image
  /// The default, 0 x 0: the whole image.
  bool whole() const { return width == 0 && height == 0; }
  /// Every field equal.
  bool operator==(const PixelRegion&) const = default;
};
/// Throws std::invalid_argument ("RenderSettings::region: ...", naming the values) unless the region is
/// whole or has a positive size and lies within an image of image_width x image_height pixels.
TILESPLAT_API void validate(const PixelRegion& region, int image_width, int image_height);
/// "x,y,widthxheight", e.g. "0,540,1920x64"; "whole" for the whole image.
TILESPLAT_API std::string to_string(const PixelRegion& region);
/// The inverse of to_string, also "x,y,width,height". Throws std::invalid_argument naming the text.
TILESPLAT_API PixelRegion parse_pixel_region(const std::string& text);

/// Everything that changes how one frame is rendered.
struct RenderSettings {
  std::array<float, 3> background = {
      0, 0,
      0};  ///< RGB behind the splats, in the splats' display values (docs/colour.md): C + T * background
  /// The key sort strategy: a name of sort_strategies(), or "auto" (the default), the fastest exact
  /// strategy for the renderer's device by the rule of docs/benchmarks.md ("The default sort"): cpu-radix
  /// on a CPU driver such as lavapipe (radix for frames the renderer does not wait for: render_to_image
  /// with HostFrameSync or HostCommandBuffer), onesweep on NVIDIA GPUs, radix on other GPUs. The images
  /// are the same to the bit whatever it picks; FrameStats::sort_strategy says what ran.
  std::string sort = "auto";
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
  /// A Gaussian whose mean's view depth (z, world units) is at or below this is culled, on the GPU and
  /// in the reference alike: kDefaultNearPlane (0.2) as the 3DGS trainer renders, or what a caller's
  /// camera uses (gsplat's rasterization() defaults to 0.01). Finite and positive.
  double near_plane = kDefaultNearPlane;
  /// The most one splat may cover of a pixel: alpha = min(max_alpha, opacity * G). kDefaultMaxAlpha (0.99)
  /// as the 3DGS trainer renders; 0.999 as gsplat's rasterizer does (tilesplat.rasterization() sets it).
  /// An asset renders as it was trained with the cap its trainer used. Above accuracy.alpha_cutoff and
  /// below 1 (at 1 a splat would end its pixels before blending, the stop being exclusive).
  double max_alpha = kDefaultMaxAlpha;
  /// Depth of field: a thin lens (tilesplat/lens.h). Its default, an aperture of 0, is the pinhole camera:
  /// nothing is averaged and the frame is the one it always was. Renderer::render and render_reference
  /// take it; render_to_image and the frames submitted without waiting refuse it, as does host depth.
  ThinLens lens;
  /// Motion blur: a shutter open over camera motion (tilesplat/shutter.h). Off by default (closed, no end
  /// camera). Taken and refused where the lens is; with both, every time sample is a lens frame.
  Shutter shutter;
  /// Depth of field and motion blur a sample at a time (docs/effects.md, "Samples that add up"): each call
  /// renders one more sample of the lens and the shutter, both with SamplePattern::kSobol (else
  /// std::invalid_argument), and returns the mean of it and the samples of the calls before it, as long as
  /// they had the same camera, scene (set_scene) and settings, their `samples` counts aside; anything else
  /// starts anew. Sample k is the camera at shutter_time(..., k, ...) seen from lens_sample(..., k, ...),
  /// both from point k of effect_sample_point (with both effects, one joint sample, not a time's lens
  /// frames), so that N calls give the mean of those N pinhole frames in linear light (within float
  /// rounding: the sums are kept on the device in float32). FrameStats::accumulated_samples counts them.
  /// Renderer::render(camera, settings) and render_to_image (every form) take it, so that a window's still
  /// view converges a frame at a time; the scene and LOD forms of render() refuse it. Without an enabled
  /// lens or shutter it does nothing.
  bool accumulate_samples = false;
  /// Device memory, in bytes, that Renderer::render(scene, camera, settings) may hold for a frame: a
  /// scene whose frame would need more is rendered in parts that follow the depth order, each within
  /// the budget, into the same image bit for bit (docs/big-scenes.md). 0 (the default): the device's,
  /// the scene rendered whole where its frame fits the device (each buffer within its largest allocation,
  /// all within 3/4 of its memory: DeviceInfo), else in parts under that share. Every buffer of a part
  /// stays within the largest allocation under any budget. render(camera, settings) on a scene set_scene
  /// uploaded ignores it.
  uint64_t memory_budget = 0;
  /// For Renderer::render(const LodSet&, ...): the most Gaussians the frame draws, each chunk of the set at
  /// the level the camera calls for (select_lod_levels, docs/big-scenes.md). 0 (the default): level 0,
  /// every chunk. Other scenes ignore it.
  uint64_t splat_budget = 0;
  /// Render only these pixels of the camera's image (docs/big-scenes.md, "Image regions"): the image
  /// returned is region.width x region.height, each pixel bit for bit the whole frame's. The tiles keep
  /// the camera's grid and only those the region meets are binned, sorted and composited, so a band of
  /// rows costs the projection of every Gaussian and its share of the rest. Renderer::render and
  /// render_reference take it with every compositor, a lens and a shutter (each sample renders the
  /// region); render_to_image, the frames submitted without waiting and a host's depth refuse it. Where a
  /// frame's depth keys are quantized over its visible depth range (depth16, the approximate sort
  /// strategies), a region's range is its own. The whole image (the default) is what it always was.
  PixelRegion region;
  /// Member-wise equality (HostDepth by the memory it views).
  bool operator==(const RenderSettings&) const = default;
};

}  // namespace tilesplat
