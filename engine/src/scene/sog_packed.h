// A SOG's Gaussians as its images hold them: what read_sog_zip and read_sog_meta decode to floats, and what a
// scene read in parts from a SOG holds (SceneInParts). Past the positions, which are decoded as the means
// images are read (the depth order and the bounds need them), a Gaussian keeps its texels of the quats,
// scales, sh0 and shN labels images (16 bytes, and the shN palette once), against 44 to 224 bytes as floats.
// Each Gaussian decodes alone, so a part gathers any of them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "scene/scene_readers.h"
#include "tilesplat/scene.h"

namespace tilesplat::detail {

// One lossless WebP decoded: texel i (row-major) is Gaussian i, or a palette entry's.
struct SogImage {
  int width = 0;
  int height = 0;
  std::vector<unsigned char> rgba;
  const unsigned char* texel(size_t i) const { return rgba.data() + 4 * i; }
};

// What a version 2 meta.json declares. A version 1 meta.json does not say its SH degree (its palette image's
// width does): SceneError, as for a malformed one.
DeclaredCounts read_sog_zip_counts(std::span<const std::byte> data, std::string_view name);
DeclaredCounts read_sog_meta_counts(std::string_view meta_json, std::string_view name);

class SogPacked {
 public:
  // A bundled SOG (a zip of meta.json and its images) or an unbundled one (meta.json, its images read by
  // `load_image`). Throws SceneError naming `name` for a malformed one.
  static SogPacked from_zip(std::span<const std::byte> data, std::string_view name);
  static SogPacked from_meta(std::string_view meta_json, std::string_view name, const FileLoader& load_image);

  size_t size() const { return positions_.size() / 3; }
  int sh_degree() const { return sh_degree_; }
  const std::string& format() const { return format_; }    // "sog" or "sog (unbundled)"
  const std::string& version() const { return version_; }  // "1" or "2"
  const std::vector<float>& positions() const { return positions_; }
  // Whether every position and every value a channel's texel can pick is finite: then no Gaussian is
  // (rotations always are), and finish_scene drops none.
  bool all_values_finite() const;

  // Gaussians `indices` (any order) as the SOG readers decode them, before finish_scene (which may drop
  // non-finite ones: a meta.json's ranges and codebooks can hold values no float holds).
  GaussianScene decode(std::span<const uint32_t> indices) const;
  GaussianScene decode_range(size_t first, size_t end) const;

 private:
  friend class SogDecoder;
  template <typename IndexOf>
  GaussianScene decode_each(size_t count, IndexOf index_of) const;

  int sh_degree_ = 0;
  std::string format_, version_;
  std::vector<float> positions_;
  SogImage quats_, scales_, colours_, labels_, centroids_;
  // Each channel's 256 values: log scales x y z; DC colour r g b and the opacity logit; the SH rest's.
  std::array<std::array<float, 256>, 3> scale_values_{};
  std::array<std::array<float, 256>, 4> colour_values_{};
  std::array<float, 256> sh_values_{};
  size_t palette_ = 0;  // shN palette entries
};

}  // namespace tilesplat::detail
