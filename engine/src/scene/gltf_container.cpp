#include "scene/gltf_container.h"

#include "scene/scene_reading.h"
#include "tilesplat/scene.h"
#include "tilesplat/scene_description.h"

namespace tilesplat::detail {

namespace {
constexpr uint32_t kJsonChunk = 0x4e4f534a;
constexpr uint32_t kBinChunk = 0x004e4942;
}  // namespace

GlbChunks split_glb(std::string_view name, const unsigned char* bytes, size_t size) {
  const auto fail = [name](const std::string& what) { detail::fail(name, what); };
  GlbChunks chunks;
  if (size < 20) fail("truncated GLB header");
  const uint32_t version = load_le<uint32_t>(bytes + 4);
  if (version != 2) fail("unsupported GLB version " + std::to_string(version) + " (supported: 2)");
  const uint32_t length = load_le<uint32_t>(bytes + 8);
  if (length > size)
    fail("truncated GLB: the header declares " + std::to_string(length) + " bytes, the file has " +
         std::to_string(size));
  size_t offset = 12;
  bool first = true;
  while (offset + 8 <= length) {
    const uint32_t chunk_length = load_le<uint32_t>(bytes + offset);
    const uint32_t chunk_type = load_le<uint32_t>(bytes + offset + 4);
    if (chunk_length > length - offset - 8)
      fail("GLB chunk at byte " + std::to_string(offset) + " runs past the end of the file");
    const unsigned char* chunk = bytes + offset + 8;
    if (first && chunk_type != kJsonChunk) fail("the first GLB chunk is not JSON");
    if (first) chunks.json = std::string_view(reinterpret_cast<const char*>(chunk), chunk_length);
    if (!first && chunk_type == kBinChunk && !chunks.bin)
      chunks.bin = std::span<const unsigned char>(chunk, chunk_length);
    first = false;
    offset += 8 + chunk_length;
  }
  if (first) fail("a GLB without a JSON chunk");
  return chunks;
}

std::vector<unsigned char> decode_base64(std::string_view name, std::string_view text) {
  std::vector<unsigned char> out;
  out.reserve(text.size() / 4 * 3);
  uint32_t bits = 0;
  int count = 0;
  for (char c : text) {
    int value;
    if (c >= 'A' && c <= 'Z')
      value = c - 'A';
    else if (c >= 'a' && c <= 'z')
      value = c - 'a' + 26;
    else if (c >= '0' && c <= '9')
      value = c - '0' + 52;
    else if (c == '+')
      value = 62;
    else if (c == '/')
      value = 63;
    else if (c == '=')
      break;
    else
      detail::fail(name, "a data: URI holds a character that is not base64");
    bits = (bits << 6) | static_cast<uint32_t>(value);
    if (++count == 4) {
      out.push_back(static_cast<unsigned char>(bits >> 16));
      out.push_back(static_cast<unsigned char>(bits >> 8));
      out.push_back(static_cast<unsigned char>(bits));
      bits = 0;
      count = 0;
    }
  }
  if (count == 2) out.push_back(static_cast<unsigned char>(bits >> 4));
  if (count == 3) {
    out.push_back(static_cast<unsigned char>(bits >> 10));
    out.push_back(static_cast<unsigned char>(bits >> 2));
  }
  return out;
}

std::string percent_decoded(std::string_view name, const std::string& uri, size_t buffer_index) {
  std::string file;
  for (size_t k = 0; k < uri.size(); ++k) {
    if (uri[k] != '%') {
      file += uri[k];
      continue;
    }
    const auto hex = [](char c) {
      return c >= '0' && c <= '9'   ? c - '0'
             : c >= 'a' && c <= 'f' ? c - 'a' + 10
             : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                    : -1;
    };
    if (k + 2 >= uri.size() || hex(uri[k + 1]) < 0 || hex(uri[k + 2]) < 0)
      detail::fail(name, "buffer " + std::to_string(buffer_index) + ": the uri '" + uri +
                             "' has a malformed percent escape");
    file += static_cast<char>(hex(uri[k + 1]) * 16 + hex(uri[k + 2]));
    k += 2;
  }
  return file;
}

Matrix4 multiply(const Matrix4& a, const Matrix4& b) {
  Matrix4 c{};
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row)
      for (int k = 0; k < 4; ++k) c[col * 4 + row] += a[k * 4 + row] * b[col * 4 + k];
  return c;
}

Matrix4 local_matrix(std::string_view name, const nlohmann::json& node) {
  const auto fail = [name](const std::string& what) { detail::fail(name, what); };
  const auto number = [&](const nlohmann::json& value, const std::string& what) {
    if (!value.is_number()) fail(what + " is not a number");
    return value.get<double>();
  };
  if (node.contains("matrix")) {
    const nlohmann::json& m = node["matrix"];
    if (!m.is_array() || m.size() != 16) fail("a node matrix must have 16 numbers");
    Matrix4 result{};
    for (size_t i = 0; i < 16; ++i) result[i] = number(m[i], "node matrix");
    return result;
  }
  std::array<double, 3> t = {0, 0, 0}, s = {1, 1, 1};
  std::array<double, 4> r = {0, 0, 0, 1};  // x y z w
  const auto read = [&](const char* key, auto& out) {
    if (!node.contains(key)) return;
    const nlohmann::json& v = node[key];
    if (!v.is_array() || v.size() != out.size()) fail(std::string("node.") + key + " has the wrong length");
    for (size_t i = 0; i < out.size(); ++i) out[i] = number(v[i], std::string("node.") + key);
  };
  read("translation", t);
  read("rotation", r);
  read("scale", s);
  const std::array<double, 9> rot = rotation_matrix({r[3], r[0], r[1], r[2]});  // row-major
  Matrix4 m{};
  for (int col = 0; col < 3; ++col)
    for (int row = 0; row < 3; ++row) m[col * 4 + row] = rot[row * 3 + col] * s[col];
  m[12] = t[0];
  m[13] = t[1];
  m[14] = t[2];
  m[15] = 1;
  return m;
}

}  // namespace tilesplat::detail
