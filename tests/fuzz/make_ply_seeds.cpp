// Makes a small seed corpus for the PLY fuzzer out of real scenes, however large they are: for
// every .ply given (or found in a directory given), the header and the first few items of each
// element, re-encoded in all three PLY encodings (ASCII, binary little and big endian) with the
// element counts rewritten. Only the bytes needed are read, so a 500 MB scene costs a few KB.
//
//   make_ply_seeds OUT_DIR FILE_OR_DIR...
//
// Files it cannot cut (binary data with list properties, no end_header in the first 64 KiB) are
// skipped with a note; it fails only when it wrote nothing at all.
#include <algorithm>
#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace fs = std::filesystem;

namespace {

constexpr uint64_t kItemCounts[] = {1, 5};  // items kept per element, one seed each
constexpr size_t kMaxHeaderBytes = 64 * 1024;

struct Property {
  std::string type;  // PLY type name
  size_t size = 0;
  bool is_float = false;
  bool is_signed = false;
  bool is_list = false;
  std::string count_type;
  size_t count_size = 0;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  size_t header_line = 0;  // index of its 'element' line
  std::vector<Property> properties;
  std::vector<std::vector<std::vector<double>>> items;  // kept items: property -> values
};

struct Ply {
  std::string format;  // ascii, binary_little_endian, binary_big_endian
  std::vector<std::string> header_lines;  // without newlines; 'format' and 'element' lines are rewritten
  size_t format_line = 0;
  size_t data_offset = 0;
  std::vector<Element> elements;
};

bool scalar_info(std::string_view type, Property& property) {
  struct Info {
    std::string_view name;
    size_t size;
    bool is_float;
    bool is_signed;
  };
  static constexpr Info kTypes[] = {
      {"char", 1, false, true},    {"int8", 1, false, true},     {"uchar", 1, false, false},
      {"uint8", 1, false, false},  {"short", 2, false, true},    {"int16", 2, false, true},
      {"ushort", 2, false, false}, {"uint16", 2, false, false},  {"int", 4, false, true},
      {"int32", 4, false, true},   {"uint", 4, false, false},    {"uint32", 4, false, false},
      {"float", 4, true, true},    {"float32", 4, true, true},   {"double", 8, true, true},
      {"float64", 8, true, true}};
  for (const Info& info : kTypes) {
    if (info.name != type) continue;
    property.type = std::string(type);
    property.size = info.size;
    property.is_float = info.is_float;
    property.is_signed = info.is_signed;
    return true;
  }
  return false;
}

std::vector<std::string> split(const std::string& line) {
  std::istringstream stream(line);
  std::vector<std::string> tokens;
  for (std::string token; stream >> token;) tokens.push_back(token);
  return tokens;
}

Ply parse_header(std::ifstream& in) {
  std::string head(kMaxHeaderBytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  in.clear();
  Ply ply;
  size_t pos = 0;
  bool ended = false;
  while (pos < head.size()) {
    const size_t newline = head.find('\n', pos);
    if (newline == std::string::npos) break;
    std::string line = head.substr(pos, newline - pos);
    pos = newline + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::vector<std::string> tokens = split(line);
    ply.header_lines.push_back(line);
    if (tokens.empty()) continue;
    if (tokens[0] == "end_header") {
      ended = true;
      break;
    }
    if (tokens[0] == "format" && tokens.size() == 3) {
      ply.format = tokens[1];
      ply.format_line = ply.header_lines.size() - 1;
    } else if (tokens[0] == "element" && tokens.size() == 3) {
      Element element;
      element.name = tokens[1];
      element.count = std::stoull(tokens[2]);
      element.header_line = ply.header_lines.size() - 1;
      ply.elements.push_back(element);
    } else if (tokens[0] == "property" && !ply.elements.empty()) {
      Property property;
      const bool ok = tokens.size() == 5 && tokens[1] == "list"
                          ? scalar_info(tokens[3], property) && [&] {
                              Property count;
                              if (!scalar_info(tokens[2], count)) return false;
                              property.is_list = true;
                              property.count_type = count.type;
                              property.count_size = count.size;
                              return true;
                            }()
                          : tokens.size() == 3 && scalar_info(tokens[1], property);
      if (!ok) throw std::runtime_error("unsupported property line '" + line + "'");
      ply.elements.back().properties.push_back(property);
    }
  }
  if (!ended) throw std::runtime_error("no end_header in the first 64 KiB");
  if (ply.header_lines.empty() || ply.header_lines[0] != "ply") throw std::runtime_error("not a PLY");
  if (ply.format != "ascii" && ply.format != "binary_little_endian" && ply.format != "binary_big_endian")
    throw std::runtime_error("unknown format '" + ply.format + "'");
  ply.data_offset = pos;
  return ply;
}

double decode(const unsigned char* bytes, const std::string& type, bool swap) {
  unsigned char b[8];
  Property info;
  scalar_info(type, info);
  for (size_t i = 0; i < info.size; ++i) b[i] = swap ? bytes[info.size - 1 - i] : bytes[i];
  auto get = [&]<typename T>(T) {
    T value;
    std::memcpy(&value, b, sizeof(T));
    return static_cast<double>(value);
  };
  if (info.is_float) return info.size == 4 ? get(float{}) : get(double{});
  switch (info.size) {
    case 1:
      return info.is_signed ? get(int8_t{}) : get(uint8_t{});
    case 2:
      return info.is_signed ? get(int16_t{}) : get(uint16_t{});
    default:
      return info.is_signed ? get(int32_t{}) : get(uint32_t{});
  }
}

void read_items(std::ifstream& in, Ply& ply, uint64_t keep) {
  if (ply.format == "ascii") {
    in.seekg(static_cast<std::streamoff>(ply.data_offset));
    for (Element& element : ply.elements) {
      element.items.clear();
      for (uint64_t i = 0; i < element.count; ++i) {
        std::string line;
        if (!std::getline(in, line)) throw std::runtime_error("truncated ASCII data");
        if (i >= keep) continue;
        std::istringstream stream(line);
        std::vector<std::vector<double>> item;
        for (const Property& property : element.properties) {
          std::vector<double> values;
          double count = 1;
          if (property.is_list && !(stream >> count)) throw std::runtime_error("bad ASCII list");
          for (double v = 0; v < count; ++v) {
            double value;
            if (!(stream >> value)) throw std::runtime_error("bad ASCII value");
            values.push_back(value);
          }
          item.push_back(values);
        }
        element.items.push_back(item);
      }
    }
    return;
  }
  const bool swap = (ply.format == "binary_big_endian") != (std::endian::native == std::endian::big);
  uint64_t offset = ply.data_offset;
  for (Element& element : ply.elements) {
    size_t row = 0;
    for (const Property& property : element.properties) {
      if (property.is_list) throw std::runtime_error("binary element '" + element.name + "' has a list");
      row += property.size;
    }
    const uint64_t kept = std::min(keep, element.count);
    std::vector<unsigned char> bytes(static_cast<size_t>(kept) * row);
    in.seekg(static_cast<std::streamoff>(offset));
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (static_cast<size_t>(in.gcount()) != bytes.size()) throw std::runtime_error("truncated binary data");
    element.items.clear();
    for (uint64_t i = 0; i < kept; ++i) {
      std::vector<std::vector<double>> item;
      size_t at = static_cast<size_t>(i) * row;
      for (const Property& property : element.properties) {
        item.push_back({decode(bytes.data() + at, property.type, swap)});
        at += property.size;
      }
      element.items.push_back(item);
    }
    offset += element.count * row;
  }
}

void encode(std::string& out, double value, const std::string& type, const std::string& format) {
  Property info;
  scalar_info(type, info);
  if (format == "ascii") {
    char buffer[64];
    const auto result = !info.is_float ? std::to_chars(buffer, buffer + 64, static_cast<long long>(value))
                        : info.size == 4 ? std::to_chars(buffer, buffer + 64, static_cast<float>(value))
                                         : std::to_chars(buffer, buffer + 64, value);
    out.append(buffer, result.ptr);
    return;
  }
  unsigned char b[8];
  auto put = [&]<typename T>(T v) { std::memcpy(b, &v, sizeof(T)); };
  if (info.is_float) {
    info.size == 4 ? put(static_cast<float>(value)) : put(value);
  } else if (info.size == 1) {
    info.is_signed ? put(static_cast<int8_t>(value)) : put(static_cast<uint8_t>(value));
  } else if (info.size == 2) {
    info.is_signed ? put(static_cast<int16_t>(value)) : put(static_cast<uint16_t>(value));
  } else {
    info.is_signed ? put(static_cast<int32_t>(value)) : put(static_cast<uint32_t>(value));
  }
  const bool swap = (format == "binary_big_endian") != (std::endian::native == std::endian::big);
  if (swap) std::reverse(b, b + info.size);
  out.append(reinterpret_cast<const char*>(b), info.size);
}

std::string write(const Ply& ply, const std::string& format) {
  std::vector<std::string> lines = ply.header_lines;
  lines[ply.format_line] = "format " + format + " 1.0";
  for (const Element& element : ply.elements)
    lines[element.header_line] = "element " + element.name + " " + std::to_string(element.items.size());
  std::string out;
  for (const std::string& line : lines) out += line + "\n";
  for (const Element& element : ply.elements) {
    for (const auto& item : element.items) {
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const Property& property = element.properties[p];
        if (format == "ascii" && p > 0) out += ' ';
        if (property.is_list) {
          encode(out, static_cast<double>(item[p].size()), property.count_type, format);
          if (format == "ascii" && !item[p].empty()) out += ' ';
        }
        for (size_t v = 0; v < item[p].size(); ++v) {
          if (format == "ascii" && v > 0) out += ' ';
          encode(out, item[p][v], property.type, format);
        }
      }
      if (format == "ascii") out += '\n';
    }
  }
  return out;
}

bool is_ply(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".ply" && fs::is_regular_file(path);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: make_ply_seeds OUT_DIR FILE_OR_DIR...\n";
    return 2;
  }
  const fs::path out_dir = argv[1];
  fs::create_directories(out_dir);
  std::vector<fs::path> inputs;
  for (int i = 2; i < argc; ++i) {
    const fs::path arg = argv[i];
    if (fs::is_directory(arg)) {
      for (const auto& entry : fs::recursive_directory_iterator(arg))
        if (is_ply(entry.path())) inputs.push_back(entry.path());
    } else if (is_ply(arg)) {
      inputs.push_back(arg);
    } else {
      std::cerr << "make_ply_seeds: skipping " << arg << " (not a .ply file or directory)\n";
    }
  }
  std::sort(inputs.begin(), inputs.end());
  size_t written = 0;
  for (const fs::path& input : inputs) {
    try {
      std::ifstream in(input, std::ios::binary);
      if (!in) throw std::runtime_error("cannot open");
      Ply ply = parse_header(in);
      for (const uint64_t keep : kItemCounts) {
        read_items(in, ply, keep);
        for (const char* format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
          const fs::path out = out_dir / (input.stem().string() + "_first" + std::to_string(keep) + "_" +
                                          format + ".ply");
          std::ofstream(out, std::ios::binary) << write(ply, format);
          ++written;
        }
      }
    } catch (const std::exception& error) {
      std::cerr << "make_ply_seeds: skipping " << input << ": " << error.what() << "\n";
    }
  }
  std::cout << "make_ply_seeds: " << written << " seeds from " << inputs.size() << " PLY files in " << out_dir
            << "\n";
  return written > 0 ? 0 : 1;
}
