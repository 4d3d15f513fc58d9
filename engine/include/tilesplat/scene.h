/// @file
/// A 3D Gaussian Splatting scene as the trainer wrote it: raw (pre-activation) parameters.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "tilesplat/bounds.h"
#include "tilesplat/export.h"
#include "tilesplat/scene_error.h"

namespace tilesplat {

/// Structure-of-arrays storage of N Gaussians. Values are kept as the trainer stores them
/// (log scales, opacity logits) so that every renderer applies the activations itself, in its
/// own precision: the float64 reference and the GPU see the same inputs.
struct GaussianScene {
  int sh_degree = 0;                  ///< 0..3
  std::vector<float> positions;       ///< 3N, world space x y z
  std::vector<float> log_scales;      ///< 3N, scale = exp(log_scale)
  std::vector<float> rotations;       ///< 4N, unit quaternion w x y z (normalized on load, zero -> identity)
  std::vector<float> opacity_logits;  ///< N, opacity = sigmoid(logit)
  /// N * K * 3 with K = (sh_degree + 1)^2: coefficient-major, RGB innermost, i.e.
  /// sh[(i * K + k) * 3 + c]. k = 0 is the DC term (f_dc); the loader reorders the PLY's
  /// channel-major f_rest into this layout.
  std::vector<float> sh;
  std::vector<float> normals;  ///< 3N when the file has nx ny nz, else empty

  size_t size() const { return opacity_logits.size(); }                      ///< N, the number of Gaussians
  bool empty() const { return opacity_logits.empty(); }                      ///< whether N is 0
  int sh_coefficients() const { return (sh_degree + 1) * (sh_degree + 1); }  ///< K per colour channel
  bool has_normals() const { return !normals.empty(); }                      ///< whether `normals` is filled
};

/// How the readers treat what they read.
struct LoadOptions {
  /// Strict: any non-finite value is an error naming the first bad Gaussian and property.
  /// Default: Gaussians with non-finite values are dropped and reported.
  bool strict = false;
};

/// The Gaussians a read dropped because of one property's non-finite values.
struct DroppedProperty {
  std::string property;    ///< e.g. "scale_1"
  size_t count = 0;        ///< Gaussians dropped whose first non-finite value was this property
  size_t first_index = 0;  ///< index in the file of the first Gaussian dropped for it
};

/// What a reader found and did, for a caller that wants to tell the user (tilesplat-info prints it).
struct TILESPLAT_API LoadReport {
  /// The format as the reader found it from the content: "ply binary_little_endian", "ply ascii",
  /// "compressed ply", "splat", "spz", "sog", "sog (unbundled)", "glb", "gltf", "ksplat level 0 (float32)" (and
  /// levels 1 and 2, with their layouts), "glb (SPZ v3 in KHR_gaussian_splatting_compression_spz_2)", "rad (1
  /// chunk; LOD tree of N splats, its M leaves read; center f32_lebytes, ...)" (its chunks and encodings).
  std::string format;
  std::string version;           ///< the format's version where it has one ("1.0", "3", "2", ...), else empty
  size_t gaussians_in_file = 0;  ///< Gaussians the file holds, dropped ones included
  size_t dropped = 0;            ///< Gaussians removed for non-finite values
  std::vector<DroppedProperty> dropped_by_property;  ///< why they were dropped, per property
  std::vector<std::string> ignored_properties;       ///< extra properties the file carries
  std::string summary() const;  ///< one human-readable line, empty when nothing was dropped
};

/// Reads a 3DGS PLY (binary little/big endian or ASCII), or a PlayCanvas compressed PLY (told apart
/// by its header's elements). Throws SceneError.
TILESPLAT_API GaussianScene load_ply(const std::filesystem::path& path, const LoadOptions& options = {},
                                     LoadReport* report = nullptr);

/// The same reader on a PLY already in memory; `name` stands for the file in error messages.
TILESPLAT_API GaussianScene parse_ply(std::span<const std::byte> data, std::string_view name,
                                      const LoadOptions& options = {}, LoadReport* report = nullptr);

/// Reads a scene file of any supported format, chosen by its content (magic bytes, zip or JSON
/// structure), with the extension only deciding for .splat, the one format without a header:
///   .ply (binary or ASCII), PlayCanvas compressed .ply, antimatter15 .splat, Niantic .spz
///   (versions 2, 3 and 4), PlayCanvas SOG version 2 (and 1) as a .sog zip or an unbundled
///   meta.json beside its WebP images, glTF 2.0 (.glb or .gltf) with KHR_gaussian_splatting,
///   GaussianSplats3D .ksplat (compression levels 0, 1 and 2; told by its header, which has no magic).
/// Every reader yields the same GaussianScene (trainer's activations and axes; see docs/formats.md)
/// and shares one post-processing step: non-finite values dropped (or rejected, strict), quaternions
/// normalized, a quaternion of zero or denormal components the identity. Throws SceneError naming
/// the file and the problem.
TILESPLAT_API GaussianScene load_scene(const std::filesystem::path& path, const LoadOptions& options = {},
                                       LoadReport* report = nullptr);

/// The same readers on a file already in memory; `name` stands for the file in error messages and
/// decides, by its extension, only whether headerless bytes are read as .splat. Formats that refer
/// to other files (an unbundled SOG meta.json, a .gltf with external buffers) need load_scene.
TILESPLAT_API GaussianScene parse_scene(std::span<const std::byte> data, std::string_view name,
                                        const LoadOptions& options = {}, LoadReport* report = nullptr);

/// Writes the scene as the 3DGS trainer's binary little-endian PLY, which every 3DGS viewer reads: x y z,
/// nx ny nz (when the scene has normals), f_dc_0..2, f_rest_* (channel-major, as the trainer writes them),
/// opacity (the logit), scale_0..2 (log scales), rot_0..3 (w x y z), all float. Each value is written as it
/// is, so load_ply gives every one back to the bit, but for the rotations, which it normalizes again as every
/// reader does (which moves some of an already normalized scene's by a float step).
/// Written atomically: a reader never sees part of the file. Throws std::invalid_argument naming the file
/// for arrays of inconsistent sizes, std::runtime_error naming it when it cannot be written.
TILESPLAT_API void write_ply(const GaussianScene& scene, const std::filesystem::path& path);

/// The scene's bounds; all zero for an empty scene.
TILESPLAT_API Bounds compute_bounds(const GaussianScene& scene);

/// What a file holds, at a glance (tilesplat-info prints it): the means' box and a robust box that
/// ignores floaters, and the activated opacity and scale ranges. All zero for an empty scene.
struct SceneStatistics {
  double min[3] = {0, 0, 0};         ///< smallest x, y, z of the means
  double max[3] = {0, 0, 0};         ///< largest x, y, z of the means
  double robust_min[3] = {0, 0, 0};  ///< 1st percentile of the means per axis
  double robust_max[3] = {0, 0, 0};  ///< 99th percentile of the means per axis
  double opacity_min = 0;            ///< smallest sigmoid(opacity logit)
  double opacity_max = 0;            ///< largest sigmoid(opacity logit)
  double scale_min = 0;              ///< smallest exp(log scale) over the three axes
  double scale_max = 0;              ///< largest exp(log scale) over the three axes
};
/// The scene's statistics; all zero for an empty scene.
TILESPLAT_API SceneStatistics compute_statistics(const GaussianScene& scene);

}  // namespace tilesplat
