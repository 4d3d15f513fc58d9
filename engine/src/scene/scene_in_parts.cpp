// SceneInParts: a scene file read once to learn its Gaussians' positions, then part by part as frames draw
// it. A binary PLY's pages are let go of after each block of the first read and after each part: the file's
// bytes never stay resident, only the positions (12 bytes a Gaussian) and the part being decoded. An SPZ or a
// SOG, compressed as a whole, cannot be read in place: it is held in its own quantized layout (an SPZ's
// packed bytes, a SOG's texels), a quarter or less of its Gaussians' size as floats, and each part decoded
// from that.
#include "tilesplat/scene_in_parts.h"

#include <algorithm>
#include <cstdint>
#include <numeric>

#include "scene/part_rows.h"
#include "scene/scene_readers.h"
#include "tilesplat/scene_description.h"

namespace tilesplat {
namespace detail {

void PartRows::set_positions(std::span<const float> positions) {
  positions_ = positions;
  bounds_ = bounds_of_positions(positions);
}

void PartRows::set_dropped(size_t in_file, std::span<const size_t> dropped) {
  kept_.clear();
  if (dropped.empty()) return;
  kept_.reserve(in_file - dropped.size());
  for (size_t i = 0, next_dropped = 0; i < in_file; ++i) {
    if (next_dropped < dropped.size() && dropped[next_dropped] == i) {
      ++next_dropped;
      continue;
    }
    kept_.push_back(uint32_t(i));
  }
}

GaussianScene PartRows::gather(std::span<const uint32_t> indices) const {
  if (kept_.empty()) return decode(indices);
  std::vector<uint32_t> in_file(indices.size());
  for (size_t k = 0; k < indices.size(); ++k) in_file[k] = kept_[indices[k]];
  return decode(in_file);
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
  set_dropped(rows, dropped);
  set_positions(positions_);
  sh_degree_ = rows_->sh_degree();
  has_normals_ = rows_->has_normals();
  LoadReport found = rows_->take_report();
  if (report) *report = std::move(found);
}

GaussianScene MappedPlyRows::decode(std::span<const uint32_t> in_file) const {
  const std::vector<uint64_t> rows(in_file.begin(), in_file.end());
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

GaussianScene SpzPartRows::decode(std::span<const uint32_t> in_file) const {
  GaussianScene scene = packed_.decode(in_file);
  normalize_rotations(scene);  // the rest of read_spz's finish_scene: nothing in an SPZ is non-finite
  return scene;
}

KsplatPartRows::KsplatPartRows(const std::filesystem::path& path, const LoadOptions& options,
                               LoadReport* report) {
  open_scene_file(path, contents_);
  const std::string name = path.string();
  packed_.emplace(contents_.bytes(), name);
  if (packed_->size() > UINT32_MAX)
    fail(name, std::to_string(packed_->size()) + " splats: a scene read in parts holds at most 2^32 - 1");
  // The positions, and the Gaussians finish_scene would drop, a block at a time.
  NonFiniteTally tally(name, options);
  std::vector<size_t> dropped;
  constexpr size_t kBlock = size_t(1) << 20;
  for (size_t first = 0; first < packed_->size(); first += kBlock) {
    const GaussianScene block = packed_->decode_range(first, std::min(packed_->size(), first + kBlock));
    const std::vector<size_t> bad = non_finite_gaussians(block, first, tally);
    size_t next_bad = 0;
    for (size_t i = 0; i < block.size(); ++i) {
      if (next_bad < bad.size() && bad[next_bad] == i) {
        dropped.push_back(first + i);
        ++next_bad;
        continue;
      }
      positions_.insert(positions_.end(), block.positions.begin() + std::ptrdiff_t(3 * i),
                        block.positions.begin() + std::ptrdiff_t(3 * i + 3));
    }
  }
  set_dropped(packed_->size(), dropped);
  set_positions(positions_);
  sh_degree_ = packed_->sh_degree();
  if (report) {
    LoadReport found;  // what read_ksplat reports
    found.format = packed_->format();
    found.version = packed_->version();
    found.gaussians_in_file = packed_->size();
    found.dropped = dropped.size();
    found.dropped_by_property = tally.take();
    *report = std::move(found);
  }
}

RadPartRows::RadPartRows(const std::filesystem::path& path, const LoadOptions& options, LoadReport* report)
    : name_(path.string()), load_chunk_(sibling_loader(path)) {
  open_scene_file(path, contents_);
  const RadFile::Chunking chunking = RadFile::chunking_of(contents_.bytes(), name_);
  chunk_size_ = chunking.chunk_size;
  // A chunk at a time: the leaves' positions, the Gaussians finish_scene would drop, the tree to check.
  NonFiniteTally tally(name_, options);
  std::vector<size_t> dropped;
  std::vector<uint32_t> child_count, child_start;
  RadFile::Description description;  // the first chunk's, as read_rad's whole read reports it
  size_t nodes = 0;
  for (size_t c = 0; c < chunking.chunks; ++c) {
    const RadFile chunk = RadFile::chunk_of(contents_.bytes(), name_, load_chunk_, c, sh_codes_);
    if (c == 0) {
      sh_codes_ = chunk.sh_codes();
      description = chunk.description();
    }
    std::vector<uint32_t> leaves = chunk.leaves();  // in the chunk
    const GaussianScene block = chunk.decode(leaves);
    const std::vector<size_t> bad = non_finite_gaussians(block, leaf_nodes_.size(), tally);
    size_t next_bad = 0;
    for (size_t i = 0; i < leaves.size(); ++i) {
      if (next_bad < bad.size() && bad[next_bad] == i) {
        dropped.push_back(leaf_nodes_.size() + i);
        ++next_bad;
      } else {
        positions_.insert(positions_.end(), block.positions.begin() + std::ptrdiff_t(3 * i),
                          block.positions.begin() + std::ptrdiff_t(3 * i + 3));
      }
    }
    for (size_t i = 0; i < leaves.size(); ++i) leaves[i] += static_cast<uint32_t>(nodes);
    leaf_nodes_.insert(leaf_nodes_.end(), leaves.begin(), leaves.end());
    if (chunk.has_lod_tree())
      for (size_t i = 0; i < chunk.size(); ++i) {
        child_count.push_back(chunk.child_count(i));
        child_start.push_back(chunk.child_start(i));
      }
    nodes += chunk.size();
  }
  RadFile::check_tree_of(name_, child_count, child_start);
  if (leaf_nodes_.size() > UINT32_MAX)
    fail(name_, std::to_string(leaf_nodes_.size()) + " splats: a scene read in parts holds at most 2^32 - 1");
  set_dropped(leaf_nodes_.size(), dropped);
  set_positions(positions_);
  sh_degree_ = chunking.sh_degree;
  if (report) {
    *report = LoadReport{.format = description.format(leaf_nodes_.size()),
                         .version = "1",
                         .gaussians_in_file = leaf_nodes_.size(),
                         .dropped = dropped.size(),
                         .dropped_by_property = tally.take()};
  }
}

GaussianScene RadPartRows::decode(std::span<const uint32_t> in_file) const {
  // The Gaussians by chunk (ascending, as in_file is): each chunk decoded once for those it holds.
  std::vector<GaussianScene> scenes;
  for (size_t i = 0; i < in_file.size();) {
    const size_t chunk = leaf_nodes_[in_file[i]] / chunk_size_;
    std::vector<uint32_t> local;
    for (; i < in_file.size() && leaf_nodes_[in_file[i]] / chunk_size_ == chunk; ++i)
      local.push_back(static_cast<uint32_t>(leaf_nodes_[in_file[i]] - chunk * chunk_size_));
    scenes.push_back(RadFile::chunk_of(contents_.bytes(), name_, load_chunk_, chunk, sh_codes_).decode(local));
  }
  GaussianScene scene = scenes.size() == 1 ? std::move(scenes.front()) : merge_scenes(scenes);
  if (scenes.empty()) allocate_scene(scene, 0, sh_degree_);
  normalize_rotations(scene);  // the rest of read_rad's finish_scene (the dropped ones are not asked for)
  return scene;
}

GaussianScene KsplatPartRows::decode(std::span<const uint32_t> in_file) const {
  GaussianScene scene = packed_->decode(in_file);
  normalize_rotations(scene);  // the rest of read_ksplat's finish_scene (the dropped ones are not asked for)
  return scene;
}

SogPartRows::SogPartRows(SogPacked packed, std::string_view name, const LoadOptions& options,
                         LoadReport* report)
    : packed_(std::move(packed)) {
  // The Gaussians finish_scene would drop: only a position or a table value past float's range makes one
  // non-finite, so they are looked for, decoding each once a block at a time, only where there is such a
  // value.
  NonFiniteTally tally(name, options);
  std::vector<size_t> dropped;
  constexpr size_t kBlock = size_t(1) << 20;
  if (!packed_.all_values_finite())
    for (size_t first = 0; first < packed_.size(); first += kBlock) {
      const GaussianScene block = packed_.decode_range(first, std::min(packed_.size(), first + kBlock));
      for (size_t i : non_finite_gaussians(block, first, tally)) dropped.push_back(first + i);
    }
  set_dropped(packed_.size(), dropped);
  if (dropped.empty()) {
    set_positions(packed_.positions());
  } else {
    const std::vector<float>& all = packed_.positions();
    for (size_t i = 0; i < packed_.size() - dropped.size(); ++i)
      kept_positions_.insert(kept_positions_.end(), all.begin() + std::ptrdiff_t(3 * in_file(i)),
                             all.begin() + std::ptrdiff_t(3 * in_file(i) + 3));
    set_positions(kept_positions_);
  }
  sh_degree_ = packed_.sh_degree();
  if (report) {
    LoadReport found;  // what finish_scene reports
    found.format = packed_.format();
    found.version = packed_.version();
    found.gaussians_in_file = packed_.size();
    found.dropped = tally.dropped();
    found.dropped_by_property = tally.take();
    *report = std::move(found);
  }
}

GaussianScene SogPartRows::decode(std::span<const uint32_t> in_file) const {
  GaussianScene scene = packed_.decode(in_file);
  normalize_rotations(scene);  // the rest of finish_scene
  return scene;
}

}  // namespace detail

namespace {
std::string_view as_text(std::span<const std::byte> bytes) {  // a meta.json's
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}
}  // namespace

SceneInParts SceneInParts::open(const std::filesystem::path& path, const LoadOptions& options,
                                LoadReport* report) {
  {
    detail::FileContents contents;
    detail::open_scene_file(path, contents);
    const std::span<const std::byte> bytes = contents.bytes();
    const std::string name = path.string();
    switch (detail::container_of(bytes)) {
      case detail::Container::kPly:
        break;  // mapped again below, to be read as it is drawn
      case detail::Container::kSpz:
        return SceneInParts(std::make_shared<const detail::SpzPartRows>(contents, name, options, report));
      case detail::Container::kZip:
        return SceneInParts(std::make_shared<const detail::SogPartRows>(
            detail::SogPacked::from_zip(bytes, name), name, options, report));
      case detail::Container::kKsplat:
        return SceneInParts(std::make_shared<const detail::KsplatPartRows>(path, options, report));
      case detail::Container::kRad:
        return SceneInParts(std::make_shared<const detail::RadPartRows>(path, options, report));
      case detail::Container::kJson:  // falls through to the refusal below when it is no SOG meta.json
        if (detail::is_sog_meta(as_text(bytes)))
          return SceneInParts(std::make_shared<const detail::SogPartRows>(
              detail::SogPacked::from_meta(as_text(bytes), name, detail::sibling_loader(path)), name, options,
              report));
        [[fallthrough]];
      case detail::Container::kGlb:
      case detail::Container::kUnknown:
        if (!bytes.empty())
          detail::fail(
              name,
              "not a PLY file (it does not start with the 'ply' magic line), an SPZ, a SOG, a .ksplat or a .rad: "
              "only these are read part by part; load_scene reads the others whole");
        break;  // empty: the PLY reader says so
    }
  }  // an SPZ's or a SOG's file is let go of once decoded
  return SceneInParts(std::make_shared<const detail::MappedPlyRows>(path, options, report));
}

uint64_t SceneInParts::whole_scene_bytes(const std::filesystem::path& path) {
  try {
    detail::FileContents contents;
    detail::open_scene_file(path, contents);
    const std::span<const std::byte> bytes = contents.bytes();
    const std::string name = path.string();
    switch (detail::container_of(bytes)) {
      case detail::Container::kPly:
        return bytes.size();  // a binary PLY's rows are its floats
      case detail::Container::kSpz:
        return detail::read_spz_counts(bytes, name).scene_bytes();
      case detail::Container::kZip:
        return detail::read_sog_zip_counts(bytes, name).scene_bytes();
      case detail::Container::kJson:
        return detail::is_sog_meta(as_text(bytes))
                   ? detail::read_sog_meta_counts(as_text(bytes), name).scene_bytes()
                   : 0;
      case detail::Container::kKsplat:
        return detail::KsplatPacked(bytes, name).counts().scene_bytes();
      case detail::Container::kRad: {
        // At most every splat of the file (a LOD tree's leaves are fewer), as floats.
        const detail::RadFile::Chunking chunking = detail::RadFile::chunking_of(bytes, name);
        return detail::DeclaredCounts{chunking.count, chunking.sh_degree}.scene_bytes();
      }
      case detail::Container::kGlb:
      case detail::Container::kUnknown:
        return 0;
    }
  } catch (const SceneError&) {
  }
  return 0;
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
