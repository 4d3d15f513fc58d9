// Reader for 3DGS PLY files: binary (little or big endian) and ASCII.
//
// The whole file is mapped (or read with one call) and decoded in place; parse_ply decodes a buffer
// the caller holds (the fuzz harness in tests/fuzz uses it). Properties are found by name;
// every value is converted to float. Structure (element sizes, truncation, trailing bytes) is
// validated before the output arrays are allocated, so a malformed header can never trigger a
// huge allocation.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "scene/ply_header.h"
#include "scene/ply_rows.h"
#include "scene/ply_vertex_properties.h"
#include "scene/scene_readers.h"
#include "scene/scene_reading.h"
#include "tilesplat/scene.h"

namespace tilesplat::detail {
namespace {

// How many bytes of vertex rows are decoded before the reader lets go of them.
constexpr size_t kReleaseBlockBytes = size_t(64) << 20;

using ConsumedBytes = std::function<void(size_t end)>;

// One output slot per used property: where its value goes for Gaussian 0, and the distance in
// floats between consecutive Gaussians.
struct Column {
  size_t property_index = 0;  // position among the vertex properties (ASCII token index)
  size_t row_offset = 0;      // byte offset inside a binary row
  ScalarType type = ScalarType::kFloat32;
  float* first = nullptr;
  size_t stride = 0;
  const std::string* name = nullptr;
};

}  // namespace

// Decodes a PLY held in memory. `name` (the file's path, for load_ply) prefixes every error.
class PlyReader {
 public:
  // `done_with(end)`, where given, is told that bytes [0, end) of the file will not be read again.
  PlyReader(std::string_view name, const unsigned char* bytes, size_t size, const LoadOptions& options,
            ConsumedBytes done_with = {})
      : name_(name),
        options_(options),
        ply_(name, bytes, size),
        bytes_(bytes),
        size_(size),
        done_with_(std::move(done_with)),
        non_finite_(name, options) {}

  GaussianScene read(LoadReport* report) {
    if (size_ == 0) fail("empty file, not a PLY file");
    header_ = ply_.parse_header();
    if (is_compressed_ply(header_)) return read_compressed_ply(ply_, header_, options_, report);
    plan_vertex_columns();

    GaussianScene scene;
    scene.sh_degree = sh_degree_;
    if (header_.format == PlyFormat::kAscii) {
      read_ascii(scene);
    } else {
      read_binary(scene);
    }
    normalize_rotations(scene);
    if (report) *report = take_report();
    return scene;
  }

  // ---- rows on demand (PlyRows) ----

  // Parses the header and finds the vertex rows of a binary 3DGS PLY, before any row is decoded.
  void prepare_rows() {
    if (size_ == 0) fail("empty file, not a PLY file");
    header_ = ply_.parse_header();
    if (is_compressed_ply(header_))
      fail("a compressed PLY (PlayCanvas) cannot be read part by part: its rows are packed in chunks");
    if (header_.format == PlyFormat::kAscii)
      fail("an ASCII PLY cannot be read part by part: its rows vary in length");
    plan_vertex_columns();
    vertex_offset_ = swapped() ? locate_vertex_rows<true>() : locate_vertex_rows<false>();
  }
  size_t rows() const { return static_cast<size_t>(vertex().count); }
  // The rows of one block: as many as kReleaseBlockBytes hold, decoded before the file's pages are let go of.
  size_t rows_per_block() const { return std::max<size_t>(1, kReleaseBlockBytes / vertex().fixed_row_size); }
  int sh_degree() const { return sh_degree_; }
  bool has_normals() const { return has_normals_; }

  // Rows [first, end) into `scene` (allocated here) from slot 0, the non-finite ones left out (their rows
  // appended to `dropped`) and counted as load_ply counts them; returns the slots filled. The rotations
  // are left as the file has them.
  size_t decode_range(size_t first, size_t end, GaussianScene& scene, std::vector<size_t>& dropped) {
    scene.sh_degree = sh_degree_;
    if (end <= first) return 0;  // no rows: no columns to point into empty arrays
    allocate(scene, end - first);
    dropped_rows_ = &dropped;
    const size_t kept = decode_rows_of(
        scene, [first](size_t i) { return first + i; }, end - first);
    dropped_rows_ = nullptr;
    return kept;
  }

  // The rows `rows` into a scene of their own, rotations normalized: load_ply's Gaussians, bit for bit.
  GaussianScene decode_rows_at(std::span<const uint64_t> rows) {
    GaussianScene scene;
    scene.sh_degree = sh_degree_;
    if (rows.empty()) return scene;
    for (uint64_t row : rows)
      if (row >= this->rows()) fail("row " + std::to_string(row) + " is past the file's vertices");
    allocate(scene, rows.size());
    const size_t kept = decode_rows_of(
        scene, [rows](size_t i) { return size_t(rows[i]); }, rows.size());
    if (kept != rows.size())
      fail("a row that was finite when the file was opened no longer is: the file changed while it was read");
    normalize_rotations(scene);
    return scene;
  }

  LoadReport take_report() {
    LoadReport result;
    result.format = "ply " + header_.format_name;
    result.version = "1.0";
    result.gaussians_in_file = static_cast<size_t>(vertex().count);
    result.dropped = non_finite_.dropped();
    result.dropped_by_property = non_finite_.take();
    result.ignored_properties = std::move(ignored_properties_);
    return result;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { ply_.fail(what); }

  const PlyElement& vertex() const { return header_.elements[header_.vertex_element]; }

  std::string_view text(size_t begin, size_t end) const {
    return {reinterpret_cast<const char*>(bytes_) + begin, end - begin};
  }

  // Works out which vertex properties are used and the SH degree, and checks the required
  // ones are present, all before any data is touched.
  void plan_vertex_columns() {
    const PlyElement& element = vertex();
    targets_.clear();
    size_t rest_count = 0;
    size_t max_rest_index = 0;
    std::string max_rest_name;
    bool normal_present[3] = {false, false, false};
    for (const PlyProperty& property : element.properties) {
      const ColumnTarget target = classify_property(name_, property.name);
      if (property.is_list)
        fail("the vertex element has a list property '" + property.name +
             "'; list properties in the vertex element are not supported");
      if (target.target == Target::kShRest) {
        ++rest_count;
        if (target.component >= max_rest_index) {
          max_rest_index = target.component;
          max_rest_name = property.name;
        }
      }
      if (target.target == Target::kNormal) normal_present[target.component] = true;
      if (target.target == Target::kIgnored) ignored_properties_.push_back(property.name);
      targets_.push_back(target);
    }

    static constexpr std::string_view kRequired[] = {"x",      "y",       "z",       "f_dc_0",  "f_dc_1",
                                                     "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2",
                                                     "rot_0",  "rot_1",   "rot_2",   "rot_3"};
    for (std::string_view required : kRequired) {
      const bool found = std::any_of(element.properties.begin(), element.properties.end(),
                                     [&](const PlyProperty& p) { return p.name == required; });
      if (!found) {
        std::string message = "missing required property '" + std::string(required) + "' in element 'vertex'";
        const bool packed = std::any_of(element.properties.begin(), element.properties.end(),
                                        [](const PlyProperty& p) { return p.name.starts_with("packed_"); });
        if (packed)
          message +=
              " (packed_* properties without a 'chunk' element: an incomplete PlayCanvas compressed PLY)";
        fail(message);
      }
    }

    const size_t present_normals = static_cast<size_t>(normal_present[0]) +
                                   static_cast<size_t>(normal_present[1]) +
                                   static_cast<size_t>(normal_present[2]);
    if (present_normals != 0 && present_normals != 3) {
      static constexpr std::string_view kNames[] = {"nx", "ny", "nz"};
      std::string message = "incomplete normals: the file has";
      for (size_t i = 0; i < 3; ++i)
        if (normal_present[i]) message += " '" + std::string(kNames[i]) + "'";
      message += " but not";
      for (size_t i = 0; i < 3; ++i)
        if (!normal_present[i]) message += " '" + std::string(kNames[i]) + "'";
      fail(message + " (normals need all of nx, ny, nz or none)");
    }
    has_normals_ = present_normals == 3;

    switch (rest_count) {
      case 0:
        sh_degree_ = 0;
        break;
      case 9:
        sh_degree_ = 1;
        break;
      case 24:
        sh_degree_ = 2;
        break;
      case 45:
        sh_degree_ = 3;
        break;
      default:
        fail("unsupported number of f_rest properties (" + std::to_string(rest_count) +
             "); expected 0, 9, 24 or 45 for SH degree 0, 1, 2 or 3");
    }
    // Names are unique, so indices 0..count-1 are all present exactly when the largest is count-1.
    if (rest_count > 0 && max_rest_index != rest_count - 1)
      fail("the " + std::to_string(rest_count) + " f_rest properties are not contiguous: found '" +
           max_rest_name + "', expected f_rest_0..f_rest_" + std::to_string(rest_count - 1));
  }

  void allocate(GaussianScene& scene, size_t count) const {
    allocate_scene(scene, count, sh_degree_);
    if (has_normals_) scene.normals.resize(3 * count);
  }

  // Only valid once allocate() ran for a non-empty scene.
  std::vector<Column> make_columns(GaussianScene& scene) const {
    const PlyElement& element = vertex();
    const size_t coefficients = static_cast<size_t>(scene.sh_coefficients());
    const size_t rest_per_channel = coefficients - 1;
    std::vector<Column> columns;
    for (size_t i = 0; i < element.properties.size(); ++i) {
      const ColumnTarget& target = targets_[i];
      if (target.target == Target::kIgnored) continue;
      Column column;
      column.property_index = i;
      column.row_offset = element.properties[i].row_offset;
      column.type = element.properties[i].type;
      column.name = &element.properties[i].name;
      switch (target.target) {
        case Target::kPosition:
          column.first = scene.positions.data() + target.component;
          column.stride = 3;
          break;
        case Target::kNormal:
          column.first = scene.normals.data() + target.component;
          column.stride = 3;
          break;
        case Target::kShDc:
          column.first = scene.sh.data() + target.component;
          column.stride = 3 * coefficients;
          break;
        case Target::kShRest: {
          // The file is channel-major (all of red's coefficients, then green's, ...); the scene is
          // coefficient-major with RGB innermost.
          const size_t channel = target.component / rest_per_channel;
          const size_t coefficient = target.component % rest_per_channel + 1;
          column.first = scene.sh.data() + coefficient * 3 + channel;
          column.stride = 3 * coefficients;
          break;
        }
        case Target::kOpacity:
          column.first = scene.opacity_logits.data();
          column.stride = 1;
          break;
        case Target::kScale:
          column.first = scene.log_scales.data() + target.component;
          column.stride = 3;
          break;
        case Target::kRotation:
          column.first = scene.rotations.data() + target.component;
          column.stride = 4;
          break;
        case Target::kIgnored:
          break;
      }
      columns.push_back(column);
    }
    return columns;
  }

  // Called for a Gaussian whose values (already written to slot `kept`) include a non-finite one.
  void on_non_finite(size_t gaussian_index, size_t kept, const std::vector<Column>& columns) {
    for (const Column& column : columns) {
      const float value = column.first[kept * column.stride];
      if (std::isfinite(value)) continue;
      non_finite_.record(gaussian_index, *column.name, value);
      if (dropped_rows_) dropped_rows_->push_back(gaussian_index);
      return;
    }
  }

  void shrink(GaussianScene& scene, size_t kept) const {
    if (kept == scene.size()) return;
    const size_t coefficients = static_cast<size_t>(scene.sh_coefficients());
    scene.positions.resize(3 * kept);
    scene.log_scales.resize(3 * kept);
    scene.rotations.resize(4 * kept);
    scene.opacity_logits.resize(kept);
    scene.sh.resize(3 * coefficients * kept);
    if (has_normals_) scene.normals.resize(3 * kept);
    scene.positions.shrink_to_fit();
    scene.log_scales.shrink_to_fit();
    scene.rotations.shrink_to_fit();
    scene.opacity_logits.shrink_to_fit();
    scene.sh.shrink_to_fit();
    scene.normals.shrink_to_fit();
  }

  // ---- binary ----

  // Walks the binary elements, checking their sizes against the file's; returns where the vertex rows
  // start.
  template <bool kSwap>
  size_t locate_vertex_rows() const {
    const size_t row_size = vertex().fixed_row_size;
    size_t offset = header_.data_offset;
    size_t vertex_offset = 0;
    for (size_t e = 0; e < header_.elements.size(); ++e) {
      const PlyElement& element = header_.elements[e];
      if (e != header_.vertex_element) {
        offset = ply_.skip_binary_element(element, offset, kSwap);
        continue;
      }
      const size_t available = size_ - offset;
      uint64_t needed = 0;
      if (!checked_multiply(element.count, row_size, &needed) || needed > size_)
        fail("impossible vertex count " + std::to_string(element.count) + ": " +
             std::to_string(element.count) + " vertices of " + std::to_string(row_size) +
             " bytes need more than the whole file (" + std::to_string(size_) +
             " bytes); the file is truncated or the count is wrong");
      if (needed > available)
        fail("truncated binary data: expected " + std::to_string(element.count) + " vertices (" +
             std::to_string(needed) + " bytes) but only " + std::to_string(available) + " bytes remain; " +
             std::to_string(needed - available) + " bytes missing (the data ends in vertex " +
             std::to_string(available / row_size) + ")");
      vertex_offset = offset;
      offset += static_cast<size_t>(needed);
    }
    if (offset != size_)
      fail(
          std::to_string(size_ - offset) +
          " bytes of trailing data after the declared elements; the vertex count in the header may be wrong");
    return vertex_offset;
  }

  bool swapped() const {
    const bool file_little = header_.format == PlyFormat::kBinaryLittleEndian;
    return file_little != (std::endian::native == std::endian::little);
  }

  void read_binary(GaussianScene& scene) {
    vertex_offset_ = swapped() ? locate_vertex_rows<true>() : locate_vertex_rows<false>();
    const size_t count = rows();
    if (count == 0) return;
    allocate(scene, count);
    // In blocks of rows, each let go of once decoded: the file's pages and the decoded arrays are never
    // both whole in memory (a mapped file's pages count as resident while mapped).
    const size_t row_size = vertex().fixed_row_size;
    const size_t block = rows_per_block();
    const std::vector<Column> columns = make_columns(scene);
    size_t kept = 0;
    for (size_t first = 0; first < count; first += block) {
      const size_t end = std::min(count, first + block);
      kept = decode_rows(columns, kept, first, end, [](size_t i) { return i; });
      if (done_with_) done_with_(vertex_offset_ + end * row_size);
    }
    shrink(scene, kept);
  }

  // Rows row_of(0), ..., row_of(count - 1) into `scene` (allocated for them) from slot 0.
  template <typename RowOf>
  size_t decode_rows_of(GaussianScene& scene, RowOf row_of, size_t count) {
    return decode_rows(make_columns(scene), 0, 0, count, row_of);
  }

  // Rows row_of(first) to row_of(end - 1) into the columns' scene from slot `kept` on; returns the slots
  // filled after them.
  template <typename RowOf>
  size_t decode_rows(const std::vector<Column>& columns, size_t kept, size_t first, size_t end,
                     RowOf row_of) {
    const bool all_float = std::all_of(columns.begin(), columns.end(),
                                       [](const Column& c) { return c.type == ScalarType::kFloat32; });
    if (swapped()) return decode_typed_rows<false, true>(columns, kept, first, end, row_of);
    return all_float ? decode_typed_rows<true, false>(columns, kept, first, end, row_of)
                     : decode_typed_rows<false, false>(columns, kept, first, end, row_of);
  }

  // kFloatOnly: every used property is a native-endian float32, so a value is one memcpy.
  template <bool kFloatOnly, bool kSwap, typename RowOf>
  size_t decode_typed_rows(const std::vector<Column>& columns, size_t kept, size_t first, size_t end,
                           RowOf row_of) {
    const size_t row_size = vertex().fixed_row_size;
    const unsigned char* rows = bytes_ + vertex_offset_;
    for (size_t j = first; j < end; ++j) {
      const size_t i = row_of(j);
      const unsigned char* row = rows + i * row_size;
      bool finite = true;
      for (const Column& column : columns) {
        float value;
        if constexpr (kFloatOnly) {
          std::memcpy(&value, row + column.row_offset, sizeof(float));
        } else {
          value = load_as_float<kSwap>(row + column.row_offset, column.type);
        }
        column.first[kept * column.stride] = value;
        if (!std::isfinite(value)) finite = false;
      }
      if (finite) {
        ++kept;
      } else {
        on_non_finite(i, kept, columns);
      }
    }
    return kept;
  }

  // ---- ASCII ----

  struct LineCursor {
    size_t pos = 0;
    size_t line_number = 0;
  };

  std::optional<std::string_view> next_line(LineCursor& cursor) const {
    if (cursor.pos >= size_) return std::nullopt;
    const void* newline = std::memchr(bytes_ + cursor.pos, '\n', size_ - cursor.pos);
    const size_t line_end =
        newline ? static_cast<size_t>(static_cast<const unsigned char*>(newline) - bytes_) : size_;
    std::string_view line = text(cursor.pos, line_end);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    cursor.pos = newline ? line_end + 1 : size_;
    ++cursor.line_number;
    return line;
  }

  void read_ascii(GaussianScene& scene) {
    const PlyElement& vertex_element = vertex();
    const size_t property_count = vertex_element.properties.size();
    // Each value takes at least one character and one separator, so a count above this bound
    // cannot be real: refuse it before allocating.
    const size_t data_bytes = size_ - header_.data_offset;
    uint64_t minimum_bytes = 0;
    if (!checked_multiply(vertex_element.count, 2 * property_count, &minimum_bytes) ||
        (minimum_bytes > 0 && minimum_bytes - 1 > data_bytes))
      fail("impossible vertex count " + std::to_string(vertex_element.count) + ": " +
           std::to_string(vertex_element.count) + " ASCII vertices of " + std::to_string(property_count) +
           " values cannot fit in the " + std::to_string(data_bytes) +
           " bytes after the header; the file is truncated or the count is wrong");

    const size_t count = static_cast<size_t>(vertex_element.count);
    std::vector<Column> columns;
    if (count > 0) {
      allocate(scene, count);
      columns = make_columns(scene);
    }
    std::vector<double> values(property_count);
    size_t kept = 0;

    LineCursor cursor{header_.data_offset, header_.header_lines};
    for (size_t e = 0; e < header_.elements.size(); ++e) {
      const PlyElement& element = header_.elements[e];
      if (e != header_.vertex_element) {
        for (uint64_t item = 0; item < element.count; ++item)
          if (!next_line(cursor))
            fail("truncated ASCII data in element '" + element.name + "': expected " +
                 std::to_string(element.count) + " lines, the file ends after " + std::to_string(item) +
                 " (line " + std::to_string(cursor.line_number) + ")");
        continue;
      }
      for (size_t i = 0; i < count; ++i) {
        const std::optional<std::string_view> line = next_line(cursor);
        if (!line)
          fail("truncated ASCII data: expected " + std::to_string(count) + " vertices, the file ends after " +
               std::to_string(i) + " (line " + std::to_string(cursor.line_number) + ")");
        parse_ascii_vertex(name_, vertex(), *line, cursor.line_number, i, values);
        bool finite = true;
        for (const Column& column : columns) {
          const float value = to_float(values[column.property_index]);
          column.first[kept * column.stride] = value;
          if (!std::isfinite(value)) finite = false;
        }
        if (finite) {
          ++kept;
        } else {
          on_non_finite(i, kept, columns);
        }
      }
    }
    // Anything but whitespace after the declared elements means the counts are wrong.
    for (size_t pos = cursor.pos; pos < size_; ++pos) {
      const char c = static_cast<char>(bytes_[pos]);
      if (c == '\n') {
        ++cursor.line_number;
        continue;
      }
      if (is_blank(c)) continue;
      fail("trailing data after the declared elements (line " + std::to_string(cursor.line_number + 1) +
           "); the vertex count in the header may be wrong");
    }
    if (count > 0) shrink(scene, kept);
  }

  std::string_view name_;
  const LoadOptions& options_;
  PlyBytes ply_;
  const unsigned char* bytes_ = nullptr;
  size_t size_ = 0;
  ConsumedBytes done_with_;
  PlyHeader header_;
  std::vector<ColumnTarget> targets_;  // one per vertex property
  int sh_degree_ = 0;
  bool has_normals_ = false;
  size_t vertex_offset_ = 0;  // where the binary vertex rows start
  NonFiniteTally non_finite_;
  std::vector<size_t>* dropped_rows_ = nullptr;  // decode_range's: the rows left out
  std::vector<std::string> ignored_properties_;
};

PlyRows::PlyRows(std::string name, const unsigned char* bytes, size_t size, const LoadOptions& options)
    : name_(std::move(name)),
      options_(options),
      reader_(std::make_unique<PlyReader>(name_, bytes, size, options_)) {
  reader_->prepare_rows();
}
PlyRows::~PlyRows() = default;
size_t PlyRows::rows() const {
  return reader_->rows();
}
size_t PlyRows::rows_per_block() const {
  return reader_->rows_per_block();
}
int PlyRows::sh_degree() const {
  return reader_->sh_degree();
}
bool PlyRows::has_normals() const {
  return reader_->has_normals();
}
size_t PlyRows::decode_range(size_t first, size_t end, GaussianScene& scene, std::vector<size_t>& dropped) {
  return reader_->decode_range(first, end, scene, dropped);
}
GaussianScene PlyRows::decode(std::span<const uint64_t> rows) const {
  return reader_->decode_rows_at(rows);
}
LoadReport PlyRows::take_report() {
  return reader_->take_report();
}

}  // namespace tilesplat::detail

namespace tilesplat {

using namespace detail;

GaussianScene parse_ply(std::span<const std::byte> data, std::string_view name, const LoadOptions& options,
                        LoadReport* report) {
  PlyReader reader(name, reinterpret_cast<const unsigned char*>(data.data()), data.size(), options);
  return reader.read(report);
}

namespace detail {

GaussianScene read_ply_file(FileContents& contents, std::string_view name, const LoadOptions& options,
                            LoadReport* report) {
  PlyReader reader(name, contents.data(), contents.size(), options,
                   [&contents](size_t end) { contents.release_before(end); });
  return reader.read(report);
}

}  // namespace detail

GaussianScene load_ply(const std::filesystem::path& path, const LoadOptions& options, LoadReport* report) {
  detail::FileContents contents;
  detail::open_scene_file(path, contents);
  return detail::read_ply_file(contents, path.string(), options, report);
}

}  // namespace tilesplat
