/// @file
/// Level-of-detail trees: Spark 2's .rad files built with a LOD tree (its `build-lod`), where each node is a
/// splat, the leaves are the capture's Gaussians and each inner node stands for its children merged. A
/// frame draws a cut through the tree: one level of it (as Spark's own level view cuts it), or the cut a
/// camera calls for under a splat budget (as Spark's traversal chooses it). docs/big-scenes.md has the rules;
/// tilesplat/lod_set.h is the same for splat-transform's chunked sets.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/export.h"
#include "tilesplat/scene.h"

namespace tilesplat {

namespace detail {
class RadFile;  // scene/rad_file.h: the decoded file
}  // namespace detail

/// The nodes one camera draws under a splat budget (SplatLodTree::select).
struct LodTreeCut {
  std::vector<uint32_t> nodes;  ///< the cut, ascending: every leaf has exactly one of its ancestors (or itself) here
  /// The budget is below 1: the root alone is drawn.
  bool over_budget = false;
};

/// An opened .rad with a LOD tree, decoded whole (a tree's cuts need every node's size).
class TILESPLAT_API SplatLodTree {
 public:
  /// Reads the file (chunk files beside it included) and checks the tree: one parent per node, every node
  /// reached from the root. Throws SceneError naming the file, also for a .rad without a LOD tree.
  static SplatLodTree open(const std::filesystem::path& path);
  /// The same on a .rad in memory (`name` stands for it in errors); one whose chunks are files is refused.
  static SplatLodTree parse(std::span<const std::byte> data, std::string_view name);
  SplatLodTree(SplatLodTree&&) noexcept;             ///< moves the tree
  SplatLodTree& operator=(SplatLodTree&&) noexcept;  ///< moves the tree
  ~SplatLodTree();

  size_t nodes() const;  ///< every splat of the file, inner nodes included
  int sh_degree() const;  ///< the SH degree of every node (the file's maxSh)
  /// Node `node`'s children are nodes [child_start, child_start + child_count); a leaf has none. Node 0 is
  /// the root. Throws std::out_of_range past nodes().
  uint32_t child_count(uint32_t node) const;
  uint32_t child_start(uint32_t node) const;  ///< the first child's index (see child_count)
  /// What the cuts compare: 2 x the node's mean scale, widened for an opacity above 1 (Spark's measure).
  double node_size(uint32_t node) const;
  /// Level 0 is the leaves (the capture); level L > 0 is Spark's level view at depth levels() - 1 - L: from
  /// the root down, a node is drawn where its size (2 x its mean scale, widened for an opacity above 1) is at
  /// most the root's over 1.25^(levels() - 1 - L), else its children are looked at; a leaf is always drawn.
  /// The last level is the root alone.
  int levels() const;
  std::vector<uint32_t> level_nodes(int level) const;  ///< throws std::out_of_range for a level it lacks
  /// Spark's traversal for a camera: starting from the root, the node that covers the most of the view (its
  /// size over its distance from the camera; ties to the lower index) is replaced by its children while the
  /// cut stays within `splat_budget` nodes; the first that would pass it ends the refinement. A budget of at
  /// least the leaves draws them all.
  LodTreeCut select(const Camera& camera, uint64_t splat_budget) const;
  /// The Gaussians of `nodes`, in their order, as load_scene decodes the file (inner nodes with Spark's
  /// wider kernel widened to the Gaussian one: docs/formats.md).
  GaussianScene load(std::span<const uint32_t> nodes, const LoadOptions& options = {}) const;
  GaussianScene load_level(int level, const LoadOptions& options = {}) const;  ///< load(level_nodes(level))

 private:
  struct Impl;
  SplatLodTree(std::string name, detail::RadFile&& file);  // throws SceneError for a file without a tree
  std::unique_ptr<Impl> impl_;
};

/// Whether `path` is a .rad whose header says it holds a LOD tree (reads the header only; false for
/// anything else, a missing file included).
TILESPLAT_API bool is_lod_tree(const std::filesystem::path& path);

}  // namespace tilesplat
