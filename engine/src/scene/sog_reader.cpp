// Reader for PlayCanvas SOG ("spatially ordered Gaussians"), version 2, and the older version 1.
//
// A SOG is meta.json plus lossless WebP images in which texel i holds Gaussian i (row-major). It
// comes bundled (a .sog zip of them all, read with libzip) or unbundled (meta.json with the images
// beside it). Version 2's meta.json ("version": 2, "count"):
//   means   {mins, maxs, files: [low bytes, high bytes]}: 16-bit x y z (low | high << 8) over
//           [min, max] of sign(v) * log(|v| + 1), so v = sign(u) * (exp(|u|) - 1)
//   quats   {files: [q]}: smallest three, RGB = (c / sqrt2 + 1) * 127.5 of the other three
//           components in w x y z order, A = 252 + the index of the largest (w x y z)
//   scales  {codebook[256], files}: RGB index the codebook of log scales
//   sh0     {codebook[256], files}: RGB index the codebook of DC coefficients, A = sigmoid * 255
//   shN     {count, bands, codebook[256], files: [centroids, labels]}: the labels' RG is a 16-bit
//           palette index; palette entry e is row e / 64, texels (e % 64) * K + j for its K rest
//           coefficients j, whose RGB index the codebook
// Version 1 (no "version"; means.shape [count, 3]) has per-channel mins/maxs in place of codebooks.
// SOG stores the trainer's axes: no conversion.
#include <webp/decode.h>
#include <zip.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/scene_readers.h"
#include "scene/scene_reading.h"
#include "scene/sog_packed.h"

namespace tilesplat::detail {

using nlohmann::json;

// Reads meta.json and its images into a SogPacked (a friend of it).
class SogDecoder {
 public:
  SogDecoder(std::string_view name, const FileLoader& load) : name_(name), load_(load) {}

  [[noreturn]] void fail(const std::string& what) const { detail::fail(name_, what); }

  // Decodes one lossless WebP of the meta's `files`, checking it holds at least `min_texels` and at
  // most `max_texels` texels before decoding (a huge declared size is refused, not allocated).
  SogImage image(const std::string& file, size_t min_texels, size_t max_texels) const {
    const std::vector<unsigned char> bytes = load_(file);
    WebPBitstreamFeatures features;
    if (WebPGetFeatures(bytes.data(), bytes.size(), &features) != VP8_STATUS_OK)
      fail(file + ": not a WebP image (or a truncated one)");
    if (features.format != 2) fail(file + ": a lossy WebP; SOG images must be lossless");
    const size_t texels = static_cast<size_t>(features.width) * static_cast<size_t>(features.height);
    if (texels < min_texels || texels > max_texels)
      fail(file + ": a " + std::to_string(features.width) + "x" + std::to_string(features.height) +
           " image, the wrong size for " + std::to_string(min_texels) + " entries");
    SogImage result;
    result.width = features.width;
    result.height = features.height;
    result.rgba.resize(4 * texels);
    if (!WebPDecodeRGBAInto(bytes.data(), bytes.size(), result.rgba.data(), result.rgba.size(),
                            4 * features.width))
      fail(file + ": the WebP image does not decode");
    return result;
  }

  const json& member(const json& object, const char* key, const std::string& where) const {
    if (!object.is_object() || !object.contains(key)) fail("meta.json: " + where + " has no '" + key + "'");
    return object.at(key);
  }
  std::vector<double> numbers(const json& object, const char* key, size_t size,
                              const std::string& where) const {
    const json& value = member(object, key, where);
    if (!value.is_array() || value.size() != size)
      fail("meta.json: " + where + "." + key + " must be an array of " + std::to_string(size) + " numbers");
    std::vector<double> result;
    for (const json& item : value) {
      if (!item.is_number()) fail("meta.json: " + where + "." + key + " holds a value that is not a number");
      result.push_back(item.get<double>());
    }
    return result;
  }
  std::vector<float> codebook(const json& object, const std::string& where) const {
    std::vector<float> result;
    for (double value : numbers(object, "codebook", 256, where)) result.push_back(to_float(value));
    return result;
  }
  std::string file(const json& object, size_t index, const std::string& where) const {
    const json& files = member(object, "files", where);
    if (!files.is_array() || files.size() <= index || !files[index].is_string())
      fail("meta.json: " + where + ".files needs " + std::to_string(index + 1) + " file names");
    return files[index].get<std::string>();
  }
  double number(const json& object, const char* key, const std::string& where) const {
    const json& value = member(object, key, where);
    if (!value.is_number()) fail("meta.json: " + where + "." + key + " is not a number");
    return value.get<double>();
  }

  SogPacked decode(const json& meta) const {
    SogPacked packed;
    const bool v2 = meta.contains("version");
    if (v2 && !(meta["version"].is_number_integer() && meta["version"].get<int64_t>() == 2))
      fail("meta.json: unsupported SOG version " + meta["version"].dump() + " (supported: 1, 2)");
    packed.version_ = v2 ? "2" : "1";
    const json& means = member(meta, "means", "the meta");
    double declared = 0;
    if (v2) {
      declared = number(meta, "count", "the meta");
    } else {
      const std::vector<double> shape = numbers(means, "shape", 2, "means");
      declared = shape[0];
    }
    if (!(declared >= 0 && declared <= 4294967295.0) || declared != std::floor(declared))
      fail("meta.json: the count " + std::to_string(declared) + " is not a count of Gaussians");
    const size_t count = static_cast<size_t>(declared);
    // Texel i is Gaussian i, row-major, in rows of at most 16383 (WebP's limit), padded to whole
    // rows (writers round them up to multiples of 4): a larger image is not this scene's.
    constexpr size_t kMaxSide = 16383;
    if (count > kMaxSide * kMaxSide)
      fail("meta.json: " + std::to_string(count) + " Gaussians are more than a WebP image can hold");
    const size_t max_texels = count + 4 * kMaxSide;

    const json* sh_n = meta.contains("shN") ? &meta["shN"] : nullptr;
    if (sh_n) {
      if (v2) {
        const double bands = number(*sh_n, "bands", "shN");
        if (bands != 1 && bands != 2 && bands != 3) fail("meta.json: shN.bands must be 1, 2 or 3");
        packed.sh_degree_ = static_cast<int>(bands);
        const double entries = number(*sh_n, "count", "shN");
        if (!(entries >= 0 && entries <= 65536)) fail("meta.json: shN.count must be 0..65536");
        packed.palette_ = static_cast<size_t>(entries);
      }
      packed.labels_ = image(file(*sh_n, 1, "shN"), count, max_texels);
      // The palette's image: 64 entries a row, each K texels; its width tells version 1 the degree.
      packed.centroids_ = image(file(*sh_n, 0, "shN"), 1, 64 * 15 * (65536 / 64 + 1));
      const SogImage& centroids = packed.centroids_;
      if (!v2) {
        const int degree = centroids.width == 192   ? 1
                           : centroids.width == 512 ? 2
                           : centroids.width == 960 ? 3
                                                    : 0;
        if (degree == 0)
          fail(file(*sh_n, 0, "shN") + ": width " + std::to_string(centroids.width) +
               " is not a palette of 1, 2 or 3 SH bands (192, 512 or 960)");
        packed.sh_degree_ = degree;
        packed.palette_ =
            static_cast<size_t>(centroids.width / ((degree + 1) * (degree + 1) - 1)) * centroids.height;
      }
      const int rest = (packed.sh_degree_ + 1) * (packed.sh_degree_ + 1) - 1;
      if (centroids.width != 64 * rest)
        fail(file(*sh_n, 0, "shN") + ": width " + std::to_string(centroids.width) + " does not match " +
             std::to_string(packed.sh_degree_) + " SH bands (" + std::to_string(64 * rest) + ")");
      packed.sh_values_ = sh_values(*sh_n, v2);
    }

    // The means first: their images prove the count before anything is sized by it.
    {
      const SogImage low = image(file(means, 0, "means"), count, max_texels);
      const SogImage high = image(file(means, 1, "means"), count, max_texels);
      packed.positions_ = decode_means(means, low, high, count);
    }
    packed.quats_ = image(file(member(meta, "quats", "the meta"), 0, "quats"), count, max_texels);
    const json& scales = member(meta, "scales", "the meta");
    const json& sh0 = member(meta, "sh0", "the meta");
    packed.scales_ = image(file(scales, 0, "scales"), count, max_texels);
    packed.colours_ = image(file(sh0, 0, "sh0"), count, max_texels);
    if (v2) {
      const std::vector<float> scale_book = codebook(scales, "scales");
      const std::vector<float> colour_book = codebook(sh0, "sh0");
      for (size_t b = 0; b < 256; ++b) {
        for (size_t a = 0; a < 3; ++a) {
          packed.scale_values_[a][b] = scale_book[b];
          packed.colour_values_[a][b] = colour_book[b];
        }
        packed.colour_values_[3][b] = static_cast<float>(clamped_logit(static_cast<double>(b) / 255.0));
      }
    } else {
      // Version 1: per-channel linear ranges; sh0's fourth channel is the opacity logit itself.
      const std::vector<double> scale_min = numbers(scales, "mins", 3, "scales");
      const std::vector<double> scale_max = numbers(scales, "maxs", 3, "scales");
      const std::vector<double> colour_min = numbers(sh0, "mins", 4, "sh0");
      const std::vector<double> colour_max = numbers(sh0, "maxs", 4, "sh0");
      for (size_t b = 0; b < 256; ++b) {
        for (size_t a = 0; a < 3; ++a)
          packed.scale_values_[a][b] =
              to_float(scale_min[a] + (scale_max[a] - scale_min[a]) * (static_cast<double>(b) / 255.0));
        for (size_t a = 0; a < 4; ++a)
          packed.colour_values_[a][b] =
              to_float(colour_min[a] + (colour_max[a] - colour_min[a]) * (static_cast<double>(b) / 255.0));
      }
    }
    return packed;
  }

 private:
  std::vector<float> decode_means(const json& means, const SogImage& low, const SogImage& high,
                                  size_t count) const {
    const std::vector<double> mins = numbers(means, "mins", 3, "means");
    const std::vector<double> maxs = numbers(means, "maxs", 3, "means");
    std::vector<float> positions(3 * count);
    for (size_t i = 0; i < count; ++i)
      for (size_t a = 0; a < 3; ++a) {
        const double range = maxs[a] - mins[a] != 0 ? maxs[a] - mins[a] : 1.0;
        const double quantized = low.texel(i)[a] | (high.texel(i)[a] << 8);
        const double u = mins[a] + range * (quantized / 65535.0);
        const double magnitude = std::exp(std::fabs(u)) - 1.0;
        positions[3 * i + a] = to_float(u < 0 ? -magnitude : magnitude);
      }
    return positions;
  }

  // The SH rest's 256 values: version 2's codebook, version 1's linear range.
  std::array<float, 256> sh_values(const json& sh_n, bool v2) const {
    std::array<float, 256> values{};
    if (v2) {
      const std::vector<float> book = codebook(sh_n, "shN");
      std::copy(book.begin(), book.end(), values.begin());
      return values;
    }
    const double low = number(sh_n, "mins", "shN");
    const double high = number(sh_n, "maxs", "shN");
    for (size_t b = 0; b < 256; ++b)
      values[b] = to_float(low + (high - low) * (static_cast<double>(b) / 255.0));
    return values;
  }

  std::string_view name_;
  const FileLoader& load_;
};

template <typename IndexOf>
GaussianScene SogPacked::decode_each(size_t count, IndexOf index_of) const {
  GaussianScene scene;
  allocate_scene(scene, count, sh_degree_);
  const size_t rest = static_cast<size_t>(scene.sh_coefficients()) - 1;
  const size_t stride = 3 * (rest + 1);
  for (size_t out = 0; out < count; ++out) {
    const size_t i = index_of(out);
    std::copy_n(positions_.data() + 3 * i, 3, scene.positions.data() + 3 * out);

    const unsigned char* t = quats_.texel(i);
    float* q = scene.rotations.data() + 4 * out;
    if (t[3] < 252) {  // not a smallest-three tag: the reference decoders take the identity
      q[0] = 1;
      q[1] = q[2] = q[3] = 0;
    } else {
      const size_t largest = t[3] - 252u;
      double wxyz[4] = {0, 0, 0, 0};
      double sum = 0;
      for (size_t j = 0, k = 0; j < 4; ++j) {
        if (j == largest) continue;
        wxyz[j] = (t[k++] / 255.0 * 2.0 - 1.0) / std::sqrt(2.0);
        sum += wxyz[j] * wxyz[j];
      }
      wxyz[largest] = std::sqrt(std::max(0.0, 1.0 - sum));
      for (size_t j = 0; j < 4; ++j) q[j] = static_cast<float>(wxyz[j]);
    }

    const unsigned char* scale = scales_.texel(i);
    const unsigned char* colour = colours_.texel(i);
    for (size_t a = 0; a < 3; ++a) {
      scene.log_scales[3 * out + a] = scale_values_[a][scale[a]];
      scene.sh[stride * out + a] = colour_values_[a][colour[a]];
    }
    scene.opacity_logits[out] = colour_values_[3][colour[3]];

    if (rest == 0) continue;
    const size_t label = labels_.texel(i)[0] | (labels_.texel(i)[1] << 8);
    if (label >= palette_) continue;  // no palette entry: zero, as the reference decoders leave it
    const size_t row = label / 64;
    float* sh = scene.sh.data() + stride * out + 3;
    for (size_t j = 0; j < rest; ++j) {
      const size_t column = (label % 64) * rest + j;
      if (row >= static_cast<size_t>(centroids_.height)) break;
      const unsigned char* c = centroids_.texel(row * static_cast<size_t>(centroids_.width) + column);
      for (size_t k = 0; k < 3; ++k) sh[3 * j + k] = sh_values_[c[k]];
    }
  }
  return scene;
}

bool SogPacked::all_values_finite() const {
  const auto finite = [](const auto& values) {
    return std::all_of(values.begin(), values.end(), [](float v) { return std::isfinite(v); });
  };
  return finite(positions_) && finite(sh_values_) &&
         std::all_of(scale_values_.begin(), scale_values_.end(), finite) &&
         std::all_of(colour_values_.begin(), colour_values_.end(), finite);
}

GaussianScene SogPacked::decode(std::span<const uint32_t> indices) const {
  return decode_each(indices.size(), [&](size_t k) { return size_t(indices[k]); });
}

GaussianScene SogPacked::decode_range(size_t first, size_t end) const {
  return decode_each(end - first, [first](size_t k) { return first + k; });
}

namespace {

json parse_meta(std::string_view text, std::string_view name) {
  json meta = json::parse(text.begin(), text.end(), nullptr, false);
  if (meta.is_discarded()) fail(name, "meta.json is not valid JSON");
  if (!meta.is_object()) fail(name, "meta.json is not a JSON object");
  return meta;
}

// A zip opened from memory; entries are read whole, their declared sizes checked first.
class ZipArchive {
 public:
  ZipArchive(std::span<const std::byte> data, std::string_view name) : name_(name) {
    zip_error_t error;
    zip_error_init(&error);
    zip_source_t* source = zip_source_buffer_create(data.data(), data.size(), 0, &error);
    if (source) archive_ = zip_open_from_source(source, ZIP_RDONLY | ZIP_CHECKCONS, &error);
    if (!archive_) {
      const std::string message = zip_error_strerror(&error);
      if (source) zip_source_free(source);
      zip_error_fini(&error);
      detail::fail(name_, "not a readable zip archive (" + message + ")");
    }
    zip_error_fini(&error);
  }
  ~ZipArchive() {
    if (archive_) zip_discard(archive_);
  }
  ZipArchive(const ZipArchive&) = delete;
  ZipArchive& operator=(const ZipArchive&) = delete;

  bool contains(const std::string& entry) const { return zip_name_locate(archive_, entry.c_str(), 0) >= 0; }

  std::vector<unsigned char> read(const std::string& entry, uint64_t max_size) const {
    const zip_int64_t index = zip_name_locate(archive_, entry.c_str(), 0);
    if (index < 0) detail::fail(name_, "the SOG archive has no '" + entry + "'");
    zip_stat_t stat;
    zip_stat_init(&stat);
    if (zip_stat_index(archive_, static_cast<zip_uint64_t>(index), 0, &stat) != 0 ||
        !(stat.valid & ZIP_STAT_SIZE))
      detail::fail(name_, entry + ": cannot read its size in the zip");
    // Deflate expands at most about 1032 times: a bigger declared size is a bomb or a lie.
    const bool compressed_known = (stat.valid & ZIP_STAT_COMP_SIZE) != 0;
    if (stat.size > max_size || (compressed_known && stat.size > 1032 * stat.comp_size + 1024))
      detail::fail(name_,
                   entry + ": declares " + std::to_string(stat.size) +
                       " bytes uncompressed, more than such an entry can be; refusing to decompress it");
    zip_file_t* file = zip_fopen_index(archive_, static_cast<zip_uint64_t>(index), 0);
    if (!file) detail::fail(name_, entry + ": cannot open it in the zip (" + zip_strerror(archive_) + ")");
    std::vector<unsigned char> bytes(stat.size);
    const zip_int64_t got = bytes.empty() ? 0 : zip_fread(file, bytes.data(), bytes.size());
    unsigned char extra;
    const zip_int64_t more = zip_fread(file, &extra, 1);
    zip_fclose(file);
    if (got != static_cast<zip_int64_t>(bytes.size()) || more != 0)
      detail::fail(name_, entry + ": corrupt or truncated in the zip (" + std::to_string(got < 0 ? 0 : got) +
                              " of " + std::to_string(stat.size) + " bytes)");
    return bytes;
  }

 private:
  std::string_view name_;
  zip_t* archive_ = nullptr;
};

// Sizes past this are refused before reading: meta.json is a few kB, an image of 16M texels 64 MB.
constexpr uint64_t kMaxEntry = uint64_t(1) << 31;

}  // namespace

bool is_sog_meta(std::string_view json_text) {
  const json meta = json::parse(json_text.begin(), json_text.end(), nullptr, false);
  return meta.is_object() && meta.contains("means") && meta.contains("quats");
}

DeclaredCounts read_sog_meta_counts(std::string_view meta_json, std::string_view name) {
  const json meta = parse_meta(meta_json, name);
  const auto whole_number = [&](const json* value, double most) {
    if (!value || !value->is_number() || !(value->get<double>() >= 0 && value->get<double>() <= most))
      fail(name, "meta.json: not a version 2 count");
    return static_cast<size_t>(value->get<double>());
  };
  if (!meta.contains("version")) fail(name, "meta.json: version 1 does not declare its SH degree");
  DeclaredCounts counts;
  counts.count = whole_number(meta.contains("count") ? &meta["count"] : nullptr, 4294967295.0);
  if (meta.contains("shN"))
    counts.sh_degree = int(whole_number(meta["shN"].contains("bands") ? &meta["shN"]["bands"] : nullptr, 3));
  return counts;
}

DeclaredCounts read_sog_zip_counts(std::span<const std::byte> data, std::string_view name) {
  const ZipArchive archive(data, name);
  if (!archive.contains("meta.json")) fail(name, "a zip without meta.json, not a SOG archive");
  const std::vector<unsigned char> text = archive.read("meta.json", 64u << 20);
  return read_sog_meta_counts(std::string_view(reinterpret_cast<const char*>(text.data()), text.size()),
                              name);
}

SogPacked SogPacked::from_meta(std::string_view meta_json, std::string_view name,
                               const FileLoader& load_image) {
  SogPacked packed = SogDecoder(name, load_image).decode(parse_meta(meta_json, name));
  packed.format_ = "sog (unbundled)";
  return packed;
}

SogPacked SogPacked::from_zip(std::span<const std::byte> data, std::string_view name) {
  const ZipArchive archive(data, name);
  if (!archive.contains("meta.json")) fail(name, "a zip without meta.json, not a SOG archive");
  const std::vector<unsigned char> text = archive.read("meta.json", 64u << 20);
  const json meta =
      parse_meta(std::string_view(reinterpret_cast<const char*>(text.data()), text.size()), name);
  const FileLoader load = [&](const std::string& entry) { return archive.read(entry, kMaxEntry); };
  SogPacked packed = SogDecoder(name, load).decode(meta);
  packed.format_ = "sog";
  return packed;
}

namespace {

GaussianScene read_packed(const SogPacked& packed, std::string_view name, const LoadOptions& options,
                          LoadReport* report) {
  GaussianScene scene = packed.decode_range(0, packed.size());
  finish_scene(scene, name, options, packed.format(), packed.version(), report);
  return scene;
}

}  // namespace

GaussianScene read_sog_meta(std::string_view meta_json, std::string_view name, const FileLoader& load_image,
                            const LoadOptions& options, LoadReport* report) {
  return read_packed(SogPacked::from_meta(meta_json, name, load_image), name, options, report);
}

GaussianScene read_sog_zip(std::span<const std::byte> data, std::string_view name, const LoadOptions& options,
                           LoadReport* report) {
  return read_packed(SogPacked::from_zip(data, name), name, options, report);
}

}  // namespace tilesplat::detail
