/// @file
/// Level-of-detail sets: splat-transform's streamed SOG (`lod-meta.json`), a scene cut into spatial
/// chunks, each held at several levels of detail (level 0 the full capture, each further level coarser),
/// and the choice of a level per chunk for a camera under a splat budget, as streaming viewers make it.
/// The format and the rule are documented in docs/big-scenes.md.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/export.h"
#include "tilesplat/scene.h"

namespace tilesplat {

/// A run of Gaussians in one of the set's chunk files: Gaussians [offset, offset + count) of file `file`.
struct LodSlice {
  uint32_t file = 0;    ///< index into LodSet::files()
  uint64_t offset = 0;  ///< the first Gaussian's index in the file
  uint64_t count = 0;   ///< how many; 0 where the chunk has none at this level
};

/// One leaf of the set's bounds tree: a region of space and its Gaussians at each level.
struct LodChunk {
  std::array<double, 3> min = {0, 0, 0};  ///< the region's box, as the index gives it: lowest corner
  std::array<double, 3> max = {0, 0, 0};  ///< highest corner
  /// One entry per level of the set; a level without Gaussians here has count 0.
  std::vector<LodSlice> levels;
};

/// Which level each chunk is drawn at for one camera (select_lod_levels).
struct LodSelection {
  /// One entry per chunk (LodSet::chunks()): the level drawn, or -1 for a chunk outside the view.
  std::vector<int> chunk_levels;
  uint64_t splats = 0;           ///< Gaussians drawn: the chosen slices' counts plus the environment's
  uint64_t coarsest_splats = 0;  ///< what the chunks in view cost at their coarsest, plus the environment
  /// The Gaussians drawn exceed the budget: it is below what the chunks in view need at their coarsest.
  bool over_budget = false;
};

/// An opened lod-meta.json: the index, read and checked in full; the chunk files are read when a level or
/// a selection needs them, each decoded once and kept while the cache's byte limit allows. Its const
/// functions may run on several threads at once (the cache is locked; a LodStreamer loads on its own).
class TILESPLAT_API LodSet {
 public:
  /// Reads and checks the index (version 1, or the older unversioned one): levels, per-level counts
  /// (which must equal the tree's), file names beside it, the tree's slices. The chunk files are not
  /// read. Throws SceneError naming the file and what is wrong.
  static LodSet open(const std::filesystem::path& index_path);
  /// The same checks on an index already in memory; `index_path` names it and locates its files.
  static LodSet parse(std::string_view json_text, const std::filesystem::path& index_path);

  LodSet(LodSet&&) noexcept;             ///< moves the index and the cache
  LodSet& operator=(LodSet&&) noexcept;  ///< moves the index and the cache
  ~LodSet();

  const std::filesystem::path& index_path() const;  ///< the lod-meta.json it was opened from
  int levels() const;                               ///< the number of levels, at least 1
  uint64_t level_size(int level) const;             ///< Gaussians at a level, the environment not counted
  const std::vector<LodChunk>& chunks() const;      ///< the tree's leaves, in the index's order
  const std::vector<std::string>& files() const;    ///< chunk file names, relative to the index
  const std::optional<std::string>& environment() const;  ///< a file drawn at every level (sky, far field)
  /// Gaussians in the environment file (0 without one); reads it, once, into the cache.
  uint64_t environment_size() const;
  std::string generator() const;  ///< asset.generator, or empty

  /// Every chunk at `level` (0 the finest), then the environment: the scene that level draws, in the
  /// index's chunk order. Throws SceneError for a level that does not exist, a chunk file that is missing
  /// or unreadable, or one that holds fewer Gaussians than the index's slices of it.
  GaussianScene load_level(int level, const LoadOptions& options = {}) const;
  /// The chunks at the levels `selection` chose, then the environment (chunks at -1 are left out).
  GaussianScene load_selection(const LodSelection& selection, const LoadOptions& options = {}) const;

  /// The decoded chunk files kept between loads stay within this many bytes (default 2 GiB); the least
  /// recently used go first. 0 keeps none.
  void set_cache_bytes(uint64_t bytes);
  uint64_t cached_bytes() const;  ///< what the cache holds now

 private:
  struct Impl;
  explicit LodSet(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// Whether the path names a LOD set's index: a .json whose top level has "lodLevels", "filenames" and
/// "tree" (what splat-transform writes as lod-meta.json).
TILESPLAT_API bool is_lod_set(const std::filesystem::path& path);

/// The levels a camera draws under a splat budget, as streaming viewers choose them. Chunks whose box lies
/// wholly outside the camera's view are left out (-1). The rest start at their coarsest level, and the chunk
/// whose drawn Gaussians cover the most pixels each (its box's projected area over its count at its
/// current level) moves one level finer while the total stays within `splat_budget`, until none can.
/// A budget of at least the finest total draws every chunk in view at level 0. Ties go to the lower chunk
/// index, so the choice is deterministic. Cameras other than the pinhole keep every chunk (no culling).
TILESPLAT_API LodSelection select_lod_levels(const LodSet& set, const Camera& camera, uint64_t splat_budget);

/// A scene a LodStreamer loaded: the selection it holds and its Gaussians (LodSet::load_selection's).
struct LodLoad {
  LodSelection selection;  ///< the levels chosen for the camera of the request
  GaussianScene scene;     ///< those levels' Gaussians, then the environment
  double load_ms = 0;      ///< the time the streamer's thread took to read and gather them
};

/// Loads the levels a moving camera calls for on a thread of its own, as streaming viewers do: the caller
/// asks for each frame's camera and goes on drawing the scene it has until the new levels are read, then
/// takes them. Requests come faster than files are read, so only the newest waits: a request replaces one
/// queued before it that has not started, and one whose levels equal the newest requested is no request.
///
/// The functions are called from one thread (the caller's); the loads run on the streamer's. The set must
/// outlive the streamer, whose destructor waits for a load in flight (a file is not read half).
class TILESPLAT_API LodStreamer {
 public:
  /// `on_loaded`, if set, runs on the streamer's thread after each load, finished or failed, once take()
  /// can have it and before wait_and_take() returns (a viewer wakes its event loop with it:
  /// glfwPostEmptyEvent); it must not call back into the streamer.
  LodStreamer(const LodSet& set, uint64_t splat_budget, LoadOptions options = {},
              std::function<void()> on_loaded = {});
  ~LodStreamer();
  LodStreamer(const LodStreamer&) = delete;
  LodStreamer& operator=(const LodStreamer&) = delete;

  /// The levels `camera` calls for under the budget (select_lod_levels). Queued for loading unless they
  /// equal the newest levels requested. Returns the selection, to show what is being drawn or loaded.
  LodSelection request(const Camera& camera);
  /// The newest load finished since the last take, or nothing. Rethrows the SceneError of a failed load
  /// (once; its levels may then be requested again).
  std::optional<LodLoad> take();
  /// Waits until nothing is queued or loading, then takes (a first frame, a screenshot, a test).
  std::optional<LodLoad> wait_and_take();
  /// Whether a load is queued or running.
  bool busy() const;
  uint64_t splat_budget() const;  ///< the budget requests are chosen under

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tilesplat
