// Reader for 3DGS PLY files: binary (little or big endian) and ASCII.
//
// The whole file is mapped (or read with one call) and decoded in place; parse_ply decodes a buffer
// the caller holds (the fuzz harness in tests/fuzz uses it). Properties are found by name;
// every value is converted to float. Structure (element sizes, truncation, trailing bytes) is
// validated before the output arrays are allocated, so a malformed header can never trigger a
// huge allocation.
#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_set>
#include <vector>

#include "tilesplat/scene.h"

#if __has_include(<sys/mman.h>) && __has_include(<unistd.h>)
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#define TILESPLAT_PLY_HAS_MMAP 1
#else
#define TILESPLAT_PLY_HAS_MMAP 0
#endif

namespace tilesplat {
namespace {

enum class ScalarType : uint8_t { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

size_t scalar_size(ScalarType type) {
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

bool is_integer(ScalarType type) {
  return type != ScalarType::kFloat32 && type != ScalarType::kFloat64;
}

std::optional<ScalarType> parse_scalar_type(std::string_view name) {
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

bool checked_multiply(uint64_t a, uint64_t b, uint64_t* product) {
  if (a != 0 && b > std::numeric_limits<uint64_t>::max() / a) return false;
  *product = a * b;
  return true;
}

// A double outside float's range becomes +-inf explicitly: the plain cast would be undefined.
float to_float(double value) {
  if (std::isfinite(value) && std::fabs(value) > static_cast<double>(std::numeric_limits<float>::max()))
    return value > 0 ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
  return static_cast<float>(value);
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

std::string describe_value(float value) {
  if (std::isnan(value)) return "nan";
  return value > 0 ? "inf" : "-inf";
}

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

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

enum class Target { kIgnored, kPosition, kNormal, kShDc, kShRest, kOpacity, kScale, kRotation };

struct ColumnTarget {
  Target target = Target::kIgnored;
  size_t component = 0;  // x/y/z, rgb channel, f_rest index, ...
};

// The whole file in memory: mapped where the platform can (no copy, and the page cache serves
// it), else read with one call. A mapped file that another process truncates while it is being
// decoded raises SIGBUS; scene files are not rewritten in place, so the speed is worth it.
class FileContents {
 public:
  FileContents() = default;
  FileContents(const FileContents&) = delete;
  FileContents& operator=(const FileContents&) = delete;
  ~FileContents() {
#if TILESPLAT_PLY_HAS_MMAP
    if (mapping_) munmap(mapping_, size_);
#endif
  }

  // Returns an error message, empty on success.
  std::string open(const std::filesystem::path& path) {
#if TILESPLAT_PLY_HAS_MMAP
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return std::string("cannot open: ") + std::strerror(errno);
    struct stat info{};
    if (fstat(fd, &info) != 0) {
      const std::string error = std::string("cannot open: ") + std::strerror(errno);
      ::close(fd);
      return error;
    }
    size_ = static_cast<size_t>(info.st_size);
    if (size_ > 0) {
      void* mapping = mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
      if (mapping != MAP_FAILED) {
        mapping_ = mapping;
        data_ = static_cast<const unsigned char*>(mapping);
        madvise(mapping_, size_, MADV_SEQUENTIAL);
      }
    }
    ::close(fd);
    if (data_ || size_ == 0) return {};
    // Mapping can fail on some file systems: fall back to reading.
#endif
    std::FILE* file = std::fopen(path.c_str(), "rb");
    if (!file) return std::string("cannot open: ") + std::strerror(errno);
    std::error_code ec;
    size_ = static_cast<size_t>(std::filesystem::file_size(path, ec));
    if (ec) {
      std::fclose(file);
      return "cannot open: " + ec.message();
    }
    buffer_ = std::make_unique_for_overwrite<unsigned char[]>(std::max<size_t>(size_, 1));
    size_t total = 0;
    while (total < size_) {
      const size_t got = std::fread(buffer_.get() + total, 1, size_ - total, file);
      if (got == 0) break;
      total += got;
    }
    const bool read_error = std::ferror(file) != 0;
    std::fclose(file);
    if (read_error) return "read error";
    size_ = total;  // the file may have shrunk since file_size(); trust what was read
    data_ = buffer_.get();
    return {};
  }

  const unsigned char* data() const { return data_; }
  size_t size() const { return size_; }

 private:
  const unsigned char* data_ = nullptr;
  size_t size_ = 0;
#if TILESPLAT_PLY_HAS_MMAP
  void* mapping_ = nullptr;
#endif
  std::unique_ptr<unsigned char[]> buffer_;
};

// Checks that `path` names a readable regular file and maps or reads it; throws SceneError.
void open_scene_file(const std::filesystem::path& path, FileContents& contents) {
  const auto fail = [&](const std::string& what) { throw SceneError(path.string() + ": " + what); };
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec && status.type() != std::filesystem::file_type::not_found) fail("cannot open: " + ec.message());
  if (!std::filesystem::exists(status)) fail("cannot open: no such file");
  if (std::filesystem::is_directory(status)) fail("cannot open: is a directory, not a file");
  if (!std::filesystem::is_regular_file(status)) fail("cannot open: not a regular file");
  if (const std::string error = contents.open(path); !error.empty()) fail(error);
}

// Decodes a PLY held in memory. `name` (the file's path, for load_ply) prefixes every error.
class PlyReader {
 public:
  PlyReader(std::string_view name, const unsigned char* bytes, size_t size, const LoadOptions& options)
      : name_(name), options_(options), bytes_(bytes), size_(size) {}

  GaussianScene read(LoadReport* report) {
    if (size_ == 0) fail("empty file, not a PLY file");
    parse_header();
    plan_vertex_columns();

    GaussianScene scene;
    scene.sh_degree = sh_degree_;
    if (header_.format == PlyFormat::kAscii) {
      read_ascii(scene);
    } else {
      read_binary(scene);
    }
    normalize_rotations(scene);

    if (report) {
      LoadReport result;
      result.format = "ply " + header_.format_name;
      result.gaussians_in_file = static_cast<size_t>(vertex().count);
      result.dropped = dropped_;
      result.dropped_by_property = std::move(dropped_by_property_);
      result.ignored_properties = std::move(ignored_properties_);
      *report = std::move(result);
    }
    return scene;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw SceneError(std::string(name_) + ": " + what); }

  const PlyElement& vertex() const { return header_.elements[header_.vertex_element]; }

  std::string_view text(size_t begin, size_t end) const {
    return {reinterpret_cast<const char*>(bytes_) + begin, end - begin};
  }

  void parse_header() {
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
          header_.format = PlyFormat::kAscii;
        } else if (tokens[1] == "binary_little_endian") {
          header_.format = PlyFormat::kBinaryLittleEndian;
        } else if (tokens[1] == "binary_big_endian") {
          header_.format = PlyFormat::kBinaryBigEndian;
        } else {
          fail(where + "unsupported format '" + std::string(tokens[1]) +
               "' (supported: ascii, binary_little_endian, binary_big_endian)");
        }
        if (tokens[2] != "1.0") fail(where + "unsupported PLY version '" + std::string(tokens[2]) + "'");
        header_.format_name = std::string(tokens[1]);
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
          vertex_index = header_.elements.size();
        }
        header_.elements.push_back(std::move(element));
        element_property_names.clear();
        continue;
      }
      if (keyword == "property") {
        if (header_.elements.empty()) fail(where + "property before any element");
        PlyElement& element = header_.elements.back();
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
    header_.vertex_element = *vertex_index;
    header_.data_offset = pos;
    header_.header_lines = line_number;
  }

  ColumnTarget classify(const std::string& name) const {
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
      const bool canonical = !digits.empty() && error == std::errc() &&
                             end == digits.data() + digits.size() && (digits.size() == 1 || digits[0] != '0');
      if (!canonical) fail("property '" + name + "' is not a valid f_rest_<index> name");
      return {Target::kShRest, index};
    }
    return {Target::kIgnored, 0};
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
      const ColumnTarget target = classify(property.name);
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
              " (this looks like a compressed PLY with packed_* properties, which this reader does not "
              "decode)";
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
    const size_t coefficients = static_cast<size_t>(scene.sh_coefficients());
    scene.positions.resize(3 * count);
    scene.log_scales.resize(3 * count);
    scene.rotations.resize(4 * count);
    scene.opacity_logits.resize(count);
    scene.sh.resize(3 * coefficients * count);
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
      if (options_.strict)
        fail("Gaussian " + std::to_string(gaussian_index) + " has a non-finite value in " + *column.name +
             " (" + describe_value(value) + ") (strict mode)");
      ++dropped_;
      for (DroppedProperty& entry : dropped_by_property_) {
        if (entry.property == *column.name) {
          ++entry.count;
          return;
        }
      }
      dropped_by_property_.push_back(DroppedProperty{*column.name, 1, gaussian_index});
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

  // Walks one element's items and returns the offset after it; fails on truncation.
  template <bool kSwap>
  size_t skip_binary_element(const PlyElement& element, size_t offset) const {
    const size_t available = size_ - offset;
    if (!element.has_list) {
      uint64_t needed = 0;
      if (!checked_multiply(element.count, element.fixed_row_size, &needed) || needed > size_)
        fail("element '" + element.name + "' count " + std::to_string(element.count) +
             " is impossible for this file: " + std::to_string(element.count) + " items of " +
             std::to_string(element.fixed_row_size) + " bytes need more than the whole file (" +
             std::to_string(size_) + " bytes); the file is truncated or the count is wrong");
      if (needed > available)
        fail("truncated binary data in element '" + element.name + "': expected " +
             std::to_string(element.count) + " items (" + std::to_string(needed) + " bytes) but only " +
             std::to_string(available) + " bytes remain; " + std::to_string(needed - available) +
             " bytes missing");
      return offset + static_cast<size_t>(needed);
    }
    // Every item takes at least one byte, so this loop is bounded by the file size.
    for (uint64_t item = 0; item < element.count; ++item) {
      for (const PlyProperty& property : element.properties) {
        const auto truncated = [&] {
          fail("truncated binary data in element '" + element.name + "': the data ends in item " +
               std::to_string(item) + " of " + std::to_string(element.count) + " (property '" +
               property.name + "')");
        };
        if (!property.is_list) {
          const size_t item_size = scalar_size(property.type);
          if (size_ - offset < item_size) truncated();
          offset += item_size;
          continue;
        }
        const size_t count_size = scalar_size(property.list_count_type);
        if (size_ - offset < count_size) truncated();
        const std::optional<uint64_t> list_length =
            load_list_count<kSwap>(bytes_ + offset, property.list_count_type);
        if (!list_length)
          fail("element '" + element.name + "' item " + std::to_string(item) +
               " has a negative list count in '" + property.name + "'");
        offset += count_size;
        uint64_t list_bytes = 0;
        if (!checked_multiply(*list_length, scalar_size(property.type), &list_bytes) ||
            list_bytes > size_ - offset)
          truncated();
        offset += static_cast<size_t>(list_bytes);
      }
    }
    return offset;
  }

  template <bool kSwap>
  void read_binary_swapped(GaussianScene& scene) {
    const PlyElement& vertex_element = vertex();
    const size_t row_size = vertex_element.fixed_row_size;
    size_t offset = header_.data_offset;
    size_t vertex_offset = 0;
    for (size_t e = 0; e < header_.elements.size(); ++e) {
      const PlyElement& element = header_.elements[e];
      if (e != header_.vertex_element) {
        offset = skip_binary_element<kSwap>(element, offset);
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

    const size_t count = static_cast<size_t>(vertex_element.count);
    if (count == 0) return;
    allocate(scene, count);
    const std::vector<Column> columns = make_columns(scene);
    const unsigned char* rows = bytes_ + vertex_offset;
    if constexpr (!kSwap) {
      const bool all_float = std::all_of(columns.begin(), columns.end(),
                                         [](const Column& c) { return c.type == ScalarType::kFloat32; });
      if (all_float) {
        shrink(scene, decode_rows<true, false>(rows, row_size, count, columns));
        return;
      }
    }
    shrink(scene, decode_rows<false, kSwap>(rows, row_size, count, columns));
  }

  // kFloatOnly: every used property is a native-endian float32, so a value is one memcpy.
  template <bool kFloatOnly, bool kSwap>
  size_t decode_rows(const unsigned char* rows, size_t row_size, size_t count,
                     const std::vector<Column>& columns) {
    size_t kept = 0;
    for (size_t i = 0; i < count; ++i) {
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

  void read_binary(GaussianScene& scene) {
    const bool file_little = header_.format == PlyFormat::kBinaryLittleEndian;
    const bool host_little = std::endian::native == std::endian::little;
    if (file_little == host_little) {
      read_binary_swapped<false>(scene);
    } else {
      read_binary_swapped<true>(scene);
    }
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
        parse_ascii_vertex(*line, cursor.line_number, i, values);
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

  void parse_ascii_vertex(std::string_view line, size_t line_number, size_t vertex_index,
                          std::vector<double>& values) const {
    const PlyElement& element = vertex();
    const size_t expected = element.properties.size();
    const std::string where =
        "line " + std::to_string(line_number) + " (vertex " + std::to_string(vertex_index) + "): ";
    size_t pos = 0;
    for (size_t p = 0; p < expected; ++p) {
      while (pos < line.size() && is_blank(line[pos])) ++pos;
      if (pos == line.size())
        fail(where + "too few values, expected " + std::to_string(expected) + ", found " + std::to_string(p));
      size_t end = pos;
      while (end < line.size() && !is_blank(line[end])) ++end;
      std::string_view token = line.substr(pos, end - pos);
      // from_chars rejects a leading '+', which some writers emit.
      std::string_view digits = token;
      if (digits.size() > 1 && digits[0] == '+') digits.remove_prefix(1);
      double value = 0;
      const auto [parsed_end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
      if (error == std::errc::result_out_of_range)
        fail(where + "value '" + std::string(token) + "' of " + element.properties[p].name +
             " is out of range");
      if (error != std::errc() || parsed_end != digits.data() + digits.size())
        fail(where + "'" + std::string(token) + "' is not a number (property " + element.properties[p].name +
             ")");
      values[p] = value;
      pos = end;
    }
    while (pos < line.size() && is_blank(line[pos])) ++pos;
    if (pos != line.size())
      fail(where + "too many values, expected " + std::to_string(expected) +
           "; the properties in the header may not match the data");
  }

  // ---- post-processing ----

  static void normalize_rotations(GaussianScene& scene) {
    const size_t count = scene.size();
    for (size_t i = 0; i < count; ++i) {
      float* q = scene.rotations.data() + 4 * i;
      // Double: squares of finite floats cannot overflow or underflow to zero there.
      const double norm_squared = static_cast<double>(q[0]) * q[0] + static_cast<double>(q[1]) * q[1] +
                                  static_cast<double>(q[2]) * q[2] + static_cast<double>(q[3]) * q[3];
      if (norm_squared == 0.0) {
        q[0] = 1.0f;
        q[1] = q[2] = q[3] = 0.0f;
        continue;
      }
      const double inverse_norm = 1.0 / std::sqrt(norm_squared);
      for (size_t j = 0; j < 4; ++j) q[j] = static_cast<float>(q[j] * inverse_norm);
    }
  }

  std::string_view name_;
  const LoadOptions& options_;
  const unsigned char* bytes_ = nullptr;
  size_t size_ = 0;
  PlyHeader header_;
  std::vector<ColumnTarget> targets_;  // one per vertex property
  int sh_degree_ = 0;
  bool has_normals_ = false;
  size_t dropped_ = 0;
  std::vector<DroppedProperty> dropped_by_property_;
  std::vector<std::string> ignored_properties_;
};

}  // namespace

GaussianScene parse_ply(std::span<const std::byte> data, std::string_view name, const LoadOptions& options,
                        LoadReport* report) {
  PlyReader reader(name, reinterpret_cast<const unsigned char*>(data.data()), data.size(), options);
  return reader.read(report);
}

GaussianScene load_ply(const std::filesystem::path& path, const LoadOptions& options, LoadReport* report) {
  FileContents contents;
  open_scene_file(path, contents);
  return parse_ply(std::as_bytes(std::span(contents.data(), contents.size())), path.string(), options, report);
}

}  // namespace tilesplat
