#include "scene/rad_file.h"

#include <glm/gtc/packing.hpp>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>

#include "scene/scene_reading.h"

namespace tilesplat::detail {
namespace {

using nlohmann::json;

constexpr uint32_t kRadMagic = 0x30444152;    // "RAD0"
constexpr uint32_t kChunkMagic = 0x43444152;  // "RADC"
// Raw deflate expands at most about 1032 to 1: a property that declares more is refused before it is inflated.
constexpr uint64_t kMaxExpansion = 1032;
constexpr double kZeroLogScale = -30;  // what Spark's 8-bit log scale stores as 0

size_t round_up8(size_t n) { return (n + 7) & ~size_t(7); }

// What a property's bytes are, per splat: its name in the file, its components and whether it is required.
struct PropertyKind {
  const char* name;
  size_t components;
};
constexpr PropertyKind kCenter{"center", 3}, kAlpha{"alpha", 1}, kRgb{"rgb", 3}, kScales{"scales", 3},
    kOrientation{"orientation", 3}, kChildCount{"child_count", 1}, kChildStart{"child_start", 1},
    kShLabel{"sh_label", 1};
// Per band (sh1, sh2, sh3) its coefficients x RGB, and up to each band all of them together.
constexpr size_t kBandComponents[4] = {0, 9, 15, 21};
constexpr size_t kRestComponents[4] = {0, 9, 24, 45};

// One property of a chunk: its JSON, the payload bytes it names, and how to read them as doubles.
class Property {
 public:
  Property(const json& meta, std::span<const unsigned char> payload, const std::string& where)
      : where_(where) {
    const auto field = [&](const char* key) -> const json& {
      if (!meta.contains(key)) fail(where + " has no '" + key + "'");
      return meta[key];
    };
    if (!field("property").is_string() || !field("encoding").is_string())
      fail(where + ": property and encoding must be strings");
    name_ = meta["property"].get<std::string>();
    encoding_ = meta["encoding"].get<std::string>();
    if (!field("offset").is_number_unsigned() || !field("bytes").is_number_unsigned())
      fail(where + ": offset and bytes must be unsigned integers");
    const uint64_t offset = meta["offset"].get<uint64_t>(), bytes = meta["bytes"].get<uint64_t>();
    if (offset > payload.size() || bytes > payload.size() - offset)
      fail(where + " (" + name_ + ") lies outside its chunk's payload (" + std::to_string(payload.size()) +
           " bytes)");
    raw_ = payload.subspan(offset, bytes);
    if (meta.contains("compression") && !meta["compression"].is_null()) {
      if (meta["compression"] != "gz")
        fail(where + " (" + name_ + "): unknown compression " + meta["compression"].dump());
      compressed_ = true;
    }
    for (const char* key : {"min", "max"})
      if (meta.contains(key) && !meta[key].is_null()) {
        if (!meta[key].is_number() || !std::isfinite(meta[key].get<double>()))
          fail(where + " (" + name_ + "): " + key + " is not a finite number");
        (key[1] == 'i' ? min_ : max_) = meta[key].get<double>();
      }
  }

  const std::string& name() const { return name_; }
  const std::string& encoding() const { return encoding_; }
  [[noreturn]] void fail(const std::string& what) const { throw Failure{what}; }
  struct Failure {
    std::string what;
  };

  // The `count` x `components` values, element-major (splat i's components together), as the encoding says.
  std::vector<double> values(size_t count, size_t components) {
    const size_t n = count * components;
    std::vector<double> out(n);
    if (encoding_ == "f32" || encoding_ == "f32_lebytes" || encoding_ == "f16" || encoding_ == "f16_lebytes" ||
        encoding_ == "ln_f16") {
      const size_t size = encoding_.starts_with("f32") ? 4 : 2;
      const bool byte_planes = encoding_.ends_with("lebytes");
      const std::vector<unsigned char> data = bytes(n * size);
      for (size_t i = 0; i < count; ++i)
        for (size_t d = 0; d < components; ++d) {
          const size_t at = d * count + i;  // planar: all of component 0, then 1, ...
          unsigned char value[4] = {0, 0, 0, 0};
          for (size_t b = 0; b < size; ++b) value[b] = byte_planes ? data[b * n + at] : data[at * size + b];
          double v = size == 4 ? double(load_le<float>(value))
                               : double(glm::unpackHalf1x16(load_le<uint16_t>(value)));
          if (encoding_ == "ln_f16") v = std::exp(v);
          out[i * components + d] = v;
        }
      return out;
    }
    if (encoding_ == "r8" || encoding_ == "r8_delta" || encoding_ == "s8" || encoding_ == "s8_delta" ||
        encoding_ == "ln_0r8") {
      const bool signed_bytes = encoding_[0] == 's';
      if (!max_ || (!signed_bytes && !min_)) fail(where_ + " (" + name_ + "): " + encoding_ + " needs min and max");
      const std::vector<unsigned char> data = bytes(n);
      const double min = min_.value_or(0), max = *max_;
      for (size_t d = 0; d < components; ++d) {
        unsigned char last = 0;  // the delta encodings: each byte adds to the one before it (mod 256)
        for (size_t i = 0; i < count; ++i) {
          unsigned char b = data[d * count + i];
          if (encoding_.ends_with("_delta")) b = last = static_cast<unsigned char>(last + b);
          double v = 0;
          if (encoding_ == "ln_0r8")
            v = b == 0 ? 0.0 : std::exp(min + (b - 1) * (max - min) / 254.0);
          else if (signed_bytes)
            v = static_cast<int8_t>(b) / 127.0 * max;
          else
            v = b / 255.0 * (max - min) + min;
          out[i * components + d] = v;
        }
      }
      return out;
    }
    if (encoding_ == "u16" || encoding_ == "u32") {
      const size_t size = encoding_ == "u16" ? 2 : 4;
      const std::vector<unsigned char> data = bytes(n * size);
      for (size_t i = 0; i < count; ++i)
        for (size_t d = 0; d < components; ++d) {
          const unsigned char* p = data.data() + (d * count + i) * size;
          out[i * components + d] = size == 2 ? double(load_le<uint16_t>(p)) : double(load_le<uint32_t>(p));
        }
      return out;
    }
    fail(where_ + " (" + name_ + "): unknown encoding '" + encoding_ + "'");
  }

  // Orientation as x y z w per splat: oct88r8 (an octahedral axis in two bytes, the angle in one, splat by
  // splat), or x y z (f32, f16) with w >= 0 completing the unit quaternion.
  std::vector<double> quaternions(size_t count) {
    std::vector<double> out(4 * count);
    if (encoding_ == "oct88r8") {
      const std::vector<unsigned char> data = bytes(3 * count);
      for (size_t i = 0; i < count; ++i) {
        const unsigned char* p = data.data() + 3 * i;
        double x = p[0] / 255.0 * 2 - 1, y = p[1] / 255.0 * 2 - 1;
        const double z = 1 - std::fabs(x) - std::fabs(y);
        const double t = std::max(-z, 0.0);
        x += x >= 0 ? -t : t;
        y += y >= 0 ? -t : t;
        const double length = std::sqrt(x * x + y * y + z * z);
        const double half_angle = p[2] / 255.0 * 0.5 * 3.14159265358979323846;
        const double s = std::sin(half_angle) / length;
        out[4 * i] = x * s;
        out[4 * i + 1] = y * s;
        out[4 * i + 2] = z * s;
        out[4 * i + 3] = std::cos(half_angle);
      }
      return out;
    }
    if (encoding_ != "f32" && encoding_ != "f16")
      fail(where_ + " (orientation): unknown encoding '" + encoding_ + "'");
    const std::vector<double> xyz = values(count, 3);
    for (size_t i = 0; i < count; ++i) {
      double sum = 0;
      for (size_t d = 0; d < 3; ++d) sum += (out[4 * i + d] = xyz[3 * i + d]) * xyz[3 * i + d];
      out[4 * i + 3] = std::sqrt(std::max(0.0, 1 - sum));
    }
    return out;
  }

 private:
  // The property's bytes, inflated where compressed; exactly `size` of them or the file is damaged.
  std::vector<unsigned char> bytes(size_t size) {
    if (!compressed_) {
      if (raw_.size() != size)
        fail(where_ + " (" + name_ + ") holds " + std::to_string(raw_.size()) + " bytes; its splats need " +
             std::to_string(size));
      return {raw_.begin(), raw_.end()};
    }
    if (size / kMaxExpansion > raw_.size())
      fail(where_ + " (" + name_ + "): " + std::to_string(raw_.size()) + " compressed bytes cannot hold the " +
           std::to_string(size) + " its splats need");
    std::vector<unsigned char> out(size + 1);  // one more: a stream longer than `size` shows itself
    z_stream stream{};
    if (inflateInit2(&stream, -MAX_WBITS) != Z_OK) fail(where_ + ": cannot start decompression");
    stream.next_in = const_cast<Bytef*>(raw_.data());
    stream.avail_in = static_cast<uInt>(raw_.size());
    stream.next_out = out.data();
    stream.avail_out = static_cast<uInt>(out.size());
    const int result = inflate(&stream, Z_FINISH);
    const size_t produced = out.size() - stream.avail_out;
    inflateEnd(&stream);
    if (result != Z_STREAM_END)
      fail(where_ + " (" + name_ + "): its deflate stream is " +
           (result == Z_BUF_ERROR && produced < out.size() ? "truncated" : "damaged or longer than its splats"));
    if (produced != size)
      fail(where_ + " (" + name_ + ") inflates to " + std::to_string(produced) + " bytes; its splats need " +
           std::to_string(size));
    out.resize(size);
    return out;
  }

  std::string where_;
  std::string name_, encoding_;
  std::span<const unsigned char> raw_;
  bool compressed_ = false;
  std::optional<double> min_, max_;
};

const json& member(const json& object, const char* key, const std::string& where) {
  if (!object.is_object() || !object.contains(key)) throw Property::Failure{where + " has no '" + key + "'"};
  return object[key];
}
uint64_t unsigned_member(const json& object, const char* key, const std::string& where) {
  const json& value = member(object, key, where);
  if (!value.is_number_unsigned()) throw Property::Failure{where + ": '" + key + "' is not an unsigned integer"};
  return value.get<uint64_t>();
}

// The JSON of a RAD0 or RADC block: magic, length, text padded to 8. Returns it and the offset past it.
std::pair<json, size_t> block_json(std::span<const unsigned char> data, uint32_t magic, const std::string& where) {
  if (data.size() < 8 || load_le<uint32_t>(data.data()) != magic)
    throw Property::Failure{where + ": no " + std::string(magic == kRadMagic ? "RAD0" : "RADC") + " magic"};
  const uint32_t length = load_le<uint32_t>(data.data() + 4);
  if (length > data.size() - 8)
    throw Property::Failure{where + ": its JSON (" + std::to_string(length) + " bytes) runs past the end"};
  const char* text = reinterpret_cast<const char*>(data.data() + 8);
  json meta = json::parse(text, text + length, nullptr, false);
  if (meta.is_discarded() || !meta.is_object()) throw Property::Failure{where + ": its JSON does not parse to an object"};
  return {std::move(meta), std::min(data.size(), 8 + round_up8(length))};
}

}  // namespace

bool is_rad(std::span<const std::byte> data) {
  if (data.size() < 4) return false;
  const uint32_t magic = load_le<uint32_t>(reinterpret_cast<const unsigned char*>(data.data()));
  return magic == kRadMagic || magic == kChunkMagic;
}

RadFile::RadFile(std::span<const std::byte> data, std::string_view name, const FileLoader& load_chunk)
    : name_(name) {
  read(std::span(reinterpret_cast<const unsigned char*>(data.data()), data.size()), load_chunk);
}

RadFile RadFile::chunk_of(std::span<const std::byte> data, std::string_view name, const FileLoader& load_chunk,
                          size_t chunk, const std::vector<float>& codebook) {
  RadFile file;
  file.name_ = name;
  file.only_chunk_ = chunk;
  file.sh_codes_ = codebook;
  file.read(std::span(reinterpret_cast<const unsigned char*>(data.data()), data.size()), load_chunk);
  return file;
}

RadFile::Chunking RadFile::chunking_of(std::span<const std::byte> data, std::string_view name) {
  const std::span<const unsigned char> bytes(reinterpret_cast<const unsigned char*>(data.data()), data.size());
  try {
    const bool alone = bytes.size() >= 4 && load_le<uint32_t>(bytes.data()) == kChunkMagic;
    const auto [meta, end] = block_json(bytes, alone ? kChunkMagic : kRadMagic, alone ? "chunk" : "header");
    Chunking chunking;
    chunking.count = unsigned_member(meta, "count", "header");
    chunking.chunks = alone ? 1 : member(meta, "chunks", "header").size();
    chunking.chunk_size = alone ? chunking.count
                                : meta.contains("chunkSize") ? unsigned_member(meta, "chunkSize", "header")
                                                             : chunking.count;
    const uint64_t degree = meta.contains("maxSh") ? unsigned_member(meta, "maxSh", "header") : 0;
    chunking.sh_degree = static_cast<int>(std::min<uint64_t>(degree, 3));
    return chunking;
  } catch (const Property::Failure& failure) {
    fail(name, failure.what);
  }
}

void RadFile::read(std::span<const unsigned char> bytes, const FileLoader& load_chunk) {
  const std::string_view name = name_;
  try {
    if (bytes.size() >= 4 && load_le<uint32_t>(bytes.data()) == kChunkMagic) {  // one chunk on its own
      read_chunk(bytes, "chunk", 0, 0, true);
      description_.chunks = 1;
      description_.splats = size();
    } else {
      const auto [meta, chunks_start] = block_json(bytes, kRadMagic, "header");
      if (unsigned_member(meta, "version", "header") != 1)
        throw Property::Failure{"unsupported RAD version " + meta["version"].dump() + " (supported: 1)"};
      if (member(meta, "type", "header") != "gsplat")
        throw Property::Failure{"unsupported RAD type " + meta["type"].dump() + " (supported: gsplat)"};
      const uint64_t count = unsigned_member(meta, "count", "header");
      const uint64_t sh_degree = meta.contains("maxSh") ? unsigned_member(meta, "maxSh", "header") : 0;
      if (sh_degree > 3) throw Property::Failure{"header: maxSh " + std::to_string(sh_degree) + " (at most 3)"};
      sh_degree_ = static_cast<int>(sh_degree);
      const uint64_t chunk_size = meta.contains("chunkSize") ? unsigned_member(meta, "chunkSize", "header") : count;
      const json& ranges = member(meta, "chunks", "header");
      if (!ranges.is_array()) throw Property::Failure{"header: 'chunks' is not an array"};
      if (count > 0 && chunk_size == 0) throw Property::Failure{"header: chunkSize is 0"};
      const uint64_t expected_chunks = count == 0 ? 0 : (count + chunk_size - 1) / chunk_size;
      if (ranges.size() != expected_chunks)
        throw Property::Failure{"header: " + std::to_string(ranges.size()) + " chunks for " + std::to_string(count) +
                                " splats in chunks of " + std::to_string(chunk_size) + " (expected " +
                                std::to_string(expected_chunks) + ")"};
      // Every splat takes at least a few bytes of some chunk: a count no file can hold is refused here.
      if (count > uint64_t(std::numeric_limits<int32_t>::max()) || count / 8 > bytes.size() * kMaxExpansion)
        throw Property::Failure{"header: " + std::to_string(count) + " splats, more than a " +
                                std::to_string(bytes.size()) + "-byte file can hold"};
      if (meta.contains("shCodeCount")) sh_code_count_ = unsigned_member(meta, "shCodeCount", "header");
      if (only_chunk_ != SIZE_MAX && only_chunk_ >= ranges.size())
        throw Property::Failure{"no chunk " + std::to_string(only_chunk_) + " (the file has " +
                                std::to_string(ranges.size()) + ")"};
      alpha_.resize(only_chunk_ == SIZE_MAX ? count
                                            : std::min<uint64_t>(chunk_size, count - only_chunk_ * chunk_size));
      rebase_ = only_chunk_ == SIZE_MAX ? 0 : only_chunk_ * chunk_size;
      const std::span<const unsigned char> chunk_bytes = bytes.subspan(chunks_start);
      for (size_t c = 0; c < ranges.size(); ++c) {
        if (only_chunk_ != SIZE_MAX && c != only_chunk_) continue;
        const std::string where = "chunk " + std::to_string(c);
        const json& range = ranges[c];
        const uint64_t length = unsigned_member(range, "bytes", where + " range");
        const size_t base = c * chunk_size, chunk_count = std::min<uint64_t>(chunk_size, count - base);
        if (range.contains("filename") && range["filename"].is_string()) {
          const std::string file = range["filename"].get<std::string>();
          if (!load_chunk) throw Property::Failure{where + " is the file '" + file + "': read the .rad from disk"};
          const std::vector<unsigned char> chunk = load_chunk(file);
          if (chunk.size() < length)
            throw Property::Failure{where + " ('" + file + "') holds " + std::to_string(chunk.size()) +
                                    " bytes; the header says " + std::to_string(length)};
          read_chunk(std::span(chunk).first(length), where + " ('" + file + "')", base, chunk_count, false);
        } else {
          const uint64_t offset = unsigned_member(range, "offset", where + " range");
          if (offset > chunk_bytes.size() || length > chunk_bytes.size() - offset)
            throw Property::Failure{where + " (bytes " + std::to_string(offset) + " to " +
                                    std::to_string(offset + length) + " after the header) runs past the end of the file"};
          read_chunk(chunk_bytes.subspan(offset, length), where, base, chunk_count, false);
        }
      }
      description_.chunks = ranges.size();
      description_.splats = count;
    }
    if (!sh_labels_.empty() && sh_codes_.size() != sh_code_count_ * kRestComponents[sh_degree_])
      throw Property::Failure{"SH labels without the codebook (sh1_code, ...) they index"};
  } catch (const Property::Failure& failure) {
    fail(name, failure.what);
  }
  description_.lod_tree = has_lod_tree();
  if (size() > 0 && only_chunk_ == SIZE_MAX) check_tree();
}

std::string RadFile::Description::format(size_t leaves) const {
  std::string text = "rad (" + std::to_string(chunks) + (chunks == 1 ? " chunk; " : " chunks; ");
  if (lod_tree)
    text += "LOD tree of " + std::to_string(splats) + " splats, its " + std::to_string(leaves) + " leaves read; ";
  return text + encodings + ")";
}

void RadFile::read_chunk(std::span<const unsigned char> chunk, std::string_view where_view, size_t expected_base,
                         size_t expected_count, bool alone) {
  const std::string where(where_view);
  const auto [meta, payload_size_at] = block_json(chunk, kChunkMagic, where);
  if (unsigned_member(meta, "version", where) != 1)
    throw Property::Failure{where + ": unsupported chunk version " + meta["version"].dump()};
  const uint64_t base = unsigned_member(meta, "base", where), count = unsigned_member(meta, "count", where);
  if (payload_size_at + 8 > chunk.size()) throw Property::Failure{where + ": truncated before its payload size"};
  const uint64_t payload_bytes = load_le<uint64_t>(chunk.data() + payload_size_at);
  const std::span<const unsigned char> after = chunk.subspan(payload_size_at + 8);
  if (payload_bytes > after.size())
    throw Property::Failure{where + ": its payload (" + std::to_string(payload_bytes) + " bytes) runs past the end (" +
                            std::to_string(after.size()) + " bytes)"};
  const std::span<const unsigned char> payload = after.first(payload_bytes);
  const bool lod_tree = meta.contains("lodTree") && meta["lodTree"] == true;
  if (alone) {
    if (count > payload_bytes * kMaxExpansion)
      throw Property::Failure{where + ": " + std::to_string(count) + " splats in a " + std::to_string(payload_bytes) +
                              "-byte payload"};
    const uint64_t degree = meta.contains("maxSh") ? unsigned_member(meta, "maxSh", where) : 0;
    if (degree > 3) throw Property::Failure{where + ": maxSh " + std::to_string(degree) + " (at most 3)"};
    sh_degree_ = static_cast<int>(degree);
    expected_base = 0;
    expected_count = count;
    alpha_.resize(count);
  } else if (base != expected_base || count != expected_count) {
    throw Property::Failure{where + " holds splats " + std::to_string(base) + " to " + std::to_string(base + count) +
                            "; the header's chunking puts " + std::to_string(expected_base) + " to " +
                            std::to_string(expected_base + expected_count) + " there"};
  }
  const size_t total = alpha_.size(), first = expected_base - rebase_, n = expected_count;
  const size_t sh_components = kRestComponents[sh_degree_];
  const auto resize_once = [total](std::vector<float>& v, size_t each) {
    if (v.empty()) v.resize(total * each);
  };
  resize_once(centers_, 3);
  resize_once(rgb_, 3);
  resize_once(scales_, 3);
  resize_once(quats_, 4);
  if (lod_tree) {
    if (child_count_.empty()) child_count_.resize(total), child_start_.resize(total);
  }

  const bool describe = description_.encodings.empty();  // the first chunk read names the encodings
  const json& properties = member(meta, "properties", where);
  if (!properties.is_array()) throw Property::Failure{where + ": 'properties' is not an array"};
  std::vector<std::string> seen;
  for (size_t p = 0; p < properties.size(); ++p) {
    Property property(properties[p], payload, where + " property " + std::to_string(p));
    const std::string& name = property.name();
    if (std::find(seen.begin(), seen.end(), name) != seen.end())
      throw Property::Failure{where + ": the property " + name + " appears twice"};
    seen.push_back(name);
    const auto store = [&](std::vector<float>& into, size_t components, const std::vector<double>& values,
                           size_t stride, size_t at) {
      for (size_t i = 0; i < n; ++i)
        for (size_t d = 0; d < components; ++d) into[(first + i) * stride + at + d] = to_float(values[i * components + d]);
    };
    if (name == kCenter.name) {
      store(centers_, 3, property.values(n, 3), 3, 0);
    } else if (name == kAlpha.name) {
      store(alpha_, 1, property.values(n, 1), 1, 0);
    } else if (name == kRgb.name) {
      store(rgb_, 3, property.values(n, 3), 3, 0);
    } else if (name == kScales.name) {
      store(scales_, 3, property.values(n, 3), 3, 0);
    } else if (name == kOrientation.name) {
      store(quats_, 4, property.quaternions(n), 4, 0);
    } else if (name == "sh1" || name == "sh2" || name == "sh3") {
      const int band = name[2] - '0';
      if (band > sh_degree_) continue;  // beyond maxSh: not drawn
      resize_once(sh_, sh_components);
      const size_t components = kBandComponents[band];
      store(sh_, components, property.values(n, components), sh_components, kRestComponents[band - 1]);
    } else if (name == "sh1_code" || name == "sh2_code" || name == "sh3_code") {
      const int band = name[2] - '0';
      if (band > sh_degree_) continue;
      if (sh_code_count_ == 0) throw Property::Failure{where + ": " + name + " without the header's shCodeCount"};
      if (sh_codes_.size() != sh_code_count_ * sh_components) sh_codes_.assign(sh_code_count_ * sh_components, 0.0f);
      const size_t components = kBandComponents[band];
      const std::vector<double> values = property.values(sh_code_count_, components);
      for (size_t i = 0; i < sh_code_count_; ++i)
        for (size_t d = 0; d < components; ++d)
          sh_codes_[i * sh_components + kRestComponents[band - 1] + d] = to_float(values[i * components + d]);
    } else if (name == kShLabel.name) {
      if (sh_labels_.empty()) sh_labels_.resize(total);
      const std::vector<double> labels = property.values(n, 1);
      for (size_t i = 0; i < n; ++i) {
        if (labels[i] >= double(sh_code_count_))
          throw Property::Failure{where + ": splat " + std::to_string(first + i) + "'s SH label " +
                                  std::to_string(uint64_t(labels[i])) + " is past the codebook (" +
                                  std::to_string(sh_code_count_) + " entries)"};
        sh_labels_[first + i] = static_cast<uint32_t>(labels[i]);
      }
    } else if (name == kChildCount.name || name == kChildStart.name) {
      if (!lod_tree) throw Property::Failure{where + ": " + name + " in a chunk that is not a LOD tree's"};
      const std::vector<double> values = property.values(n, 1);
      std::vector<uint32_t>& into = name == kChildCount.name ? child_count_ : child_start_;
      for (size_t i = 0; i < n; ++i) into[first + i] = static_cast<uint32_t>(values[i]);
    } else {
      throw Property::Failure{where + ": unknown property '" + name + "'"};
    }
    if (describe)
      description_.encodings += (description_.encodings.empty() ? "" : ", ") + name + " " + property.encoding();
  }
  std::vector<const char*> required = {kCenter.name, kAlpha.name, kRgb.name, kScales.name, kOrientation.name};
  if (lod_tree) required.insert(required.end(), {kChildCount.name, kChildStart.name});
  for (const char* name : required)
    if (std::find(seen.begin(), seen.end(), name) == seen.end())
      throw Property::Failure{where + " lacks the property " + std::string(name)};
  const bool labelled = std::find(seen.begin(), seen.end(), kShLabel.name) != seen.end();
  for (int band = 1; band <= sh_degree_ && !labelled; ++band)
    if (std::find(seen.begin(), seen.end(), "sh" + std::to_string(band)) == seen.end())
      throw Property::Failure{where + " lacks sh" + std::to_string(band) + ", which maxSh " +
                              std::to_string(sh_degree_) + " calls for"};
}

void RadFile::check_tree_of(std::string_view name, std::span<const uint32_t> counts,
                            std::span<const uint32_t> starts) {
  if (counts.empty()) return;
  try {
    // A tree: every node but the root (0) has one parent, and every node is reached from the root.
    const size_t total = counts.size();
    std::vector<uint8_t> parents(total, 0);
    for (size_t i = 0; i < total; ++i) {
      if (counts[i] == 0) continue;
      if (starts[i] >= total || counts[i] > total - starts[i])
        throw Property::Failure{"splat " + std::to_string(i) + "'s children (" + std::to_string(counts[i]) +
                                " from " + std::to_string(starts[i]) + ") are past the file's " +
                                std::to_string(total) + " splats"};
      for (size_t c = starts[i]; c < starts[i] + counts[i]; ++c)
        if (c == 0 || parents[c]++ > 0)
          throw Property::Failure{"splat " + std::to_string(c) + " has two parents in the LOD tree (" +
                                  std::to_string(i) + " is the second)"};
    }
    std::vector<uint32_t> stack = {0};
    size_t reached = 0;
    while (!stack.empty()) {
      const uint32_t node = stack.back();
      stack.pop_back();
      ++reached;
      for (uint32_t c = starts[node]; c < starts[node] + counts[node]; ++c) stack.push_back(c);
    }
    if (reached != total)
      throw Property::Failure{"the LOD tree reaches " + std::to_string(reached) + " of the file's " +
                              std::to_string(total) + " splats from its root"};
  } catch (const Property::Failure& failure) {
    fail(name, failure.what);
  }
}

double RadFile::node_size(size_t node) const {
  const double mean_scale = (double(scales_[3 * node]) + scales_[3 * node + 1] + scales_[3 * node + 2]) / 3;
  const double alpha = alpha_[node];
  const double expansion = alpha <= 1 ? 1.0 : 1 + 0.7 * (alpha * 4 - 3 - 1);
  return 2 * expansion * mean_scale;
}

std::vector<uint32_t> RadFile::leaves() const {
  std::vector<uint32_t> nodes;
  for (size_t i = 0; i < size(); ++i)
    if (!has_lod_tree() || child_count_[i] == 0) nodes.push_back(static_cast<uint32_t>(i));
  return nodes;
}

GaussianScene RadFile::decode(std::span<const uint32_t> nodes) const {
  GaussianScene scene;
  allocate_scene(scene, nodes.size(), sh_degree_);
  const size_t coefficients = static_cast<size_t>(scene.sh_coefficients());
  const size_t rest = 3 * (coefficients - 1);
  for (size_t out = 0; out < nodes.size(); ++out) {
    const size_t i = nodes[out];
    double alpha = alpha_[i], widen = 1;
    if (alpha > 1) {  // a merged node's wider kernel, as Spark's --inflate draws it with the Gaussian one
      const double a = std::min(alpha * 4 - 3, 5.0);
      widen = std::cbrt(std::exp((a * a - 1) / 2.718281828459045));
      alpha = 1;
    }
    for (size_t d = 0; d < 3; ++d) {
      scene.positions[3 * out + d] = centers_[3 * i + d];
      const double scale = scales_[3 * i + d] * widen;
      scene.log_scales[3 * out + d] = to_float(scale > 0 ? std::log(scale) : kZeroLogScale);
      scene.sh[3 * coefficients * out + d] = to_float((rgb_[3 * i + d] - 0.5) / kShC0);
    }
    scene.opacity_logits[out] = to_float(clamped_logit(alpha));
    const float* q = quats_.data() + 4 * i;  // x y z w
    scene.rotations[4 * out] = q[3];
    for (size_t d = 0; d < 3; ++d) scene.rotations[4 * out + 1 + d] = q[d];
    if (rest > 0) {
      const float* sh = sh_labels_.empty() ? sh_.data() + rest * i : sh_codes_.data() + rest * sh_labels_[i];
      std::copy(sh, sh + rest, scene.sh.data() + 3 * coefficients * out + 3);
    }
  }
  return scene;
}

}  // namespace tilesplat::detail
