// SceneInParts: a scene file read once to learn its Gaussians' positions, then part by part as frames draw
// it. A binary PLY's pages are let go of after each block of the first read and after each part: the file's
// bytes never stay resident, only the positions (12 bytes a Gaussian) and the part being decoded. An SPZ,
// compressed as a whole, cannot be read in place: it is held decompressed in its own quantized layout, a
// quarter of its Gaussians' size as floats, and each part is decoded from that.
#include "tilesplat/scene_in_parts.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <numeric>

#include "scene/part_rows.h"
#include "scene/scene_readers.h"

namespace tilesplat {
namespace detail {

void PartRows::set_positions(std::span<const float> positions) {
  positions_ = positions;
  bounds_ = bounds_of_positions(positions);
}

GaussianScene PartRows::load() const {
  std::vector<uint32_t> all(size());
  std::iota(all.begin(), all.end(), 0u);
  return gather(all);
}

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
  set_positions(positions_);
  sh_degree_ = rows_->sh_degree();
  has_normals_ = rows_->has_normals();
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

SpzPartRows::SpzPartRows(FileContents& contents, std::string_view name, const LoadOptions& options,
                         LoadReport* report)
    : packed_(contents.bytes(), name, &contents) {
  (void)options;  // strict or not alike: no Gaussian of an SPZ can hold a non-finite value
  set_positions(packed_.positions());
  sh_degree_ = packed_.sh_degree();
  if (report) {
    LoadReport found;  // what read_spz reports
    found.format = "spz";
    found.version = std::to_string(packed_.version());
    found.gaussians_in_file = packed_.size();
    if (packed_.has_extensions()) found.ignored_properties.push_back(kSpzExtensionsIgnored);
    *report = std::move(found);
  }
}

GaussianScene SpzPartRows::gather(std::span<const uint32_t> indices) const {
  GaussianScene scene = packed_.decode(indices);
  normalize_rotations(scene);  // the rest of read_spz's finish_scene: nothing in an SPZ is non-finite
  return scene;
}

}  // namespace detail

SceneInParts SceneInParts::open(const std::filesystem::path& path, const LoadOptions& options,
                                LoadReport* report) {
  {
    detail::FileContents contents;
    detail::open_scene_file(path, contents);
    const std::span<const std::byte> bytes = contents.bytes();
    const bool ply = bytes.size() >= 3 && std::memcmp(bytes.data(), "ply", 3) == 0;
    if (!ply && detail::is_spz(bytes))
      return SceneInParts(
          std::make_shared<const detail::SpzPartRows>(contents, path.string(), options, report));
    if (!ply && !bytes.empty())
      detail::fail(path.string(),
                   "not a PLY file (it does not start with the 'ply' magic line) nor an SPZ: only these two "
                   "are read part by part; load_scene reads the others whole");
  }  // the SPZ's file is let go of once decompressed; a PLY is mapped again, to be read as it is drawn
  return SceneInParts(std::make_shared<const detail::MappedPlyRows>(path, options, report));
}

uint64_t SceneInParts::whole_scene_bytes(const std::filesystem::path& path) {
  try {
    detail::FileContents contents;
    detail::open_scene_file(path, contents);
    const std::span<const std::byte> bytes = contents.bytes();
    if (bytes.size() >= 3 && std::memcmp(bytes.data(), "ply", 3) == 0) return bytes.size();
    if (!detail::is_spz(bytes)) return 0;
    const detail::SpzCounts counts = detail::read_spz_counts(bytes, path.string());
    const uint64_t floats = 11 + 3 * uint64_t((counts.sh_degree + 1) * (counts.sh_degree + 1));
    return uint64_t(counts.count) * floats * sizeof(float);
  } catch (const SceneError&) {
    return 0;
  }
}

size_t SceneInParts::size() const {
  return rows_->size();
}
int SceneInParts::sh_degree() const {
  return rows_->sh_degree();
}
bool SceneInParts::has_normals() const {
  return rows_->has_normals();
}
const Bounds& SceneInParts::bounds() const {
  return rows_->bounds();
}
GaussianScene SceneInParts::load() const {
  return rows_->load();
}

}  // namespace tilesplat
