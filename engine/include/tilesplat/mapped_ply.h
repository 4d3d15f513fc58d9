/// @file
/// A binary PLY scene read from its file as it is drawn: for a scene larger than the host's memory, or one
/// a renderer should not hold whole on the host while the device holds a part (docs/big-scenes.md).
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>

#include "tilesplat/export.h"
#include "tilesplat/scene.h"

namespace tilesplat {

namespace detail {
class MappedPlyRows;
}  // namespace detail
class PartSource;

/// A binary 3DGS PLY (little or big endian) opened for reading part by part. Opening maps the file and
/// reads it once, in blocks let go of as they are decoded, keeping the Gaussians' positions (12 bytes
/// each) and their bounds; Renderer::render(MappedPly, ...) then decodes each part's Gaussians from the
/// file as the part is drawn and lets go of the file's pages again. The Gaussians are load_ply's, bit for
/// bit (those with non-finite values dropped or, strict, refused, as it does), so the frames are too.
/// The file must not change while it is open. Copies share the open file.
class TILESPLAT_API MappedPly {
 public:
  /// Opens `path`. Throws SceneError naming the file for one that is missing, malformed, truncated, or not
  /// a binary 3DGS PLY (an ASCII or a compressed PLY is read whole by load_ply). `report`, where given,
  /// gets what load_ply would report.
  static MappedPly open(const std::filesystem::path& path, const LoadOptions& options = {},
                        LoadReport* report = nullptr);

  size_t size() const;           ///< the Gaussians, as load_ply would give them
  int sh_degree() const;         ///< 0 to 3
  bool has_normals() const;      ///< whether the file carries nx, ny, nz
  const Bounds& bounds() const;  ///< compute_bounds of the scene load_ply would give
  /// The whole scene, as load_ply reads it (for a frame that fits: the renderer's set_scene).
  GaussianScene load() const;

 private:
  friend class PartSource;  // the renderer's parts read the rows
  explicit MappedPly(std::shared_ptr<const detail::MappedPlyRows> rows) : rows_(std::move(rows)) {}
  std::shared_ptr<const detail::MappedPlyRows> rows_;
};

}  // namespace tilesplat
