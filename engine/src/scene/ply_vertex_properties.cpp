#include "scene/ply_vertex_properties.h"

#include <charconv>
#include <system_error>

#include "scene/scene_reading.h"

namespace tilesplat::detail {

ColumnTarget classify_property(std::string_view file, const std::string& name) {
  static constexpr std::string_view kAxes[] = {"x", "y", "z"};
  static constexpr std::string_view kNormals[] = {"nx", "ny", "nz"};
  static constexpr std::string_view kDc[] = {"f_dc_0", "f_dc_1", "f_dc_2"};
  static constexpr std::string_view kScales[] = {"scale_0", "scale_1", "scale_2"};
  static constexpr std::string_view kRotations[] = {"rot_0", "rot_1", "rot_2", "rot_3"};
  for (size_t i = 0; i < 3; ++i) {
    if (name == kAxes[i]) return {Target::kPosition, i};
    if (name == kNormals[i]) return {Target::kNormal, i};
    if (name == kDc[i]) return {Target::kShDc, i};
    if (name == kScales[i]) return {Target::kScale, i};
  }
  for (size_t i = 0; i < 4; ++i)
    if (name == kRotations[i]) return {Target::kRotation, i};
  if (name == "opacity") return {Target::kOpacity, 0};
  if (name.starts_with("f_rest_")) {
    const std::string_view digits = std::string_view(name).substr(7);
    size_t index = 0;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), index);
    const bool canonical = !digits.empty() && error == std::errc() && end == digits.data() + digits.size() &&
                           (digits.size() == 1 || digits[0] != '0');
    if (!canonical) fail(file, "property '" + name + "' is not a valid f_rest_<index> name");
    return {Target::kShRest, index};
  }
  return {Target::kIgnored, 0};
}

void parse_ascii_vertex(std::string_view file, const PlyElement& element, std::string_view line,
                        size_t line_number, size_t vertex_index, std::vector<double>& values) {
  const size_t expected = element.properties.size();
  const std::string where =
      "line " + std::to_string(line_number) + " (vertex " + std::to_string(vertex_index) + "): ";
  size_t pos = 0;
  for (size_t p = 0; p < expected; ++p) {
    while (pos < line.size() && is_blank(line[pos])) ++pos;
    if (pos == line.size())
      fail(file,
           where + "too few values, expected " + std::to_string(expected) + ", found " + std::to_string(p));
    size_t end = pos;
    while (end < line.size() && !is_blank(line[end])) ++end;
    std::string_view token = line.substr(pos, end - pos);
    // from_chars rejects a leading '+', which some writers emit.
    std::string_view digits = token;
    if (digits.size() > 1 && digits[0] == '+') digits.remove_prefix(1);
    double value = 0;
    const auto [parsed_end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (error == std::errc::result_out_of_range)
      fail(file, where + "value '" + std::string(token) + "' of " + element.properties[p].name +
                     " is out of range");
    if (error != std::errc() || parsed_end != digits.data() + digits.size())
      fail(file, where + "'" + std::string(token) + "' is not a number (property " +
                     element.properties[p].name + ")");
    values[p] = value;
    pos = end;
  }
  while (pos < line.size() && is_blank(line[pos])) ++pos;
  if (pos != line.size())
    fail(file, where + "too many values, expected " + std::to_string(expected) +
                   "; the properties in the header may not match the data");
}

}  // namespace tilesplat::detail
