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

namespace tilesplat::detail {
namespace {

using nlohmann::json;

struct Image {
  int width = 0;
  int height = 0;
  std::vector<unsigned char> rgba;
  const unsigned char* texel(size_t i) const { return rgba.data() + 4 * i; }
};

class SogDecoder {
 public:
  SogDecoder(std::string_view name, const FileLoader& load) : name_(name), load_(load) {}

  [[noreturn]] void fail(const std::string& what) const { detail::fail(name_, what); }

  // Decodes one lossless WebP of the meta's `files`, checking it holds at least `min_texels` and at
  // most `max_texels` texels before decoding (a huge declared size is refused, not allocated).
  Image image(const std::string& file, size_t min_texels, size_t max_texels) const {
    const std::vector<unsigned char> bytes = load_(file);
    WebPBitstreamFeatures features;
    if (WebPGetFeatures(bytes.data(), bytes.size(), &features) != VP8_STATUS_OK)
      fail(file + ": not a WebP image (or a truncated one)");
    if (features.format != 2) fail(file + ": a lossy WebP; SOG images must be lossless");
    const size_t texels = static_cast<size_t>(features.width) * static_cast<size_t>(features.height);
    if (texels < min_texels || texels > max_texels)
      fail(file + ": a " + std::to_string(features.width) + "x" + std::to_string(features.height) +
           " image, the wrong size for " + std::to_string(min_texels) + " entries");
    Image result;
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

  GaussianScene decode(const json& meta) const {
    const bool v2 = meta.contains("version");
    if (v2 && !(meta["version"].is_number_integer() && meta["version"].get<int64_t>() == 2))
      fail("meta.json: unsupported SOG version " + meta["version"].dump() + " (supported: 1, 2)");
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

    int sh_degree = 0;
    const json* sh_n = meta.contains("shN") ? &meta["shN"] : nullptr;
    Image centroids, labels;
    size_t palette = 0;
    if (sh_n) {
      if (v2) {
        const double bands = number(*sh_n, "bands", "shN");
        if (bands != 1 && bands != 2 && bands != 3) fail("meta.json: shN.bands must be 1, 2 or 3");
        sh_degree = static_cast<int>(bands);
        const double entries = number(*sh_n, "count", "shN");
        if (!(entries >= 0 && entries <= 65536)) fail("meta.json: shN.count must be 0..65536");
        palette = static_cast<size_t>(entries);
      }
      labels = image(file(*sh_n, 1, "shN"), count, max_texels);
      // The palette's image: 64 entries a row, each K texels; its width tells version 1 the degree.
      centroids = image(file(*sh_n, 0, "shN"), 1, 64 * 15 * (65536 / 64 + 1));
      if (!v2) {
        sh_degree = centroids.width == 192 ? 1 : centroids.width == 512 ? 2 : centroids.width == 960 ? 3 : 0;
        if (sh_degree == 0)
          fail(file(*sh_n, 0, "shN") + ": width " + std::to_string(centroids.width) +
               " is not a palette of 1, 2 or 3 SH bands (192, 512 or 960)");
        palette =
            static_cast<size_t>(centroids.width / ((sh_degree + 1) * (sh_degree + 1) - 1)) * centroids.height;
      }
      const int rest = (sh_degree + 1) * (sh_degree + 1) - 1;
      if (centroids.width != 64 * rest)
        fail(file(*sh_n, 0, "shN") + ": width " + std::to_string(centroids.width) + " does not match " +
             std::to_string(sh_degree) + " SH bands (" + std::to_string(64 * rest) + ")");
    }

    // The means first: their images prove the count before the scene is sized by it.
    const Image low = image(file(means, 0, "means"), count, max_texels);
    const Image high = image(file(means, 1, "means"), count, max_texels);
    GaussianScene scene;
    allocate_scene(scene, count, sh_degree);
    decode_means(means, low, high, count, scene);
    decode_quats(meta, count, max_texels, scene);
    decode_scales_and_colours(meta, v2, count, max_texels, scene);
    if (sh_n) decode_sh(*sh_n, v2, centroids, labels, palette, scene);
    return scene;
  }

 private:
  void decode_means(const json& means, const Image& low, const Image& high, size_t count,
                    GaussianScene& scene) const {
    const std::vector<double> mins = numbers(means, "mins", 3, "means");
    const std::vector<double> maxs = numbers(means, "maxs", 3, "means");
    for (size_t i = 0; i < count; ++i)
      for (size_t a = 0; a < 3; ++a) {
        const double range = maxs[a] - mins[a] != 0 ? maxs[a] - mins[a] : 1.0;
        const double quantized = low.texel(i)[a] | (high.texel(i)[a] << 8);
        const double u = mins[a] + range * (quantized / 65535.0);
        const double magnitude = std::exp(std::fabs(u)) - 1.0;
        scene.positions[3 * i + a] = to_float(u < 0 ? -magnitude : magnitude);
      }
  }

  void decode_quats(const json& meta, size_t count, size_t max_texels, GaussianScene& scene) const {
    const Image quats = image(file(member(meta, "quats", "the meta"), 0, "quats"), count, max_texels);
    for (size_t i = 0; i < count; ++i) {
      const unsigned char* t = quats.texel(i);
      float* q = scene.rotations.data() + 4 * i;
      if (t[3] < 252) {  // not a smallest-three tag: the reference decoders take the identity
        q[0] = 1;
        q[1] = q[2] = q[3] = 0;
        continue;
      }
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
  }

  void decode_scales_and_colours(const json& meta, bool v2, size_t count, size_t max_texels,
                                 GaussianScene& scene) const {
    const json& scales = member(meta, "scales", "the meta");
    const json& sh0 = member(meta, "sh0", "the meta");
    const Image scale_image = image(file(scales, 0, "scales"), count, max_texels);
    const Image colour_image = image(file(sh0, 0, "sh0"), count, max_texels);
    const size_t stride = 3 * static_cast<size_t>(scene.sh_coefficients());
    if (v2) {
      const std::vector<float> scale_book = codebook(scales, "scales");
      const std::vector<float> colour_book = codebook(sh0, "sh0");
      for (size_t i = 0; i < count; ++i) {
        for (size_t a = 0; a < 3; ++a) {
          scene.log_scales[3 * i + a] = scale_book[scale_image.texel(i)[a]];
          scene.sh[stride * i + a] = colour_book[colour_image.texel(i)[a]];
        }
        scene.opacity_logits[i] = static_cast<float>(clamped_logit(colour_image.texel(i)[3] / 255.0));
      }
      return;
    }
    // Version 1: per-channel linear ranges; sh0's fourth channel is the opacity logit itself.
    const std::vector<double> scale_min = numbers(scales, "mins", 3, "scales");
    const std::vector<double> scale_max = numbers(scales, "maxs", 3, "scales");
    const std::vector<double> colour_min = numbers(sh0, "mins", 4, "sh0");
    const std::vector<double> colour_max = numbers(sh0, "maxs", 4, "sh0");
    for (size_t i = 0; i < count; ++i) {
      for (size_t a = 0; a < 3; ++a) {
        scene.log_scales[3 * i + a] =
            to_float(scale_min[a] + (scale_max[a] - scale_min[a]) * (scale_image.texel(i)[a] / 255.0));
        scene.sh[stride * i + a] =
            to_float(colour_min[a] + (colour_max[a] - colour_min[a]) * (colour_image.texel(i)[a] / 255.0));
      }
      scene.opacity_logits[i] =
          to_float(colour_min[3] + (colour_max[3] - colour_min[3]) * (colour_image.texel(i)[3] / 255.0));
    }
  }

  void decode_sh(const json& sh_n, bool v2, const Image& centroids, const Image& labels, size_t palette,
                 GaussianScene& scene) const {
    const size_t count = scene.size();
    const size_t rest = static_cast<size_t>(scene.sh_coefficients()) - 1;
    const size_t stride = 3 * (rest + 1);
    std::vector<float> book(256);
    if (v2) {
      book = codebook(sh_n, "shN");
    } else {
      const double low = number(sh_n, "mins", "shN");
      const double high = number(sh_n, "maxs", "shN");
      for (size_t b = 0; b < 256; ++b)
        book[b] = to_float(low + (high - low) * (static_cast<double>(b) / 255.0));
    }
    for (size_t i = 0; i < count; ++i) {
      const size_t label = labels.texel(i)[0] | (labels.texel(i)[1] << 8);
      float* out = scene.sh.data() + stride * i + 3;
      if (label >= palette) continue;  // no palette entry: zero, as the reference decoders leave it
      const size_t row = label / 64;
      for (size_t j = 0; j < rest; ++j) {
        const size_t column = (label % 64) * rest + j;
        if (row >= static_cast<size_t>(centroids.height)) break;
        const unsigned char* t = centroids.texel(row * static_cast<size_t>(centroids.width) + column);
        for (size_t c = 0; c < 3; ++c) out[3 * j + c] = book[t[c]];
      }
    }
  }

  std::string_view name_;
  const FileLoader& load_;
};

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

GaussianScene read_sog_meta(std::string_view meta_json, std::string_view name, const FileLoader& load_image,
                            const LoadOptions& options, LoadReport* report) {
  const json meta = parse_meta(meta_json, name);
  GaussianScene scene = SogDecoder(name, load_image).decode(meta);
  finish_scene(scene, name, options, "sog (unbundled)", meta.contains("version") ? "2" : "1", report);
  return scene;
}

GaussianScene read_sog_zip(std::span<const std::byte> data, std::string_view name, const LoadOptions& options,
                           LoadReport* report) {
  const ZipArchive archive(data, name);
  if (!archive.contains("meta.json")) fail(name, "a zip without meta.json, not a SOG archive");
  const std::vector<unsigned char> text = archive.read("meta.json", 64u << 20);
  const json meta =
      parse_meta(std::string_view(reinterpret_cast<const char*>(text.data()), text.size()), name);
  const FileLoader load = [&](const std::string& entry) { return archive.read(entry, kMaxEntry); };
  GaussianScene scene = SogDecoder(name, load).decode(meta);
  finish_scene(scene, name, options, "sog", meta.contains("version") ? "2" : "1", report);
  return scene;
}

}  // namespace tilesplat::detail
