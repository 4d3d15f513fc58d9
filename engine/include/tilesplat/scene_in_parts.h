/// @file
/// A scene file read part by part as it is drawn: for a scene larger than the host's memory, or one a
/// renderer should not hold whole on the host while the device holds a part (docs/big-scenes.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>

#include "tilesplat/export.h"
#include "tilesplat/scene.h"

namespace tilesplat {

namespace detail {
class PartRows;
}  // namespace detail
class PartSource;

/// A binary 3DGS PLY (little or big endian), a Niantic SPZ (versions 2 to 4) or a PlayCanvas SOG (bundled or
/// its meta.json; versions 1 and 2) opened for reading part by part. Opening reads the file once and keeps
/// the Gaussians' positions (12 bytes each) and their bounds; Renderer::render(SceneInParts, ...) then
/// decodes each part's Gaussians as the part is drawn:
/// - a PLY is mapped and read in blocks let go of as they are decoded; each part's rows are decoded from the
///   file, whose pages are let go of again;
/// - an SPZ, compressed as a whole and so not readable in place, is held decompressed in its own quantized
///   layout (past the positions, 10 to 56 bytes a Gaussian by SH degree, against 44 to 224 as floats), and
///   each part is decoded from that;
/// - a SOG, whose images are compressed as wholes too, is held as their texels (past the positions, 16 bytes
///   a Gaussian and the SH palette once), each part decoded from those.
///
/// The Gaussians are load_scene's, bit for bit (those with non-finite values dropped or, strict, refused,
/// as it does), so the frames are too. The file must not change while it is open. Copies share it.
class TILESPLAT_API SceneInParts {
 public:
  /// Opens `path`, a binary PLY, an SPZ, a SOG or a .ksplat by its content. Throws SceneError naming the file for one
  /// that is missing, malformed or truncated, or in another format (an ASCII or a compressed PLY, a glTF,
  /// ...: those are read whole by load_scene). `report`, where given, gets what load_scene would report.
  static SceneInParts open(const std::filesystem::path& path, const LoadOptions& options = {},
                           LoadReport* report = nullptr);

  /// The bytes of the arrays load_scene would fill for the file at `path`, told from its header alone: for
  /// choosing between load_scene and open (tilesplat-render reads a scene in parts when they would take
  /// more than half of the host's memory). A binary PLY's rows are its floats: its size. 0 for a file
  /// open refuses, a version 1 SOG (whose SH degree only its palette image tells) or a file that cannot be
  /// read (load_scene then says why).
  static uint64_t whole_scene_bytes(const std::filesystem::path& path);

  size_t size() const;           ///< the Gaussians, as load_scene would give them
  int sh_degree() const;         ///< 0 to 3
  bool has_normals() const;      ///< whether the file carries nx, ny, nz (a PLY's; the other formats have none)
  const Bounds& bounds() const;  ///< compute_bounds of the scene load_scene would give
  /// The whole scene, as load_scene reads it (for a frame that fits: the renderer's set_scene).
  GaussianScene load() const;

 private:
  friend class PartSource;  // the renderer's parts read the positions and gather the parts
  explicit SceneInParts(std::shared_ptr<const detail::PartRows> rows) : rows_(std::move(rows)) {}
  std::shared_ptr<const detail::PartRows> rows_;
};

}  // namespace tilesplat
