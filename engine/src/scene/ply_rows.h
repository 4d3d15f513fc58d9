// A binary 3DGS PLY's vertex rows, decoded on demand rather than all at once: what MappedPly reads a
// scene part by part with. The decoding is load_ply's own (ply_reader.cpp), so a row comes out as
// load_ply gives it, bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "tilesplat/scene.h"

namespace tilesplat::detail {

class PlyReader;

class PlyRows {
 public:
  // Parses and checks the header and the layout of the `size` bytes at `bytes` (which must outlive this),
  // a binary PLY of 3DGS vertices; fails (SceneError naming `name`) for anything else, an ASCII or a
  // compressed PLY included.
  PlyRows(std::string name, const unsigned char* bytes, size_t size, const LoadOptions& options);
  ~PlyRows();
  PlyRows(const PlyRows&) = delete;
  PlyRows& operator=(const PlyRows&) = delete;

  size_t rows() const;  // the vertices the file holds, non-finite ones included
  // How many rows load_ply decodes before it lets go of the file's pages (64 MiB of them).
  size_t rows_per_block() const;
  int sh_degree() const;
  bool has_normals() const;

  // Rows [first, end) into `scene` (allocated here) from slot 0, leaving out those with a non-finite value
  // as load_ply does (their row numbers appended to `dropped`; strict: SceneError); returns the slots
  // filled. The rotations are as the file has them (not normalized).
  size_t decode_range(size_t first, size_t end, GaussianScene& scene, std::vector<size_t>& dropped);
  // The rows `rows` (each finite, as decode_range found them) as a scene of their own, rotations
  // normalized: the Gaussians load_ply gives for them, bit for bit. Safe to call from another thread
  // while nothing else decodes.
  GaussianScene decode(std::span<const uint64_t> rows) const;
  // What the decode_range calls dropped, as load_ply reports it.
  LoadReport take_report();

 private:
  std::string name_;
  LoadOptions options_;
  std::unique_ptr<PlyReader> reader_;
};

}  // namespace tilesplat::detail
