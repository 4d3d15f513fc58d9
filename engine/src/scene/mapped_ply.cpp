// MappedPly: a binary PLY read once to learn its Gaussians' positions, then part by part as frames draw
// it. Its pages are let go of after each block of the first read and after each part: the file's bytes
// never stay resident, only the positions (12 bytes a Gaussian) and the part being decoded.
#include "tilesplat/mapped_ply.h"

#include <algorithm>
#include <cstdint>
#include <numeric>

#include "scene/mapped_ply_rows.h"

namespace tilesplat {
namespace detail {
MappedPlyRows::MappedPlyRows(const std::filesystem::path& path, const LoadOptions& options,
                             LoadReport* report) {
  open_scene_file(path, contents_);
  rows_ = std::make_unique<PlyRows>(path.string(), contents_.data(), contents_.size(), options);
  const size_t rows = rows_->rows();
  if (rows > UINT32_MAX)
    fail(path.string(), std::to_string(rows) + " vertices: a scene read in parts holds at most 2^32 - 1");
  const size_t block = rows_->rows_per_block();
  std::vector<size_t> dropped;
  GaussianScene decoded;
  positions_.reserve(3 * rows);
  for (size_t first = 0; first < rows; first += block) {
    const size_t end = std::min(rows, first + block);
    const size_t kept = rows_->decode_range(first, end, decoded, dropped);
    positions_.insert(positions_.end(), decoded.positions.begin(),
                      decoded.positions.begin() + std::ptrdiff_t(3 * kept));
    contents_.release_all();
  }
  if (!dropped.empty()) {
    kept_rows_.reserve(rows - dropped.size());
    size_t next_dropped = 0;
    for (size_t row = 0; row < rows; ++row) {
      if (next_dropped < dropped.size() && dropped[next_dropped] == row) {
        ++next_dropped;
        continue;
      }
      kept_rows_.push_back(row);
    }
  }
  bounds_ = bounds_of_positions(positions_);
  LoadReport found = rows_->take_report();
  if (report) *report = std::move(found);
}

GaussianScene MappedPlyRows::gather(std::span<const uint32_t> indices) const {
  std::vector<uint64_t> rows(indices.size());
  for (size_t i = 0; i < indices.size(); ++i)
    rows[i] = kept_rows_.empty() ? indices[i] : kept_rows_[indices[i]];
  const std::lock_guard<std::mutex> lock(decoding_);
  GaussianScene scene = rows_->decode(rows);
  contents_.release_all();
  return scene;
}

GaussianScene MappedPlyRows::load() const {
  std::vector<uint32_t> all(size());
  std::iota(all.begin(), all.end(), 0u);
  return gather(all);
}

}  // namespace detail

MappedPly MappedPly::open(const std::filesystem::path& path, const LoadOptions& options, LoadReport* report) {
  return MappedPly(std::make_shared<const detail::MappedPlyRows>(path, options, report));
}

size_t MappedPly::size() const {
  return rows_->size();
}
int MappedPly::sh_degree() const {
  return rows_->sh_degree();
}
bool MappedPly::has_normals() const {
  return rows_->has_normals();
}
const Bounds& MappedPly::bounds() const {
  return rows_->bounds();
}
GaussianScene MappedPly::load() const {
  return rows_->load();
}

}  // namespace tilesplat
