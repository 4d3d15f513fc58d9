// The header of a PLY file, parsed once for every PLY-based reader: the 3DGS PLY reader and the
// PlayCanvas compressed PLY reader (which the header's elements tell apart).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/scene_reading.h"

namespace tilesplat::detail {

enum class ScalarType : uint8_t { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

inline size_t scalar_size(ScalarType type) {
  switch (type) {
    case ScalarType::kInt8:
    case ScalarType::kUint8:
      return 1;
    case ScalarType::kInt16:
    case ScalarType::kUint16:
      return 2;
    case ScalarType::kInt32:
    case ScalarType::kUint32:
    case ScalarType::kFloat32:
      return 4;
    case ScalarType::kFloat64:
      return 8;
  }
  return 0;
}

inline bool is_integer(ScalarType type) {
  return type != ScalarType::kFloat32 && type != ScalarType::kFloat64;
}

inline std::optional<ScalarType> parse_scalar_type(std::string_view name) {
  struct Alias {
    std::string_view name;
    ScalarType type;
  };
  static constexpr Alias kAliases[] = {
      {"char", ScalarType::kInt8},       {"int8", ScalarType::kInt8},       {"uchar", ScalarType::kUint8},
      {"uint8", ScalarType::kUint8},     {"short", ScalarType::kInt16},     {"int16", ScalarType::kInt16},
      {"ushort", ScalarType::kUint16},   {"uint16", ScalarType::kUint16},   {"int", ScalarType::kInt32},
      {"int32", ScalarType::kInt32},     {"uint", ScalarType::kUint32},     {"uint32", ScalarType::kUint32},
      {"float", ScalarType::kFloat32},   {"float32", ScalarType::kFloat32}, {"double", ScalarType::kFloat64},
      {"float64", ScalarType::kFloat64},
  };
  for (const Alias& alias : kAliases)
    if (alias.name == name) return alias.type;
  return std::nullopt;
}

enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyProperty {
  std::string name;
  ScalarType type = ScalarType::kFloat32;  // the item type for a list
  bool is_list = false;
  ScalarType list_count_type = ScalarType::kUint8;
  size_t row_offset = 0;  // byte offset inside a binary row (meaningful for list-free elements)
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
  bool has_list = false;
  size_t fixed_row_size = 0;  // bytes per item when the element has no list property
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::string format_name;
  std::vector<PlyElement> elements;
  size_t vertex_element = 0;
  size_t data_offset = 0;   // first byte after the end_header line
  size_t header_lines = 0;  // for ASCII line numbers
};

inline bool checked_multiply(uint64_t a, uint64_t b, uint64_t* product) {
  if (a != 0 && b > std::numeric_limits<uint64_t>::max() / a) return false;
  *product = a * b;
  return true;
}

template <typename T, bool kSwap>
T load_scalar(const unsigned char* bytes) {
  T value;
  if constexpr (kSwap) {
    unsigned char reversed[sizeof(T)];
    for (size_t i = 0; i < sizeof(T); ++i) reversed[i] = bytes[sizeof(T) - 1 - i];
    std::memcpy(&value, reversed, sizeof(T));
  } else {
    std::memcpy(&value, bytes, sizeof(T));
  }
  return value;
}

template <bool kSwap>
float load_as_float(const unsigned char* bytes, ScalarType type) {
  switch (type) {
    case ScalarType::kInt8:
      return static_cast<float>(load_scalar<int8_t, kSwap>(bytes));
    case ScalarType::kUint8:
      return static_cast<float>(load_scalar<uint8_t, kSwap>(bytes));
    case ScalarType::kInt16:
      return static_cast<float>(load_scalar<int16_t, kSwap>(bytes));
    case ScalarType::kUint16:
      return static_cast<float>(load_scalar<uint16_t, kSwap>(bytes));
    case ScalarType::kInt32:
      return static_cast<float>(load_scalar<int32_t, kSwap>(bytes));
    case ScalarType::kUint32:
      return static_cast<float>(load_scalar<uint32_t, kSwap>(bytes));
    case ScalarType::kFloat32:
      return load_scalar<float, kSwap>(bytes);
    case ScalarType::kFloat64:
      return to_float(load_scalar<double, kSwap>(bytes));
  }
  return 0.0f;
}

// List counts: negative counts are reported through the optional being empty.
template <bool kSwap>
std::optional<uint64_t> load_list_count(const unsigned char* bytes, ScalarType type) {
  int64_t value = 0;
  switch (type) {
    case ScalarType::kInt8:
      value = load_scalar<int8_t, kSwap>(bytes);
      break;
    case ScalarType::kUint8:
      value = load_scalar<uint8_t, kSwap>(bytes);
      break;
    case ScalarType::kInt16:
      value = load_scalar<int16_t, kSwap>(bytes);
      break;
    case ScalarType::kUint16:
      value = load_scalar<uint16_t, kSwap>(bytes);
      break;
    case ScalarType::kInt32:
      value = load_scalar<int32_t, kSwap>(bytes);
      break;
    case ScalarType::kUint32:
      value = load_scalar<uint32_t, kSwap>(bytes);
      break;
    case ScalarType::kFloat32:
    case ScalarType::kFloat64:
      return std::nullopt;  // rejected while parsing the header
  }
  if (value < 0) return std::nullopt;
  return static_cast<uint64_t>(value);
}

inline bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

// A PLY file's bytes and name, for parsing its header and walking its elements.
class PlyBytes {
 public:
  PlyBytes(std::string_view name, const unsigned char* bytes, size_t size)
      : name_(name), bytes_(bytes), size_(size) {}

  // Parses and validates the header: magic, format, elements and properties, an 'element vertex'.
  PlyHeader parse_header() const;
  // Walks one element's items of a binary file from `offset` and returns the offset after it;
  // fails on truncation. `swap`: the file's byte order is not the host's.
  size_t skip_binary_element(const PlyElement& element, size_t offset, bool swap) const;

  [[noreturn]] void fail(const std::string& what) const;
  const unsigned char* data() const { return bytes_; }
  size_t size() const { return size_; }
  std::string_view name() const { return name_; }

 private:
  std::string_view text(size_t begin, size_t end) const {
    return {reinterpret_cast<const char*>(bytes_) + begin, end - begin};
  }

  std::string_view name_;
  const unsigned char* bytes_ = nullptr;
  size_t size_ = 0;
};

}  // namespace tilesplat::detail
