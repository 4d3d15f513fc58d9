// splat-transform's streamed SOG index (lod-meta.json), version 1 and the unversioned one before it:
//   lodLevels   the number of levels (level 0 the finest)
//   counts      optional: Gaussians per level, which must equal the tree's
//   filenames   the chunk files, beside the index (each an unbundled SOG meta.json as splat-transform
//               writes them; any format load_scene reads will do)
//   environment optional: a file drawn with every level (splat-transform's LOD -1: sky, far field)
//   tree        a binary tree of {bound: {min, max}, children: [...]} down to leaves that hold
//               {lods: {"L": {file, offset, count}}}: the leaf's Gaussians at level L are Gaussians
//               [offset, offset + count) of filenames[file]
// Other keys (asset, lodErrors, ...) are ignored. A chunk file is decoded once and kept in a
// least-recently-used cache under a byte limit, so a camera path that revisits chunks does not read
// them again.
#include "tilesplat/lod_set.h"

#include <algorithm>
#include <cmath>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/scene_merge.h"
#include "scene/scene_readers.h"
#include "scene/scene_reading.h"

namespace tilesplat {

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// Far past any real set; bounds what a malformed index can make the reader allocate or recurse into.
constexpr int kMaxLevels = 64;
constexpr int kMaxTreeDepth = 128;
constexpr uint64_t kMaxGaussians = uint64_t(1) << 40;

class IndexParser {
 public:
  IndexParser(std::string name, int levels, size_t files)
      : name_(std::move(name)), levels_(levels), files_(files) {}

  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    detail::fail(name_, where + ": " + what);
  }

  uint64_t whole_number(const json& value, const std::string& where, uint64_t limit) const {
    if (!value.is_number_unsigned()) fail(where, "must be a whole number of at least 0");
    const uint64_t number = value.get<uint64_t>();
    if (number > limit) fail(where, std::to_string(number) + " is out of range");
    return number;
  }

  uint64_t count(const json& object, const char* key, const std::string& where, uint64_t limit) const {
    if (!object.contains(key)) fail(where, std::string("has no '") + key + "'");
    return whole_number(object.at(key), where + "." + key, limit);
  }

  std::array<double, 3> point(const json& bound, const char* key, const std::string& where) const {
    if (!bound.contains(key) || !bound.at(key).is_array() || bound.at(key).size() != 3)
      fail(where, std::string("needs '") + key + "' as an array of 3 numbers");
    std::array<double, 3> out{};
    for (size_t a = 0; a < 3; ++a) {
      const json& value = bound.at(key)[a];
      if (!value.is_number() || !std::isfinite(value.get<double>()))
        fail(where + "." + key, "holds a value that is not a finite number");
      out[a] = value.get<double>();
    }
    return out;
  }

  // Appends the leaves under `node` (depth first, as the index lists them) to `chunks`.
  void read_node(const json& node, const std::string& where, int depth, std::vector<LodChunk>& chunks) const {
    if (depth > kMaxTreeDepth)
      fail(where, "the tree is deeper than " + std::to_string(kMaxTreeDepth) + " levels");
    if (!node.is_object()) fail(where, "must be an object");
    if (node.contains("lods")) chunks.push_back(read_leaf(node, where));
    if (!node.contains("children")) return;
    const json& children = node.at("children");
    if (!children.is_array()) fail(where + ".children", "must be an array");
    for (size_t i = 0; i < children.size(); ++i)
      read_node(children[i], where + ".children[" + std::to_string(i) + "]", depth + 1, chunks);
  }

  LodChunk read_leaf(const json& node, const std::string& where) const {
    LodChunk chunk;
    if (!node.contains("bound") || !node.at("bound").is_object())
      fail(where, "a leaf (it has 'lods') needs 'bound': {min, max}");
    const json& bound = node.at("bound");
    chunk.min = point(bound, "min", where + ".bound");
    chunk.max = point(bound, "max", where + ".bound");
    for (size_t a = 0; a < 3; ++a)
      if (chunk.min[a] > chunk.max[a]) fail(where + ".bound", "min is above max");
    chunk.levels.assign(size_t(levels_), LodSlice{});
    const json& lods = node.at("lods");
    if (!lods.is_object()) fail(where + ".lods", "must be an object of levels");
    for (const auto& [key, ref] : lods.items()) {
      const std::string at = where + ".lods." + key;
      int level = -1;
      if (!key.empty() && key.size() <= 2 &&
          std::all_of(key.begin(), key.end(), [](char c) { return c >= '0' && c <= '9'; }))
        level = std::stoi(key);
      if (level < 0 || level >= levels_)
        fail(at, "not a level of the set (0 to " + std::to_string(levels_ - 1) + ")");
      if (!ref.is_object()) fail(at, "must be an object {file, offset, count}");
      LodSlice& slice = chunk.levels[size_t(level)];
      slice.file = static_cast<uint32_t>(count(ref, "file", at, files_ == 0 ? 0 : files_ - 1));
      if (files_ == 0) fail(at, "names a file, and 'filenames' is empty");
      slice.offset = count(ref, "offset", at, kMaxGaussians);
      slice.count = count(ref, "count", at, kMaxGaussians);
    }
    return chunk;
  }

 private:
  std::string name_;
  int levels_;
  size_t files_;
};

// Decoded chunk files, least recently used first out. Entries are shared: one evicted while a load
// still uses it lives until that load is done. Not locked itself: LodSet::Impl guards it.
class ChunkCache {
 public:
  using Scene = std::shared_ptr<const GaussianScene>;

  Scene find(uint32_t file) {
    const auto found = entries_.find(file);
    if (found == entries_.end()) return nullptr;
    order_.splice(order_.end(), order_, found->second.position);
    return found->second.scene;
  }

  // Keeps `scene` unless it alone is over the limit, evicting the least recently used to make room.
  // Returns the file's scene as the cache has it: one that another thread decoded and kept first wins,
  // so that every load shares one copy.
  Scene insert(uint32_t file, Scene scene) {
    if (Scene kept = find(file)) return kept;
    const uint64_t bytes = bytes_of(*scene);
    if (bytes > limit_) return scene;
    while (!order_.empty() && held_ + bytes > limit_) evict_oldest();
    order_.push_back(file);
    entries_[file] = Entry{scene, bytes, std::prev(order_.end())};
    held_ += bytes;
    return scene;
  }

  void set_limit(uint64_t bytes) {
    limit_ = bytes;
    while (!order_.empty() && held_ > limit_) evict_oldest();
  }
  uint64_t held() const { return held_; }

 private:
  struct Entry {
    Scene scene;
    uint64_t bytes = 0;
    std::list<uint32_t>::iterator position;
  };

  static uint64_t bytes_of(const GaussianScene& scene) {
    return sizeof(float) * (scene.positions.size() + scene.log_scales.size() + scene.rotations.size() +
                            scene.opacity_logits.size() + scene.sh.size() + scene.normals.size());
  }

  void evict_oldest() {
    const auto found = entries_.find(order_.front());
    held_ -= found->second.bytes;
    entries_.erase(found);
    order_.pop_front();
  }

  std::map<uint32_t, Entry> entries_;
  std::list<uint32_t> order_;
  uint64_t held_ = 0;
  uint64_t limit_ = uint64_t(2) << 30;
};

}  // namespace

struct LodSet::Impl {
  fs::path index_path;
  int levels = 0;
  std::vector<uint64_t> level_sizes;
  std::vector<LodChunk> chunks;
  std::vector<std::string> files;
  std::optional<std::string> environment;
  std::string generator;
  // What the cache is keyed by for the environment: one past the chunk files.
  uint32_t environment_key() const { return static_cast<uint32_t>(files.size()); }
  // Several threads may load at once (LodStreamer's, a renderer's, the caller's): the cache is locked
  // for its lookups and insertions only, never while a file is decoded.
  mutable std::mutex cache_mutex;
  mutable ChunkCache cache;

  [[noreturn]] void fail(const std::string& what) const { detail::fail(index_path.string(), what); }

  // The decoded file (a chunk file, or environment_key()): from the cache, else read now. A file that a
  // reader had to drop Gaussians from is refused: the index's offsets count every Gaussian of it.
  std::shared_ptr<const GaussianScene> decoded(uint32_t file, const LoadOptions& options) const {
    const std::string& name = file == environment_key() ? *environment : files[file];
    {
      const std::lock_guard lock(cache_mutex);
      if (auto cached = cache.find(file)) return cached;
    }
    const fs::path path = index_path.parent_path() / name;
    // A chunk that is itself an index would read the set again, and again.
    if (is_lod_set(path)) fail("the chunk file '" + name + "' is itself a LOD set index");
    LoadReport report;
    GaussianScene scene;
    try {
      scene = load_scene(path, options, &report);
    } catch (const SceneError& error) {
      fail("the chunk file '" + name + "' cannot be read (" + error.what() + ")");
    }
    if (report.dropped > 0)
      fail("the chunk file '" + name + "' has " + std::to_string(report.dropped) +
           " Gaussians with non-finite values; the index's offsets need every one of them");
    const std::lock_guard lock(cache_mutex);
    return cache.insert(file, std::make_shared<const GaussianScene>(std::move(scene)));
  }

  // The chunks at `chunk_levels` (-1: left out), then the environment.
  GaussianScene gather(const std::vector<int>& chunk_levels, const LoadOptions& options) const {
    std::map<uint32_t, std::shared_ptr<const GaussianScene>> used;
    uint64_t total = 0;
    for (size_t c = 0; c < chunks.size(); ++c) {
      if (chunk_levels[c] < 0) continue;
      const LodSlice& slice = chunks[c].levels[size_t(chunk_levels[c])];
      if (slice.count == 0) continue;
      auto& scene = used[slice.file];
      if (!scene) scene = decoded(slice.file, options);
      if (slice.offset > scene->size() || slice.count > scene->size() - slice.offset)
        fail("chunk " + std::to_string(c) + " takes Gaussians " + std::to_string(slice.offset) + " to " +
             std::to_string(slice.offset + slice.count) + " of '" + files[slice.file] + "', which holds " +
             std::to_string(scene->size()));
      total += slice.count;
    }
    std::shared_ptr<const GaussianScene> environment_scene;
    if (environment) {
      environment_scene = decoded(environment_key(), options);
      total += environment_scene->size();
    }
    int sh_degree = 0;
    bool normals = false;
    for (const auto& [file, scene] : used) {
      sh_degree = std::max(sh_degree, scene->sh_degree);
      normals = normals || scene->has_normals();
    }
    if (environment_scene) {
      sh_degree = std::max(sh_degree, environment_scene->sh_degree);
      normals = normals || environment_scene->has_normals();
    }
    GaussianScene out;
    detail::reserve_merged(out, total, sh_degree, normals);
    for (size_t c = 0; c < chunks.size(); ++c) {
      if (chunk_levels[c] < 0) continue;
      const LodSlice& slice = chunks[c].levels[size_t(chunk_levels[c])];
      if (slice.count > 0)
        detail::append_merged(out, *used.at(slice.file), normals, slice.offset, slice.count);
    }
    if (environment_scene) detail::append_merged(out, *environment_scene, normals);
    return out;
  }
};

LodSet::LodSet(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
LodSet::LodSet(LodSet&&) noexcept = default;
LodSet& LodSet::operator=(LodSet&&) noexcept = default;
LodSet::~LodSet() = default;

LodSet LodSet::open(const fs::path& index_path) {
  detail::FileContents contents;
  detail::open_scene_file(index_path, contents);
  return parse(std::string_view(reinterpret_cast<const char*>(contents.data()), contents.size()), index_path);
}

LodSet LodSet::parse(std::string_view json_text, const fs::path& index_path) {
  const std::string name = index_path.string();
  const json root = json::parse(json_text.begin(), json_text.end(), nullptr, false);
  if (root.is_discarded()) detail::fail(name, "not a LOD set index: the file is not valid JSON");
  if (!root.is_object()) detail::fail(name, "not a LOD set index: the top level is not an object");
  auto impl = std::make_unique<Impl>();
  impl->index_path = index_path;
  if (root.contains("version") && root.at("version") != 1)
    detail::fail(name, "LOD set index version " + root.at("version").dump() +
                           " is not supported (this reader knows 1)");

  const IndexParser top(name, kMaxLevels, 0);
  impl->levels = static_cast<int>(top.count(root, "lodLevels", "the index", kMaxLevels));
  if (impl->levels < 1) top.fail("lodLevels", "must be at least 1");

  if (!root.contains("filenames") || !root.at("filenames").is_array())
    detail::fail(name, "the index needs 'filenames', an array of the chunk files");
  for (const json& file : root.at("filenames")) {
    if (!file.is_string()) top.fail("filenames", "holds a value that is not a file name");
    const std::string file_name = file.get<std::string>();
    if (!detail::is_path_beside(file_name))
      top.fail("filenames", "'" + file_name + "' is not a path beside the index");
    impl->files.push_back(file_name);
  }
  if (root.contains("environment") && !root.at("environment").is_null()) {
    const json& environment = root.at("environment");
    if (!environment.is_string() || !detail::is_path_beside(environment.get<std::string>()))
      top.fail("environment", "must be the name of a file beside the index");
    impl->environment = environment.get<std::string>();
  }
  if (root.contains("asset") && root.at("asset").is_object() && root.at("asset").contains("generator") &&
      root.at("asset").at("generator").is_string())
    impl->generator = root.at("asset").at("generator").get<std::string>();

  if (!root.contains("tree")) detail::fail(name, "the index has no 'tree' of chunks");
  const IndexParser tree(name, impl->levels, impl->files.size());
  tree.read_node(root.at("tree"), "tree", 0, impl->chunks);

  impl->level_sizes.assign(size_t(impl->levels), 0);
  for (const LodChunk& chunk : impl->chunks)
    for (size_t level = 0; level < chunk.levels.size(); ++level) {
      impl->level_sizes[level] += chunk.levels[level].count;
      if (impl->level_sizes[level] > kMaxGaussians)
        top.fail("tree", "level " + std::to_string(level) + " holds more Gaussians than any scene can");
    }
  if (root.contains("counts")) {
    const json& counts = root.at("counts");
    if (!counts.is_array() || counts.size() != size_t(impl->levels))
      top.fail("counts", "must hold one count per level (" + std::to_string(impl->levels) + ")");
    for (size_t level = 0; level < counts.size(); ++level) {
      const uint64_t declared =
          top.whole_number(counts[level], "counts[" + std::to_string(level) + "]", kMaxGaussians);
      if (declared != impl->level_sizes[level])
        top.fail("counts[" + std::to_string(level) + "]", "says " + std::to_string(declared) +
                                                              " Gaussians, and the tree's chunks hold " +
                                                              std::to_string(impl->level_sizes[level]));
    }
  }
  return LodSet(std::move(impl));
}

const fs::path& LodSet::index_path() const {
  return impl_->index_path;
}
int LodSet::levels() const {
  return impl_->levels;
}
const std::vector<LodChunk>& LodSet::chunks() const {
  return impl_->chunks;
}
const std::vector<std::string>& LodSet::files() const {
  return impl_->files;
}
const std::optional<std::string>& LodSet::environment() const {
  return impl_->environment;
}
std::string LodSet::generator() const {
  return impl_->generator;
}

uint64_t LodSet::level_size(int level) const {
  if (level < 0 || level >= impl_->levels)
    impl_->fail("there is no level " + std::to_string(level) + " (the set has levels 0 to " +
                std::to_string(impl_->levels - 1) + ")");
  return impl_->level_sizes[size_t(level)];
}

uint64_t LodSet::environment_size() const {
  if (!impl_->environment) return 0;
  return impl_->decoded(impl_->environment_key(), {})->size();
}

GaussianScene LodSet::load_level(int level, const LoadOptions& options) const {
  level_size(level);  // throws for a level the set does not have
  return impl_->gather(std::vector<int>(impl_->chunks.size(), level), options);
}

GaussianScene LodSet::load_selection(const LodSelection& selection, const LoadOptions& options) const {
  if (selection.chunk_levels.size() != impl_->chunks.size())
    impl_->fail("the selection has " + std::to_string(selection.chunk_levels.size()) + " chunks, the set " +
                std::to_string(impl_->chunks.size()));
  for (const int level : selection.chunk_levels)
    if (level >= impl_->levels || level < -1) level_size(level);  // throws naming the level
  return impl_->gather(selection.chunk_levels, options);
}

void LodSet::set_cache_bytes(uint64_t bytes) {
  const std::lock_guard lock(impl_->cache_mutex);
  impl_->cache.set_limit(bytes);
}
uint64_t LodSet::cached_bytes() const {
  const std::lock_guard lock(impl_->cache_mutex);
  return impl_->cache.held();
}

bool is_lod_set(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (extension != ".json") return false;
  detail::FileContents contents;
  if (!contents.open(path).empty()) return false;
  return detail::is_lod_index(
      std::string_view(reinterpret_cast<const char*>(contents.data()), contents.size()));
}

namespace detail {

bool is_lod_index(std::string_view json_text) {
  const json root = json::parse(json_text.begin(), json_text.end(), nullptr, false);
  return root.is_object() && root.contains("lodLevels") && root.contains("filenames") &&
         root.contains("tree");
}

}  // namespace detail

}  // namespace tilesplat
