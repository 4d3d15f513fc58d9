// An SPZ file decompressed into its own quantized layout: what read_spz decodes to floats, and what a scene
// read in parts from an SPZ holds (SceneInParts). Past the positions, which are decoded as they are read
// (the depth order and the bounds need them), a Gaussian keeps its file's bytes: 11 at SH degree 0 to 56 at
// degree 3 (one less in version 2), against 44 to 224 as floats. Each Gaussian decodes alone, so a part
// gathers any of them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "scene/scene_readers.h"
#include "tilesplat/scene.h"

namespace tilesplat::detail {

class FileContents;  // scene/scene_reading.h

// What a LoadReport lists as ignored for an SPZ whose extension flag is set.
inline constexpr const char* kSpzExtensionsIgnored = "SPZ extension records (flag 0x2)";

// Reads only the header (inflating its 16 bytes from a gzip stream); throws SceneError as SpzPacked does.
DeclaredCounts read_spz_counts(std::span<const std::byte> data, std::string_view name);

class SpzPacked {
 public:
  // Decompresses an SPZ file (versions 2 and 3: gzip or plain; 4: zstd streams). Throws SceneError naming
  // `name` for a malformed, truncated or implausible one. Only the positions are ever held unpacked.
  // `file`, where given, is where `data` is mapped from: its pages are let go of as they are decompressed,
  // so that the file and what it holds are not both resident.
  SpzPacked(std::span<const std::byte> data, std::string_view name, FileContents* file = nullptr);

  size_t size() const { return count_; }
  int sh_degree() const { return sh_degree_; }
  uint32_t version() const { return version_; }
  bool has_extensions() const { return has_extensions_; }
  // x, y, z of each Gaussian in the engine's axes, as read_spz gives them.
  const std::vector<float>& positions() const { return positions_; }

  // Gaussians `indices` (any order) as read_spz decodes them, before finish_scene: no Gaussian of an SPZ
  // file can hold a non-finite value, so finish_scene only normalizes their rotations.
  GaussianScene decode(std::span<const uint32_t> indices) const;
  GaussianScene decode_all() const;

 private:
  template <typename IndexOf>
  GaussianScene decode_each(size_t count, IndexOf index_of) const;

  uint32_t version_ = 0;
  size_t count_ = 0;
  int sh_degree_ = 0;
  bool has_extensions_ = false;
  std::vector<float> positions_;
  // The rest, attribute after attribute as in the file: alphas, colours, scales, rotations, SH.
  std::vector<unsigned char> attributes_;
};

}  // namespace tilesplat::detail
