// What the vertex properties of a 3DGS PLY hold, by the names the trainer writes them with (x y z,
// nx ny nz, f_dc_*, f_rest_*, opacity, scale_*, rot_*), and the parsing of one ASCII vertex line.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "scene/ply_header.h"

namespace tilesplat::detail {

enum class Target { kIgnored, kPosition, kNormal, kShDc, kShRest, kOpacity, kScale, kRotation };

struct ColumnTarget {
  Target target = Target::kIgnored;
  size_t component = 0;  // x/y/z, rgb channel, f_rest index, ...
};

// The attribute a vertex property holds (kIgnored for one the renderer does not use). A malformed
// f_rest_<index> name fails, naming `file`.
ColumnTarget classify_property(std::string_view file, const std::string& name);

// The values of one ASCII vertex line, one per property of `element`, into `values`. Fails naming
// `file`, the line and the vertex for too few or too many values or one that is not a number.
void parse_ascii_vertex(std::string_view file, const PlyElement& element, std::string_view line,
                        size_t line_number, size_t vertex_index, std::vector<double>& values);

}  // namespace tilesplat::detail
