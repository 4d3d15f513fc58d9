// The container layer of glTF 2.0 (.glb and .gltf), under gltf_reader.cpp: the GLB chunks, buffer URIs
// (base64 data: URIs and percent-encoded file names) and node transforms. Every error names the file
// (detail::fail).
#pragma once

#include <array>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tilesplat::detail {

inline constexpr uint32_t kGlbMagic = 0x46546c67;  // "glTF"

// A GLB's JSON chunk and its first BIN chunk (if any), pointing into the file's bytes.
struct GlbChunks {
  std::string_view json;
  std::optional<std::span<const unsigned char>> bin;
};
GlbChunks split_glb(std::string_view name, const unsigned char* bytes, size_t size);

// The bytes of a base64 data: URI's payload.
std::vector<unsigned char> decode_base64(std::string_view name, std::string_view text);

// A relative URI reference names its file with reserved characters percent-encoded (glTF 2.0,
// "URIs"): "scene%20data.bin" is the file "scene data.bin".
std::string percent_decoded(std::string_view name, const std::string& uri, size_t buffer_index);

using Matrix4 = std::array<double, 16>;  // column-major, as glTF writes it
inline constexpr Matrix4 kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
Matrix4 multiply(const Matrix4& a, const Matrix4& b);
// A node's transform: its matrix, or its translation, rotation and scale (TRS).
Matrix4 local_matrix(std::string_view name, const nlohmann::json& node);

}  // namespace tilesplat::detail
