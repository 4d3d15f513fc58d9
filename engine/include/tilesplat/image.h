/// @file
/// Rendered images, their files (EXR, PNG preview) and comparisons between them.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/export.h"
#include "tilesplat/render_settings.h"  // PixelRegion

namespace tilesplat {

/// What a render produces, row-major with row 0 at the top.
struct RenderImage {
  int width = 0;                      ///< pixels per row
  int height = 0;                     ///< rows
  std::vector<float> rgba;            ///< 4 per pixel: premultiplied colour over the background, A = 1 - T
  std::vector<float> depth;           ///< 1 per pixel: expected view depth of the blended splats
                                      ///< (sum w z / sum w), 0 where nothing was blended; may be empty
  std::vector<uint32_t> splat_count;  ///< 1 per pixel: splats blended; may be empty
  /// 1 per pixel, in the host's depth convention, when RenderSettings::host asks for it
  /// (HostDepth::write_depth); else empty.
  std::vector<float> host_depth;

  /// width * height.
  size_t pixels() const { return size_t(width) * size_t(height); }
};

/// Finite values that an output could not hold as they were: past the range of the type they were stored
/// as (a scene-linear float of a colour far above 1, a half above 65,504), each stored as the largest finite
/// value of that type with its sign, never as an infinity (docs/colour.md, "Saturation"). Counted per
/// channel, keyed by the channel's name in its output ("R", "G", "B", "A", "Z", ...).
struct SaturatedValues {
  std::map<std::string, uint64_t> channels;  ///< channel name -> values saturated in it (none listed: 0)

  /// The values saturated over every channel.
  TILESPLAT_API uint64_t total() const;
  /// "71241 values (R 23747, G 23747, B 23747)", or "none".
  TILESPLAT_API std::string describe() const;
  /// Adds another output's counts, channel by channel.
  TILESPLAT_API SaturatedValues& operator+=(const SaturatedValues& other);
};

/// The EXR header attribute in which write_exr() records its SaturatedValues when any value saturated:
/// a string, "R 23747 G 23747 B 23747 (float)" (the channels' counts, then the type they saturated in).
/// Absent from a file in which nothing saturated.
inline constexpr const char* kSaturatedAttribute = "tilesplatSaturated";

/// What a render's colours are, and what the files hold (docs/colour.md). A 3DGS model is trained so that its
/// blended colour reproduces the photographs' 8-bit sRGB values: RenderImage::rgba holds those display values
/// (sRGB-encoded, Rec.709 primaries, D65), as every viewer shows them. Linear light is their sRGB decoding.
enum class ColourEncoding {
  /// Scene-linear Rec.709: the sRGB decoding of the colour, alpha kept premultiplied (A * decode(C / A)).
  /// OpenEXR's convention, what compositing tools assume; colorInteropID "lin_rec709_scene".
  kSceneLinear,
  /// The trained display values as rendered (sRGB-encoded, premultiplied as blended): what the float64
  /// reference and the PSNRs use; colorInteropID "srgb_rec709_display".
  kSrgbDisplay,
};
/// The Color Interop Forum's identifier of an encoding: "lin_rec709_scene", "srgb_rec709_display". It is the
/// value of the `colorInteropID` attribute of every EXR that write_exr() writes.
TILESPLAT_API std::string to_string(ColourEncoding encoding);

/// The sRGB transfer function (IEC 61966-2-1), exact and piecewise: display value to linear light.
/// Extended to all reals as an odd function (negatives mirror the positive curve), so that it is
/// invertible everywhere; NaN stays NaN.
TILESPLAT_API double srgb_to_linear(double encoded);
/// The inverse of srgb_to_linear(): linear light to the sRGB-encoded display value.
TILESPLAT_API double linear_to_srgb(double linear);

/// An image's R G B A (premultiplied) converted between encodings, each pixel on its own: to scene-linear
/// A * decode(C / A), back A * encode(L / A); a pixel with A <= 0 (or A not finite) is taken as opaque (its
/// colour converted as it is). `opaque` takes every pixel as opaque, for a file written without alpha or with
/// A = 1. Depth, counts and alpha are untouched. Converting to the same encoding copies. A finite colour
/// whose conversion passes float's range (decoding a display value above about 1e16) saturates to the
/// largest finite float with its sign, counted per channel ("R", "G", "B") in `saturated` when given.
TILESPLAT_API std::vector<float> convert_colours(const std::vector<float>& rgba, ColourEncoding from,
                                                 ColourEncoding to, bool opaque = false,
                                                 SaturatedValues* saturated = nullptr);

/// OpenEXR's compression methods that write_exr() offers.
enum class ExrCompression {
  kZip,   ///< lossless, 16 scanlines per block: the default, good on rendered images
  kPiz,   ///< lossless wavelet: smaller files of noisy images, slower to write
  kDwaa,  ///< lossy (DCT) on the R G B channels, small files for review; A, Z and counts stay lossless
  kNone,  ///< uncompressed: the fastest to write and read
};
/// "zip", "piz", "dwaa", "none".
TILESPLAT_API std::string to_string(ExrCompression compression);

/// How write_exr() stores an image.
struct ExrWriteOptions {
  bool half = false;  ///< store HALF instead of FLOAT channels
  bool alpha = true;  ///< write the A channel (false: R G B only, which readers take as opaque)
  /// Extra string attributes for the header, name -> value (e.g. "commandLine"). A name may not be
  /// empty, one of the attributes the writer sets itself (the required EXR attributes, "compression",
  /// "channels", ...) or start with "tilesplat", which is reserved for the provenance below.
  std::map<std::string, std::string> attributes;
  /// The camera the image was rendered with. Written as OpenEXR's standard `worldToCamera` and
  /// `worldToNDC` (single-precision matrices in OpenEXR's conventions, which read_exr_camera() documents)
  /// and, exactly, as tilesplat's own attributes, from which read_exr_camera() rebuilds it.
  std::optional<Camera> camera;
  ExrCompression compression = ExrCompression::kZip;  ///< how the pixels are compressed
  /// The Z written where no splat was blended (alpha 0), where a RenderImage's depth is 0. Depth
  /// compositing (a Z merge, a Z defocus) takes 0 for a surface at the camera; a far value puts empty
  /// pixels behind everything. tilesplat-render writes kFarDepth.
  float empty_depth = 0;
  /// Write A = 1 everywhere. For an image rendered over a non-black background, whose R G B already
  /// hold the background: the file is then a valid premultiplied image of an opaque frame
  /// (tilesplat-render does so whenever the background is not black).
  bool opaque_alpha = false;
  /// What the R G B channels hold. Scene-linear by default, as OpenEXR's `chromaticities` (written always)
  /// and every compositing tool assume; kSrgbDisplay keeps the rendered values bit for bit. Either way the
  /// string attribute `colorInteropID` names it, and read_exr() converts back.
  ColourEncoding colour = ColourEncoding::kSceneLinear;
  /// The image is the pixels `region` of a display_width x display_height image (a frame of
  /// RenderSettings::region): written as OpenEXR's dataWindow inside that displayWindow, where compositing
  /// tools place it (read_exr() reads the data window). Whole (the default): the image is its own display
  /// window. Otherwise the region must be the image's size and lie within the display window.
  PixelRegion region;
  int display_width = 0;   ///< the whole image's width, with `region`
  int display_height = 0;  ///< the whole image's height, with `region`
};

/// Blender's Z for pixels that show no surface: finite, so that filters and resampling stay finite,
/// and far beyond any scene.
inline constexpr float kFarDepth = 1e10f;

/// Writes `contents` to `path` as write_exr() and write_png() write their files: into a temporary file
/// beside it, synced to the storage, then renamed over it (and the directory synced), so that readers
/// and a crash see the old file or the whole new one, never a part. For the files that accompany
/// renders: the apps write their CSV, JSON, SVG, Markdown and manifests through it. Throws
/// std::runtime_error "cannot write PATH: why" (a missing directory named), leaving no temporary file.
TILESPLAT_API void write_file_atomically(const std::filesystem::path& path, std::string_view contents);

/// Writes channels R G B A (A unless options.alpha is false), Z when depth is present, and "splats"
/// (FLOAT, so that compositing tools read counts as numbers; exact up to 2^24) when counts are present.
/// Every file carries `chromaticities` (Rec.709 primaries, D65 white) and `colorInteropID` (the encoding of
/// R G B, options.colour: scene-linear unless asked otherwise) and records which engine wrote it, as string
/// attributes:
/// "tilesplatVersion" (build_info().version), "tilesplatCommit" (when built from a checkout) and
/// "tilesplatBuildType" (when set); then options.attributes.
/// Atomic: the image goes to a temporary file beside `path` that is renamed over it only once
/// complete, so a failure never leaves a partial file. Throws std::runtime_error naming the file.
/// No finite value becomes an infinity in the file: one past the range of its channel's type (a colour
/// decoded to scene-linear past float's, any value past half's 65,504 with options.half) is stored as that
/// type's largest finite value with its sign. Returns what saturated so, per channel, which the file records
/// too (kSaturatedAttribute) when any did.
TILESPLAT_API SaturatedValues write_exr(const std::filesystem::path& path, const RenderImage& image,
                                        const ExrWriteOptions& options = {});

/// Reads an EXR's R G B A (A = 1 when absent), Z and "splats" (each when present), any pixel type
/// converted, any data window origin. The colours come back as a render holds them (display values): a file
/// whose `colorInteropID` is "lin_rec709_scene" is sRGB-encoded back (convert_colours), one that says
/// "srgb_rec709_display" or has no such attribute (tilesplat's files before it wrote one, and the float64
/// references in shared/scenes) is taken as it is. Throws std::runtime_error naming the file, also for any
/// other colorInteropID.
TILESPLAT_API RenderImage read_exr(const std::filesystem::path& path);
/// The file's R G B A exactly as stored, with the encoding its header names (kSrgbDisplay when it names
/// none).
struct StoredExr {
  RenderImage image;        ///< as read_exr(), but the colours not converted
  ColourEncoding encoding;  ///< what its `colorInteropID` says
};
/// read_exr() without the colour conversion. Throws as read_exr().
TILESPLAT_API StoredExr read_exr_as_stored(const std::filesystem::path& path);

/// The camera write_exr() recorded in an EXR (ExrWriteOptions::camera), rebuilt exactly from its
/// double-precision attributes (`tilesplatRotation` M33d = Camera::rotation, `tilesplatPosition` V3d,
/// `tilesplatFocalLength` V2d = (fx, fy), `tilesplatPrincipalPoint` V2d = (cx, cy), in pixels; the size is
/// the data window's; for a model other than the pinhole `tilesplatCameraModel`, its name, and
/// `tilesplatDistortion`, its 8 coefficients as shortest round-trip decimals); std::nullopt when the file
/// has none. `worldToNDC` is written for the pinhole only (the other models' pixels are no matrix). The
/// standard attributes written beside them follow OpenEXR's conventions, which differ from Camera's:
/// - `worldToCamera` maps world points (row vectors, p * M, as Imath multiplies) into OpenEXR's camera space:
///   x right, **y up**, z forward (left-handed, as RenderMan); tilesplat's camera space is y down, so the
///   second axis is negated.
/// - `worldToNDC` maps world points to NDC with (0, 0) at the top-left and (1, 1) at the bottom-right
///   corner of the image (pixel edges, not centres): x_ndc = px / width, y_ndc = py / height after the
///   division by w; its z is 1 / depth.
/// Throws std::runtime_error naming the file when it cannot be read or its camera attributes are malformed.
TILESPLAT_API std::optional<Camera> read_exr_camera(const std::filesystem::path& path);

/// Every string attribute of an EXR's header, name -> value: the provenance write_exr records and
/// whatever else the file carries. Throws std::runtime_error naming the file.
TILESPLAT_API std::map<std::string, std::string> read_exr_string_attributes(
    const std::filesystem::path& path);

/// How a PNG preview grades a render, in linear light: the colour sRGB-decoded, times 2^exposure_stops, the
/// tone curve per channel, a clamp to [0, 1] and the sRGB encoding. Without exposure and curve the preview is
/// the trained colour itself, round(255 * clamp(C, 0, 1)). The EXR is never graded.
enum class ToneMap {
  kNone,      ///< clamp: values above 1 clip
  kAces,      ///< Narkowicz's fit of the ACES filmic curve: x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)
  kReinhard,  ///< x / (1 + x): never clips, compresses highlights
};
TILESPLAT_API std::string to_string(ToneMap tone_map);  ///< "none", "aces", "reinhard"
/// The tone curve of one linear channel value (exposure already applied); NaN and negatives map to 0.
TILESPLAT_API double apply_tone_map(ToneMap tone_map, double linear);

/// How write_png_preview() grades the colours (see ToneMap); the defaults leave them as trained.
struct PreviewOptions {
  double exposure_stops = 0;          ///< colour times 2^exposure_stops before the curve; -20 to 20
  ToneMap tone_map = ToneMap::kNone;  ///< the tone curve
};

/// The bytes of write_png_preview(): 8-bit sRGB R G B per pixel, row after row from the top (3 x width x
/// height), for showing a frame without a file (a UI texture, a notebook). Throws std::invalid_argument for
/// an rgba of the wrong size or an exposure out of range.
TILESPLAT_API std::vector<std::uint8_t> preview_pixels(const RenderImage& image,
                                                       const PreviewOptions& options = {});

/// An 8-bit sRGB PNG preview of the colour channels (alpha dropped): byte = round(255 * clamp(C, 0, 1)) of
/// the rendered display value C unless options grade it (ToneMap). Atomic like write_exr. Throws
/// std::runtime_error naming the file for an empty image or an exposure out of range.
TILESPLAT_API void write_png_preview(const std::filesystem::path& path, const RenderImage& image,
                                     const PreviewOptions& options = {});

/// How two images differ (compare_images()).
struct ImageDifference {
  double psnr_db = 0;        ///< over RGB, peak 1.0; +inf when identical
  double max_abs = 0;        ///< largest |a - b| over RGB
  double max_abs_alpha = 0;  ///< largest |a - b| over A
  double rmse = 0;           ///< root mean square of a - b over RGB
  int worst_x = 0;           ///< column of the largest RGB difference
  int worst_y = 0;           ///< row of the largest RGB difference
  int worst_channel = 0;     ///< its channel: 0 R, 1 G, 2 B
};
/// Compares the RGB(A) of two images of the same size. Throws std::invalid_argument otherwise.
TILESPLAT_API ImageDifference compare_images(const RenderImage& a, const RenderImage& b);

/// Structural similarity (Wang, Bovik, Sheikh and Simoncelli 2004) of the RGB channels, in the
/// convention of scikit-image (gaussian_weights=True, use_sample_covariance=False, data_range=1) and
/// pytorch-msssim: an 11x11 Gaussian window of sigma 1.5 (weights normalised to sum 1), K1 = 0.01,
/// K2 = 0.03, dynamic range L = 1, population (not sample) variances, the SSIM map computed only where
/// the whole window fits inside the image ("valid"), and the result the mean of that map over its
/// pixels and the three channels. 1 for identical images (exactly), and symmetric in a and b.
/// An image narrower or lower than 11 pixels gets, in that dimension, the window clipped to the image:
/// as many taps as the image has pixels, placed around the image's centre with the same sigma and
/// renormalised, so that the map has one column (or row) there; two empty images score 1.
/// The same sizes and layout as compare_images are required (std::invalid_argument otherwise); a NaN
/// or an infinity in any channel of either image, alpha included, makes the result NaN: it means the
/// renderer is broken, and NaN cannot pass for a score in any comparison.
TILESPLAT_API double ssim(const RenderImage& a, const RenderImage& b);

/// Temporal stability along a camera path. An image metric of each frame alone misses "popping": a
/// splat that appears, vanishes or jumps between two nearby views (a sort order flip, a culling or
/// tile-rect decision) can cost little error in either frame but is what the eye notices in motion.
/// Camera motion itself changes the image too, so the change of the tested sequence (a0 -> a1) is
/// measured against the change the reference has between the same two views (r0 -> r1): per pixel
/// and RGB channel e = |(a1 - a0) - (r1 - r0)|. Popping is change that the reference does not have;
/// change that the reference has too cancels out, whatever its size.
struct TemporalDifference {
  double mean_abs = 0;          ///< mean of e over pixels and RGB channels
  double flicker_fraction = 0;  ///< fraction of pixels whose largest e over RGB exceeds the threshold
};
/// All four images must have one size and the layout of compare_images (std::invalid_argument
/// otherwise, and for a threshold that is negative or not finite). A NaN or an infinity in any channel
/// of any of them makes both fields NaN, as in ssim. Empty images give {0, 0}.
TILESPLAT_API TemporalDifference temporal_excess(const RenderImage& a0, const RenderImage& a1,
                                                 const RenderImage& r0, const RenderImage& r1,
                                                 double threshold = 0.05);

/// The raw frame-to-frame change of one sequence: the mean over pixels and RGB channels of
/// |a1 - a0|. The scale for temporal_excess (how much of the change is excess), and what
/// temporal_excess would report against a perfectly still reference. Errors as temporal_excess.
TILESPLAT_API double frame_change(const RenderImage& a0, const RenderImage& a1);

/// Popping along a path of equal steps, measured without any reference: the second difference
/// e = |(a2 - a1) - (a1 - a0)| of three consecutive frames. Smooth motion (an edge sliding, shading
/// changing with the view) changes the image by about the same amount each step and cancels; a
/// discontinuity (two splats swapping order, a splat culled) happens in one step and does not. This
/// is what a mode that removes popping must lower, even where the reference pops itself (the float64
/// reference blends in the same centre-depth order, so "change the reference does not have" cannot
/// credit a mode that pops less than the reference). It is temporal_excess(a1, a2, a0, a1, threshold).
TILESPLAT_API TemporalDifference popping(const RenderImage& a0, const RenderImage& a1, const RenderImage& a2,
                                         double threshold = 0.05);

/// View consistency under rotation, the popping that per-pixel re-sorting removes (StopThePop,
/// Radl et al. 2024). The scene gives every ray one colour; a renderer that blends in centre-depth
/// order does not: turning the camera in place changes the splats' view depths and so their order,
/// and a region of the image changes where nothing moved. Between two cameras that differ only by a
/// rotation about their common centre every pixel of b sees a ray that a saw as well, so a is
/// resampled (bilinearly) onto b's pixels and compared with b, per pixel and RGB channel: e = |b -
/// warp(a)|, averaged over blocks of block x block pixels before the threshold. The blocks are what
/// makes it fair to a renderer with hard edges: resampling an edge misses by up to a pixel, which a
/// block averages away, whereas a splat changing its colour over its whole footprint stays. Render
/// a and b at block times the resolution the result is meant for. Blocks with a sample outside a are
/// left out. The cameras must share size, intrinsics and position (std::invalid_argument otherwise,
/// also for a block below 1, a negative or non-finite threshold, or images not of the cameras' size);
/// mean_abs is over the blocks kept and RGB, flicker_fraction the fraction of them whose largest
/// channel exceeds the threshold. NaN or infinity in either image gives NaN, as in ssim; no block
/// kept gives {0, 0}.
TILESPLAT_API TemporalDifference rotation_inconsistency(const RenderImage& a, const Camera& camera_a,
                                                        const RenderImage& b, const Camera& camera_b,
                                                        int block, double threshold = 0.01);

/// Popping between two frames of any camera motion, without optical flow: the renderer knows each
/// frame's camera and depth (RenderSettings::depth), so each pixel of b is lifted to the world point at
/// its depth along its ray and projected into a. Where a sees the same point (its depth at the four
/// pixels around the projection within `depth_tolerance`, relative, of the point's depth in a), a is
/// resampled there (bilinearly) and compared with b per pixel and RGB channel, e = |b - warp(a)|,
/// averaged over blocks of block x block pixels before the threshold, as in rotation_inconsistency.
/// What the motion reveals or hides, what leaves a's image, and pixels of b less than half covered
/// (alpha < 0.5, whose depth is a few faint splats') leave their block out. A scene without popping
/// warps onto itself up to resampling; a splat that changes colour between the frames, as a flipped
/// blending order does, stays. Pinhole cameras of the images' size (std::invalid_argument otherwise,
/// also for images without depth, a block below 1, or a threshold or tolerance that is negative or not
/// finite); NaN or infinity in either image gives NaN, as in ssim; no block kept gives {0, 0}.
TILESPLAT_API TemporalDifference depth_warp_difference(const RenderImage& a, const Camera& camera_a,
                                                       const RenderImage& b, const Camera& camera_b,
                                                       int block, double threshold = 0.01,
                                                       double depth_tolerance = 0.05);

}  // namespace tilesplat
