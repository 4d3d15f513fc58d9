// What a SceneInParts holds: each Gaussian's position (the depth order and the bounds need them all) and
// the means to decode any part of the Gaussians, from a mapped PLY's rows, an SPZ's packed bytes or a SOG's
// texels. The renderer's parts (frame/scene_parts.h) read positions for the depth order and gather each part.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "scene/ksplat_packed.h"
#include "scene/ply_rows.h"
#include "scene/rad_file.h"
#include "scene/scene_reading.h"
#include "scene/sog_packed.h"
#include "scene/spz_packed.h"
#include "tilesplat/scene.h"

namespace tilesplat::detail {

class PartRows {
 public:
  PartRows() = default;
  PartRows(const PartRows&) = delete;  // positions_ views the reader's own array
  PartRows& operator=(const PartRows&) = delete;
  virtual ~PartRows() = default;

  size_t size() const { return positions_.size() / 3; }
  int sh_degree() const { return sh_degree_; }
  bool has_normals() const { return has_normals_; }
  const Bounds& bounds() const { return bounds_; }
  std::array<float, 3> position(size_t i) const {
    return {positions_[3 * i], positions_[3 * i + 1], positions_[3 * i + 2]};
  }
  // Gaussians `indices` (ascending) as a scene of their own, as load_scene gives them. From any thread.
  GaussianScene gather(std::span<const uint32_t> indices) const;
  GaussianScene load() const;

 protected:
  // The file's Gaussians `in_file` (ascending), as load_scene decodes them, before it drops any.
  virtual GaussianScene decode(std::span<const uint32_t> in_file) const = 0;
  // Set by the reader: the positions of the Gaussians it keeps (x, y, z of each), and what it learnt of the
  // file. `dropped` (ascending) are the file's Gaussians load_scene drops for non-finite values, of
  // `in_file`; the others are numbered in order.
  void set_positions(std::span<const float> positions);
  void set_dropped(size_t in_file, std::span<const size_t> dropped);
  // Gaussian i's index in the file.
  size_t in_file(size_t i) const { return kept_.empty() ? i : kept_[i]; }
  int sh_degree_ = 0;
  bool has_normals_ = false;

 private:
  std::span<const float> positions_;
  std::vector<uint32_t> kept_;  // each Gaussian's index in the file, where some were dropped (else empty)
  Bounds bounds_;
};

// A binary PLY, mapped: its rows decoded from the file for each part, the file's pages let go of after.
class MappedPlyRows final : public PartRows {
 public:
  MappedPlyRows(const std::filesystem::path& path, const LoadOptions& options, LoadReport* report);

 private:
  GaussianScene decode(std::span<const uint32_t> in_file) const override;
  FileContents contents_;
  std::unique_ptr<PlyRows> rows_;
  std::vector<float> positions_;
  mutable std::mutex decoding_;  // one part decoded at a time (the file's pages are let go of after)
};

// An SPZ, held decompressed in its own quantized layout (SpzPacked); the file itself is let go of.
class SpzPartRows final : public PartRows {
 public:
  SpzPartRows(FileContents& contents, std::string_view name, const LoadOptions& options, LoadReport* report);

 private:
  GaussianScene decode(std::span<const uint32_t> in_file) const override;
  SpzPacked packed_;
};

// A .ksplat, mapped: each part's splats decoded from the file where they lie (KsplatPacked), the positions
// decoded once. Gaussians with a non-finite value (a NaN or a zero scale at level 0) are dropped, or refused,
// as load_scene drops them.
class KsplatPartRows final : public PartRows {
 public:
  KsplatPartRows(const std::filesystem::path& path, const LoadOptions& options, LoadReport* report);

 private:
  GaussianScene decode(std::span<const uint32_t> in_file) const override;
  FileContents contents_;
  std::optional<KsplatPacked> packed_;
  std::vector<float> positions_;
};

// A Spark .rad, mapped: each part decodes the chunks its Gaussians lie in (scene/rad_file.h), a chunk at a
// time; only the leaves' positions (and an SH codebook) are held. A LOD tree's leaves are its Gaussians, as
// load_scene reads them.
class RadPartRows final : public PartRows {
 public:
  RadPartRows(const std::filesystem::path& path, const LoadOptions& options, LoadReport* report);

 private:
  GaussianScene decode(std::span<const uint32_t> in_file) const override;
  FileContents contents_;
  std::string name_;
  FileLoader load_chunk_;
  size_t chunk_size_ = 0;
  std::vector<uint32_t> leaf_nodes_;  // each of the file's Gaussians (a leaf) as a node of the file
  std::vector<float> sh_codes_;       // the file's SH codebook, if it has one
  std::vector<float> positions_;
};

// A SOG, held as its images' texels (SogPacked). Gaussians with a non-finite value (a meta.json's ranges
// and codebooks can hold values no float holds) are dropped, or refused, as load_scene drops them.
class SogPartRows final : public PartRows {
 public:
  SogPartRows(SogPacked packed, std::string_view name, const LoadOptions& options, LoadReport* report);

 private:
  GaussianScene decode(std::span<const uint32_t> in_file) const override;
  SogPacked packed_;
  std::vector<float> kept_positions_;  // where some were dropped (else packed_'s are the Gaussians')
};

}  // namespace tilesplat::detail
