// What a MappedPly holds: the mapped file, its rows' decoder, the Gaussians' positions and which row each
// Gaussian is. The renderer's parts (frame/scene_parts.h) read positions for the depth order and gather
// each part's Gaussians from the file.
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
#include "tilesplat/scene.h"

namespace tilesplat::detail {

class MappedPlyRows {
 public:
  MappedPlyRows(const std::filesystem::path& path, const LoadOptions& options, LoadReport* report);

  size_t size() const { return positions_.size() / 3; }
  int sh_degree() const { return rows_->sh_degree(); }
  bool has_normals() const { return rows_->has_normals(); }
  const Bounds& bounds() const { return bounds_; }
  std::array<float, 3> position(size_t i) const {
    return {positions_[3 * i], positions_[3 * i + 1], positions_[3 * i + 2]};
  }
  // Gaussians `indices` (ascending) as a scene of their own, decoded from the file, whose pages are then
  // let go of. One gather at a time (a mutex), from any thread.
  GaussianScene gather(std::span<const uint32_t> indices) const;
  GaussianScene load() const;

 private:
  FileContents contents_;
  std::unique_ptr<PlyRows> rows_;
  std::vector<float> positions_;     // x, y, z of each Gaussian
  std::vector<uint64_t> kept_rows_;  // each Gaussian's row, where some rows were dropped (else empty)
  Bounds bounds_;
  mutable std::mutex decoding_;
};

}  // namespace tilesplat::detail
