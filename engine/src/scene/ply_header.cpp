// PLY header parsing and element walking, shared by the PLY readers (see ply_header.h).
#include "scene/ply_header.h"

#include <algorithm>
#include <charconv>
#include <limits>
#include <unordered_set>

#include "scene/scene_reading.h"

namespace tilesplat::detail {
namespace {

std::vector<std::string_view> split_tokens(std::string_view line) {
  std::vector<std::string_view> tokens;
  size_t pos = 0;
  while (pos < line.size()) {
    while (pos < line.size() && is_blank(line[pos])) ++pos;
    size_t end = pos;
    while (end < line.size() && !is_blank(line[end])) ++end;
    if (end > pos) tokens.push_back(line.substr(pos, end - pos));
    pos = end;
  }
  return tokens;
}

// Walks one element's items and returns the offset after it; fails on truncation.
template <bool kSwap>
size_t skip_element(const PlyBytes& ply, const PlyElement& element, size_t offset) {
  const size_t available = ply.size() - offset;
  if (!element.has_list) {
    uint64_t needed = 0;
    if (!checked_multiply(element.count, element.fixed_row_size, &needed) || needed > ply.size())
      ply.fail("element '" + element.name + "' count " + std::to_string(element.count) +
               " is impossible for this file: " + std::to_string(element.count) + " items of " +
               std::to_string(element.fixed_row_size) + " bytes need more than the whole file (" +
               std::to_string(ply.size()) + " bytes); the file is truncated or the count is wrong");
    if (needed > available)
      ply.fail("truncated binary data in element '" + element.name + "': expected " +
               std::to_string(element.count) + " items (" + std::to_string(needed) + " bytes) but only " +
               std::to_string(available) + " bytes remain; " + std::to_string(needed - available) +
               " bytes missing");
    return offset + static_cast<size_t>(needed);
  }
  // Every item takes at least one byte, so this loop is bounded by the file size.
  for (uint64_t item = 0; item < element.count; ++item) {
    for (const PlyProperty& property : element.properties) {
      const auto truncated = [&] {
        ply.fail("truncated binary data in element '" + element.name + "': the data ends in item " +
                 std::to_string(item) + " of " + std::to_string(element.count) + " (property '" +
                 property.name + "')");
      };
      if (!property.is_list) {
        const size_t item_size = scalar_size(property.type);
        if (ply.size() - offset < item_size) truncated();
        offset += item_size;
        continue;
      }
      const size_t count_size = scalar_size(property.list_count_type);
      if (ply.size() - offset < count_size) truncated();
      const std::optional<uint64_t> list_length =
          load_list_count<kSwap>(ply.data() + offset, property.list_count_type);
      if (!list_length)
        ply.fail("element '" + element.name + "' item " + std::to_string(item) +
                 " has a negative list count in '" + property.name + "'");
      offset += count_size;
      uint64_t list_bytes = 0;
      if (!checked_multiply(*list_length, scalar_size(property.type), &list_bytes) ||
          list_bytes > ply.size() - offset)
        truncated();
      offset += static_cast<size_t>(list_bytes);
    }
  }
  return offset;
}

}  // namespace

void PlyBytes::fail(const std::string& what) const {
  detail::fail(name_, what);
}

size_t PlyBytes::skip_binary_element(const PlyElement& element, size_t offset, bool swap) const {
  return swap ? skip_element<true>(*this, element, offset) : skip_element<false>(*this, element, offset);
}

PlyHeader PlyBytes::parse_header() const {
  PlyHeader header;
  // The magic is checked on raw bytes first so a binary non-PLY file fails at once.
  const bool magic_ok = size_ >= 4 && text(0, 3) == "ply" &&
                        (bytes_[3] == '\n' || (size_ >= 5 && bytes_[3] == '\r' && bytes_[4] == '\n'));
  if (!magic_ok) fail("not a PLY file (it does not start with the 'ply' magic line)");

  size_t pos = 0;
  size_t line_number = 0;
  bool have_format = false;
  bool ended = false;
  std::optional<size_t> vertex_index;
  // A set, not a scan of the element's properties: a hostile header may have millions.
  std::unordered_set<std::string> element_property_names;
  while (pos < size_) {
    const void* newline = std::memchr(bytes_ + pos, '\n', size_ - pos);
    const size_t line_end =
        newline ? static_cast<size_t>(static_cast<const unsigned char*>(newline) - bytes_) : size_;
    std::string_view line = text(pos, line_end);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = newline ? line_end + 1 : size_;
    ++line_number;
    if (line_number == 1) continue;  // the magic

    const std::vector<std::string_view> tokens = split_tokens(line);
    if (tokens.empty()) continue;
    const std::string_view keyword = tokens[0];
    const std::string where = "header line " + std::to_string(line_number) + ": ";

    if (keyword == "end_header") {
      ended = true;
      break;
    }
    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "format") {
      if (have_format) fail(where + "a second 'format' line");
      if (tokens.size() != 3) fail(where + "malformed format line '" + std::string(line) + "'");
      if (tokens[1] == "ascii") {
        header.format = PlyFormat::kAscii;
      } else if (tokens[1] == "binary_little_endian") {
        header.format = PlyFormat::kBinaryLittleEndian;
      } else if (tokens[1] == "binary_big_endian") {
        header.format = PlyFormat::kBinaryBigEndian;
      } else {
        fail(where + "unsupported format '" + std::string(tokens[1]) +
             "' (supported: ascii, binary_little_endian, binary_big_endian)");
      }
      if (tokens[2] != "1.0") fail(where + "unsupported PLY version '" + std::string(tokens[2]) + "'");
      header.format_name = std::string(tokens[1]);
      have_format = true;
      continue;
    }
    if (keyword == "element") {
      if (tokens.size() != 3) fail(where + "malformed element line '" + std::string(line) + "'");
      PlyElement element;
      element.name = std::string(tokens[1]);
      const std::string_view count_text = tokens[2];
      const auto [end, error] =
          std::from_chars(count_text.data(), count_text.data() + count_text.size(), element.count);
      if (error != std::errc() || end != count_text.data() + count_text.size())
        fail(where + "invalid count '" + std::string(count_text) + "' for element '" + element.name + "'");
      if (element.name == "vertex") {
        if (vertex_index) fail(where + "a second 'element vertex'");
        vertex_index = header.elements.size();
      }
      header.elements.push_back(std::move(element));
      element_property_names.clear();
      continue;
    }
    if (keyword == "property") {
      if (header.elements.empty()) fail(where + "property before any element");
      PlyElement& element = header.elements.back();
      PlyProperty property;
      if (tokens.size() >= 2 && tokens[1] == "list") {
        if (tokens.size() != 5) fail(where + "malformed list property line '" + std::string(line) + "'");
        const auto count_type = parse_scalar_type(tokens[2]);
        const auto item_type = parse_scalar_type(tokens[3]);
        if (!count_type) fail(where + "unknown property type '" + std::string(tokens[2]) + "'");
        if (!item_type) fail(where + "unknown property type '" + std::string(tokens[3]) + "'");
        if (!is_integer(*count_type))
          fail(where + "list count type '" + std::string(tokens[2]) + "' is not an integer type");
        property.is_list = true;
        property.list_count_type = *count_type;
        property.type = *item_type;
        property.name = std::string(tokens[4]);
      } else {
        if (tokens.size() != 3) fail(where + "malformed property line '" + std::string(line) + "'");
        const auto type = parse_scalar_type(tokens[1]);
        if (!type) fail(where + "unknown property type '" + std::string(tokens[1]) + "'");
        property.type = *type;
        property.name = std::string(tokens[2]);
      }
      if (!element_property_names.insert(property.name).second)
        fail(where + "duplicated property '" + property.name + "' in element '" + element.name + "'");
      property.row_offset = element.fixed_row_size;
      if (property.is_list) {
        element.has_list = true;
      } else {
        element.fixed_row_size += scalar_size(property.type);
      }
      element.properties.push_back(std::move(property));
      continue;
    }
    const bool printable = std::all_of(line.begin(), line.end(), [](char c) {
      return c == '\t' || (static_cast<unsigned char>(c) >= 0x20 && static_cast<unsigned char>(c) < 0x7f);
    });
    if (!printable) fail(where + "binary data before 'end_header' (the header is not terminated)");
    fail(where + "unexpected header line '" + std::string(line.substr(0, 80)) + "'");
  }
  if (!ended) fail("the header is not terminated by 'end_header'");
  if (!have_format) fail("the header has no 'format' line");
  if (!vertex_index) fail("the header has no 'element vertex' (no Gaussians in this file)");
  header.vertex_element = *vertex_index;
  header.data_offset = pos;
  header.header_lines = line_number;
  return header;
}

}  // namespace tilesplat::detail
