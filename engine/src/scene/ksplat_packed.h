// A .ksplat file's layout, parsed and checked once: what read_ksplat decodes whole, and what a scene read in
// parts from a .ksplat decodes a part at a time (SceneInParts). Every splat has a fixed place in the file (its
// section's data, its bucket's centre), so each one decodes alone and a part gathers any of them; the bytes
// stay the file's (mapped), only the layout is held.
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

class KsplatPacked {
 public:
  // Parses and checks the headers and the buckets of `data`, which must outlive this object. Throws
  // SceneError naming `name` and the broken part.
  KsplatPacked(std::span<const std::byte> data, std::string_view name);

  size_t size() const { return size_; }
  int sh_degree() const { return sh_degree_; }
  // What LoadReport says of the file: "ksplat level N (layout)" and "major.minor".
  std::string format() const;
  std::string version() const;
  DeclaredCounts counts() const { return {size_, sh_degree_}; }

  // Splats `indices` (ascending) as read_ksplat decodes them, before finish_scene.
  GaussianScene decode(std::span<const uint32_t> indices) const;
  // Splats [first, end).
  GaussianScene decode_range(size_t first, size_t end) const;

  struct Section {
    uint32_t splats = 0;
    uint32_t bucket_size = 0, buckets = 0, full_buckets = 0, partial_buckets = 0;
    float block_size = 0;
    uint32_t bucket_bytes = 0;
    uint32_t position_range = 0;
    int sh_degree = 0;
    uint64_t bytes_per_splat = 0;
    uint64_t begin = 0;        // the section's first byte in the file
    size_t first_splat = 0;    // its first splat's index in the file
    std::vector<uint32_t> partial_ends;  // the splats before each partly full bucket's end, in the section
    uint64_t bytes() const;
  };

 private:
  template <typename IndexOf>
  GaussianScene decode_each(size_t count, IndexOf index_of) const;
  void decode_splat(size_t index, size_t out, GaussianScene& scene) const;

  const unsigned char* bytes_ = nullptr;
  unsigned major_ = 0, minor_ = 0, level_ = 0;
  float sh_min_ = 0, sh_max_ = 0;
  size_t size_ = 0;
  int sh_degree_ = 0;
  std::vector<Section> sections_;
};

}  // namespace tilesplat::detail
