// The format readers behind load_scene() and parse_scene(), one source file each. Each decodes a
// file already in memory into the engine's GaussianScene and ends with finish_scene(); each throws
// SceneError naming the file (`name`) and the problem. Formats that refer to other files take a
// FileLoader for them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "scene/ply_header.h"
#include "tilesplat/scene.h"

namespace tilesplat::detail {

// Reads a file that another one names (an unbundled SOG's WebP image, a .gltf's buffer), by the
// name as written there; throws SceneError when it cannot.
using FileLoader = std::function<std::vector<unsigned char>(const std::string& name)>;

class FileContents;  // scene/scene_reading.h

// What a file's header declares (SPZ's, a SOG's meta.json): its Gaussians and their SH degree, for sizing a
// read before it is made (SceneInParts::whole_scene_bytes).
struct DeclaredCounts {
  size_t count = 0;
  int sh_degree = 0;
  // The bytes of the GaussianScene arrays such a file fills.
  uint64_t scene_bytes() const {
    return uint64_t(count) * (11 + 3 * uint64_t((sh_degree + 1) * (sh_degree + 1))) * sizeof(float);
  }
};

// The container a file's first bytes name: the reader they call for (load_scene, SceneInParts). A JSON
// object may be a glTF, a SOG's meta.json or a LOD set's index; kUnknown may still be a headerless .splat.
enum class Container { kPly, kSpz, kZip, kGlb, kJson, kKsplat, kRad, kUnknown };
Container container_of(std::span<const std::byte> data);

// Reads a file that `referrer` names, resolved beside it; only plain relative names are followed.
FileLoader sibling_loader(const std::filesystem::path& referrer);

// A 3DGS PLY from an open file: parse_ply, letting go of the file's pages as the vertex rows are decoded
// (FileContents::release_before), so that a big file and its decoded arrays are never both resident.
GaussianScene read_ply_file(FileContents& contents, std::string_view name, const LoadOptions& options,
                            LoadReport* report);

// PlayCanvas compressed PLY: a 'chunk' element of per-256-splat bounds, a 'vertex' element of
// packed_* uint32 fields and an optional 'sh' element of uint8 coefficients.
bool is_compressed_ply(const PlyHeader& header);
GaussianScene read_compressed_ply(const PlyBytes& ply, const PlyHeader& header, const LoadOptions& options,
                                  LoadReport* report);

// antimatter15 .splat: 32 bytes a Gaussian, no header.
GaussianScene read_splat(std::span<const std::byte> data, std::string_view name, const LoadOptions& options,
                         LoadReport* report);

// GaussianSplats3D .ksplat: a 4096-byte header, 1024 bytes a section, then the sections' buckets and splats
// at compression level 0 (float32), 1 (float16) or 2 (float16, 8-bit SH).
bool is_ksplat(std::span<const std::byte> data);  // version 0.x, the header's unused bytes zero
GaussianScene read_ksplat(std::span<const std::byte> data, std::string_view name, const LoadOptions& options,
                          LoadReport* report);

// Spark 2 .rad (RAD0, or one RADC chunk): every splat, or a LOD tree's leaves; `load_chunk` reads the chunk
// files a chunked one names (nullptr: such a file is an error).
GaussianScene read_rad(std::span<const std::byte> data, std::string_view name, const FileLoader& load_chunk,
                       const LoadOptions& options, LoadReport* report);

// Niantic .spz: versions 2 and 3 (gzip, or the same bytes uncompressed) and 4 (zstd streams).
bool is_spz(std::span<const std::byte> data);  // the NGSP magic, or a gzip stream
// `file`, where given, is where `data` is mapped from: its pages are let go of as they are decompressed.
GaussianScene read_spz(std::span<const std::byte> data, std::string_view name, const LoadOptions& options,
                       LoadReport* report, FileContents* file = nullptr);

// PlayCanvas SOG: a zip of meta.json and WebP images, or meta.json with the images beside it.
GaussianScene read_sog_zip(std::span<const std::byte> data, std::string_view name, const LoadOptions& options,
                           LoadReport* report);
bool is_sog_meta(std::string_view json_text);  // a JSON object with SOG's "means" and "quats"
GaussianScene read_sog_meta(std::string_view meta_json, std::string_view name, const FileLoader& load_image,
                            const LoadOptions& options, LoadReport* report);

// splat-transform's LOD set index (lod-meta.json, tilesplat/lod_set.h): a JSON object with "lodLevels",
// "filenames" and "tree". load_scene reads it as its level 0.
bool is_lod_index(std::string_view json_text);

// glTF 2.0 with KHR_gaussian_splatting: binary .glb, or JSON .gltf whose buffers are data: URIs or
// files that `load_buffer` reads (nullptr: external buffers are an error).
GaussianScene read_gltf(std::span<const std::byte> data, std::string_view name, const FileLoader& load_buffer,
                        const LoadOptions& options, LoadReport* report);

}  // namespace tilesplat::detail
