// What a SceneInParts holds: each Gaussian's position (the depth order and the bounds need them all) and
// the means to decode any part of the Gaussians, from a mapped PLY's rows or an SPZ's packed bytes. The
// renderer's parts (frame/scene_parts.h) read positions for the depth order and gather each part.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "scene/ply_rows.h"
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
  virtual GaussianScene gather(std::span<const uint32_t> indices) const = 0;
  GaussianScene load() const;

 protected:
  // Set by the reader: the positions it keeps (x, y, z of each Gaussian) and what it learnt of the file.
  void set_positions(std::span<const float> positions);
  int sh_degree_ = 0;
  bool has_normals_ = false;

 private:
  std::span<const float> positions_;
  Bounds bounds_;
};

// A binary PLY, mapped: its rows decoded from the file for each part, the file's pages let go of after.
class MappedPlyRows final : public PartRows {
 public:
  MappedPlyRows(const std::filesystem::path& path, const LoadOptions& options, LoadReport* report);
  GaussianScene gather(std::span<const uint32_t> indices) const override;

 private:
  FileContents contents_;
  std::unique_ptr<PlyRows> rows_;
  std::vector<float> positions_;
  std::vector<uint64_t> kept_rows_;  // each Gaussian's row, where some rows were dropped (else empty)
  mutable std::mutex decoding_;      // one part decoded at a time (the file's pages are let go of after)
};

// An SPZ, held decompressed in its own quantized layout (SpzPacked); the file itself is let go of.
class SpzPartRows final : public PartRows {
 public:
  SpzPartRows(FileContents& contents, std::string_view name, const LoadOptions& options, LoadReport* report);
  GaussianScene gather(std::span<const uint32_t> indices) const override;

 private:
  SpzPacked packed_;
};

// A SOG, held as its images' texels (SogPacked). Gaussians with a non-finite value (a meta.json's ranges
// and codebooks can hold values no float holds) are dropped, or refused, as load_scene drops them.
class SogPartRows final : public PartRows {
 public:
  SogPartRows(SogPacked packed, std::string_view name, const LoadOptions& options, LoadReport* report);
  GaussianScene gather(std::span<const uint32_t> indices) const override;

 private:
  SogPacked packed_;
  std::vector<uint32_t> kept_;  // each Gaussian's index in the file, where some were dropped (else empty)
  std::vector<float> kept_positions_;  // their positions (else packed_'s are the Gaussians')
};

}  // namespace tilesplat::detail
