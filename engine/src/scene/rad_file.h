// Spark 2's .rad files (sparkjsdev/spark, rust/spark-lib/src/rad.rs), decoded whole: what read_rad turns into
// a scene and what SplatLodTree cuts into levels.
//
// A file is "RAD0", a uint32 length and that much JSON (version 1, type "gsplat", count, maxSh, lodTree,
// chunkSize, the chunks' byte ranges, an optional SH codebook size), padded to 8 bytes; then its chunks, each in
// the file or, where the range names one, in a .radc file beside it. A chunk is "RADC", a uint32 length and
// that much JSON (base, count, payloadBytes and its properties' offset, bytes, encoding, compression and
// range), padded to 8, a uint64 payload size, then each property's bytes, raw deflate ("gz"), padded to 8.
// Properties are stored planar (all x, then all y, ...): center, alpha (opacity after the sigmoid; up to 2
// in a LOD tree, where above 1 it widens the kernel), rgb (0.5 + SH_C0 dc), scales (linear), orientation,
// sh1..sh3 (coefficient-major RGB) or an SH codebook and labels, and in a LOD tree child_count and
// child_start: node i's children are [child_start, child_start + child_count), the root is node 0.
// Positions are in the file's own axes, the trainer's as Spark reads a PLY.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "scene/scene_readers.h"
#include "tilesplat/scene.h"

namespace tilesplat::detail {

bool is_rad(std::span<const std::byte> data);  // the RAD0 or RADC magic

class RadFile {
 public:
  // Decodes every splat of a .rad (or of one .radc chunk); `load_chunk` reads chunk files the header names
  // (nullptr: such a file is an error). Throws SceneError naming `name` and the broken part.
  RadFile(std::span<const std::byte> data, std::string_view name, const FileLoader& load_chunk);

  // Chunk `chunk` of a .rad alone (its splats numbered from 0; child indices stay the file's), for reading a
  // file a chunk at a time (RadPartRows). `codebook`: the file's SH codebook (chunk 0's sh_codes(), which a
  // later chunk's labels index). The tree is not checked: the whole file's read does that.
  static RadFile chunk_of(std::span<const std::byte> data, std::string_view name, const FileLoader& load_chunk,
                          size_t chunk, const std::vector<float>& codebook = {});
  // A .rad's chunk count and splats a chunk, from its header alone (a lone .radc: 1 and its count).
  struct Chunking {
    size_t chunks = 0;
    size_t chunk_size = 0;
    size_t count = 0;
    int sh_degree = 0;
  };
  static Chunking chunking_of(std::span<const std::byte> data, std::string_view name);
  const std::vector<float>& sh_codes() const { return sh_codes_; }
  // What a LoadReport says of a .rad, from its header and the first chunk read: a value that a reader taking the
  // file a chunk at a time keeps from its first chunk.
  struct Description {
    size_t chunks = 0;
    size_t splats = 0;      // every splat of the file (a lone .radc: its own), a tree's inner nodes too
    bool lod_tree = false;
    std::string encodings;  // "center f32_lebytes, alpha f16, ...", as the first chunk read names them
    // "rad (N chunks; LOD tree of N splats, its M leaves read; encodings)"
    std::string format(size_t leaves) const;
  };
  const Description& description() const { return description_; }
  // The checks the whole read makes of a tree, for child arrays gathered a chunk at a time.
  static void check_tree_of(std::string_view name, std::span<const uint32_t> child_count,
                            std::span<const uint32_t> child_start);

  size_t size() const { return alpha_.size(); }
  int sh_degree() const { return sh_degree_; }
  bool has_lod_tree() const { return !child_count_.empty(); }

  uint32_t child_count(size_t node) const { return child_count_[node]; }
  uint32_t child_start(size_t node) const { return child_start_[node]; }
  // A node's extent as Spark's LOD traversal measures it: 2 x its mean scale, widened where alpha > 1.
  double node_size(size_t node) const;
  const float* center(size_t node) const { return centers_.data() + 3 * node; }
  // Nodes without children, ascending: the source's Gaussians in a LOD tree (every splat without one).
  std::vector<uint32_t> leaves() const;

  // Splats `nodes` as Gaussians, before finish_scene. An alpha above 1 (a LOD tree's merged node) becomes
  // opacity 1 and scales widened by a^(1/3), a = exp(((4 alpha - 3)^2 - 1) / e): Spark's own "inflate" of
  // its wider kernel, which the engine's Gaussian kernel then draws. A zero scale (Spark's "below e^-30")
  // is read as e^-30.
  GaussianScene decode(std::span<const uint32_t> nodes) const;

 private:
  void read_chunk(std::span<const unsigned char> chunk, std::string_view where, size_t expected_base,
                  size_t expected_count, bool alone);
  void check_tree() const { check_tree_of(name_, child_count_, child_start_); }

  RadFile() = default;
  void read(std::span<const unsigned char> bytes, const FileLoader& load_chunk);

  std::string name_;
  // Set by chunk_of: the one chunk read, and its first splat's index in the file (its arrays start there).
  size_t only_chunk_ = SIZE_MAX;
  size_t rebase_ = 0;
  int sh_degree_ = 0;
  Description description_;
  std::vector<float> centers_, alpha_, rgb_, scales_, quats_;  // quats x y z w, as Spark keeps them
  std::vector<float> sh_;                                      // per splat (degree+1)^2-1 coefficients x RGB
  // An SH codebook (shCodeCount entries of the same layout) and each splat's entry, in place of sh_.
  std::vector<float> sh_codes_;
  std::vector<uint32_t> sh_labels_;
  size_t sh_code_count_ = 0;
  std::vector<uint32_t> child_count_, child_start_;
};

}  // namespace tilesplat::detail
