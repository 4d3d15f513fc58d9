// Reader for GaussianSplats3D's .ksplat, its viewer's format for preprocessed scenes (SplatBuffer, format
// version 0.1; the layout is that of src/loaders/SplatBuffer.js in mkkellogg/GaussianSplats3D).
//
// All little-endian. A header of 4096 bytes, zero where unused:
//   uint8 [0] [1] version major, minor; uint32 [1] sections, [3] splats; uint16 [10] compression level;
//   float32 [6..8] the scene's centre, [9] [10] the range of level 2's 8-bit SH (0: -1.5 and 1.5).
// One header of 1024 bytes a section:
//   uint32 [1] splats, [2] splats a full bucket, [3] buckets, float32 [4] a bucket's block size, uint16 [10]
//   bytes a bucket, uint32 [6] the positions' range (0: the level's, 1 or 32767), [8] full buckets, [9]
//   partly full buckets; uint16 [20] the section's SH degree (0 to 2).
// Then each section: the partly full buckets' lengths (uint32), the buckets' centres (3 float32), then
// its splats, bucket after bucket (the full ones first):
//   level 0     float32 x y z, linear scales, quaternion w x y z; uint8 r g b a; float32 SH
//   levels 1-2  uint16 x y z, each (p - range) * block / 2 / range from its bucket's centre; float16
//               linear scales and quaternion; uint8 r g b a; SH float16 (level 1) or uint8 (level 2, the
//               header's range in 255 steps)
// r g b are floor((0.5 + SH_C0 dc) 255) and a floor(sigmoid(opacity) 255), as in .splat files. The SH
// beyond DC are channel-major within each degree: degree 1's three coefficients of R, of G, of B, then
// degree 2's five of R, G, B.
#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "scene/scene_readers.h"
#include "scene/scene_reading.h"

namespace tilesplat::detail {
namespace {

constexpr size_t kHeaderBytes = 4096;
constexpr size_t kSectionHeaderBytes = 1024;
constexpr size_t kUsedHeaderBytes = 44;  // words 0 to 10; the rest of the header is zero
constexpr double kShC0 = 0.28209479177387814;
constexpr double kDefaultShHalfRange = 1.5;  // GaussianSplats3D's SphericalHarmonics8BitCompressionRange / 2
// A scale that float16 rounded to zero was below its smallest subnormal, 2^-24: it is read as half that.
constexpr double kLogHalfUnderflow = -25 * 0.6931471805599453;

struct Header {
  unsigned major = 0, minor = 0;
  uint32_t sections = 0;
  uint32_t splats = 0;
  unsigned level = 0;
  float sh_min = 0, sh_max = 0;
};

struct Section {
  uint32_t splats = 0;
  uint32_t bucket_size = 0, buckets = 0, full_buckets = 0, partial_buckets = 0;
  float block_size = 0;
  uint32_t bucket_bytes = 0;
  uint32_t position_range = 0;
  int sh_degree = 0;
  uint64_t bytes_per_splat = 0;
  uint64_t begin = 0;  // the section's first byte in the file
  uint64_t bytes() const { return uint64_t(partial_buckets) * 4 + uint64_t(bucket_bytes) * buckets + bytes_per_splat * splats; }
};

// Bytes of a splat at `level` with SH of `degree` (0, 1 or 2): 3, 8 or 24 coefficients of SH beyond DC.
uint64_t bytes_per_splat(unsigned level, int degree) {
  const uint64_t sh_values = degree == 0 ? 0 : degree == 1 ? 9 : 24;
  if (level == 0) return 12 + 12 + 16 + 4 + 4 * sh_values;
  return 6 + 6 + 8 + 4 + (level == 1 ? 2 : 1) * sh_values;
}

std::string level_description(unsigned level) {
  switch (level) {
    case 0: return "level 0 (float32)";
    case 1: return "level 1 (float16, 16-bit positions in buckets)";
    default: return "level 2 (float16, 16-bit positions in buckets, 8-bit SH)";
  }
}

Header read_header(const unsigned char* bytes, size_t size, std::string_view name) {
  if (size < kHeaderBytes)
    fail(name, "not a whole .ksplat file: " + std::to_string(size) + " bytes, less than its 4096-byte header");
  Header h;
  h.major = bytes[0];
  h.minor = bytes[1];
  h.sections = load_le<uint32_t>(bytes + 4);
  h.splats = load_le<uint32_t>(bytes + 12);
  h.level = load_le<uint16_t>(bytes + 20);
  h.sh_min = load_le<float>(bytes + 36);
  h.sh_max = load_le<float>(bytes + 40);
  // JavaScript's `x || default`: 0 and NaN take the default.
  if (!(h.sh_min != 0)) h.sh_min = float(-kDefaultShHalfRange);
  if (!(h.sh_max != 0)) h.sh_max = float(kDefaultShHalfRange);
  if (h.major != 0 || h.minor < 1)
    fail(name, ".ksplat version " + std::to_string(h.major) + "." + std::to_string(h.minor) +
                   " is not supported (only 0.1 and later 0.x, as GaussianSplats3D's viewer reads)");
  if (h.level > 2) fail(name, ".ksplat compression level " + std::to_string(h.level) + " is not 0, 1 or 2");
  if (h.sections == 0) fail(name, ".ksplat header declares no sections");
  if (!std::isfinite(h.sh_min) || !std::isfinite(h.sh_max) || h.sh_min >= h.sh_max)
    fail(name, ".ksplat header's SH range [" + std::to_string(h.sh_min) + ", " + std::to_string(h.sh_max) +
                   "] is not an interval");
  return h;
}

Section read_section(const unsigned char* at, const Header& h, size_t index, std::string_view name) {
  const std::string which = ".ksplat section " + std::to_string(index) + ": ";
  Section s;
  s.splats = load_le<uint32_t>(at + 4);
  s.bucket_size = load_le<uint32_t>(at + 8);
  s.buckets = load_le<uint32_t>(at + 12);
  s.block_size = load_le<float>(at + 16);
  s.bucket_bytes = load_le<uint16_t>(at + 20);
  s.position_range = load_le<uint32_t>(at + 24);
  if (s.position_range == 0) s.position_range = h.level == 0 ? 1 : 32767;
  s.full_buckets = load_le<uint32_t>(at + 32);
  s.partial_buckets = load_le<uint32_t>(at + 36);
  s.sh_degree = load_le<uint16_t>(at + 40);
  if (s.sh_degree > 2) fail(name, which + "SH degree " + std::to_string(s.sh_degree) + " (the format has 0 to 2)");
  s.bytes_per_splat = bytes_per_splat(h.level, s.sh_degree);
  if (h.level >= 1) {
    if (s.bucket_bytes != 12) fail(name, which + std::to_string(s.bucket_bytes) + " bytes a bucket, not 12");
    if (uint64_t(s.full_buckets) + s.partial_buckets != s.buckets)
      fail(name, which + std::to_string(s.full_buckets) + " full and " + std::to_string(s.partial_buckets) +
                     " partly full buckets are not its " + std::to_string(s.buckets) + " buckets");
    if (!(s.block_size > 0) || !std::isfinite(s.block_size))
      fail(name, which + "bucket block size " + std::to_string(s.block_size) + " is not positive");
    if (uint64_t(s.full_buckets) * s.bucket_size > s.splats)
      fail(name, which + "its full buckets hold more than its " + std::to_string(s.splats) + " splats");
  }
  return s;
}

// Each splat's bucket, in file order: the full buckets' splats, then each partly full one's.
std::vector<uint32_t> splat_buckets(const unsigned char* bytes, const Section& s, std::string_view name,
                                    size_t index) {
  std::vector<uint32_t> bucket_of;
  bucket_of.reserve(s.splats);
  for (uint32_t b = 0; b < s.full_buckets; ++b) bucket_of.insert(bucket_of.end(), s.bucket_size, b);
  for (uint32_t p = 0; p < s.partial_buckets; ++p) {
    const uint32_t length = load_le<uint32_t>(bytes + s.begin + 4 * uint64_t(p));
    if (length > s.splats - bucket_of.size())
      fail(name, ".ksplat section " + std::to_string(index) + ": its partly full buckets hold more than its " +
                     std::to_string(s.splats) + " splats");
    bucket_of.insert(bucket_of.end(), length, s.full_buckets + p);
  }
  if (bucket_of.size() != s.splats)
    fail(name, ".ksplat section " + std::to_string(index) + ": its buckets hold " + std::to_string(bucket_of.size()) +
                   " splats, not its " + std::to_string(s.splats));
  return bucket_of;
}

// Index of SH coefficient k (1 to 8) of channel c in a splat's stored SH: channel-major per degree.
size_t stored_sh_index(int k, int c) { return k <= 3 ? size_t(3 * c + (k - 1)) : size_t(9 + 5 * c + (k - 4)); }

void read_section_splats(const unsigned char* bytes, const Header& h, const Section& s, size_t index,
                         size_t first, GaussianScene& scene, std::string_view name) {
  const std::vector<uint32_t> bucket_of = h.level >= 1 ? splat_buckets(bytes, s, name, index) : std::vector<uint32_t>{};
  const unsigned char* centres = bytes + s.begin + 4 * uint64_t(s.partial_buckets);
  const unsigned char* splats = centres + uint64_t(s.bucket_bytes) * s.buckets;
  const size_t k_count = size_t(scene.sh_coefficients());
  auto half = [](const unsigned char* at) { return double(glm::unpackHalf1x16(load_le<uint16_t>(at))); };
  auto log_scale = [&](double scale) {
    return to_float(h.level >= 1 && scale == 0 ? kLogHalfUnderflow : std::log(scale));
  };
  const double position_step = double(s.block_size) / 2 / double(s.position_range);
  for (uint32_t j = 0; j < s.splats; ++j) {
    const unsigned char* splat = splats + uint64_t(j) * s.bytes_per_splat;
    const size_t i = first + j;
    const unsigned char* colour = nullptr;
    const unsigned char* sh = nullptr;
    if (h.level == 0) {
      for (size_t a = 0; a < 3; ++a) {
        scene.positions[3 * i + a] = load_le<float>(splat + 4 * a);
        scene.log_scales[3 * i + a] = log_scale(load_le<float>(splat + 12 + 4 * a));
      }
      for (size_t a = 0; a < 4; ++a) scene.rotations[4 * i + a] = load_le<float>(splat + 24 + 4 * a);
      colour = splat + 40;
      sh = splat + 44;
    } else {
      const unsigned char* centre = centres + 12 * uint64_t(bucket_of[j]);
      for (size_t a = 0; a < 3; ++a) {
        const double stored = load_le<uint16_t>(splat + 2 * a);
        scene.positions[3 * i + a] = to_float((stored - double(s.position_range)) * position_step +
                                              double(load_le<float>(centre + 4 * a)));
        scene.log_scales[3 * i + a] = log_scale(half(splat + 6 + 2 * a));
      }
      for (size_t a = 0; a < 4; ++a) scene.rotations[4 * i + a] = float(half(splat + 12 + 2 * a));
      colour = splat + 20;
      sh = splat + 24;
    }
    for (size_t c = 0; c < 3; ++c) scene.sh[i * k_count * 3 + c] = float((colour[c] / 255.0 - 0.5) / kShC0);
    scene.opacity_logits[i] = float(clamped_logit(colour[3] / 255.0));
    const int stored_k = (s.sh_degree + 1) * (s.sh_degree + 1);
    for (int k = 1; k < stored_k; ++k)
      for (int c = 0; c < 3; ++c) {
        const size_t at = stored_sh_index(k, c);
        double value = 0;
        if (h.level == 0) value = load_le<float>(sh + 4 * at);
        else if (h.level == 1) value = half(sh + 2 * at);
        else value = sh[at] / 255.0 * (double(h.sh_max) - double(h.sh_min)) + double(h.sh_min);
        scene.sh[(i * k_count + size_t(k)) * 3 + size_t(c)] = to_float(value);
      }
  }
}

}  // namespace

bool is_ksplat(std::span<const std::byte> data) {
  if (data.size() < kHeaderBytes) return false;
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  // Version 0.x, the unused header bytes zero, a level of 0 to 2 and at least one section.
  if (bytes[0] != 0 || bytes[1] == 0 || bytes[2] != 0 || bytes[3] != 0 || load_le<uint16_t>(bytes + 22) != 0)
    return false;
  if (load_le<uint16_t>(bytes + 20) > 2 || load_le<uint32_t>(bytes + 4) == 0) return false;
  return std::all_of(bytes + kUsedHeaderBytes, bytes + kHeaderBytes, [](unsigned char b) { return b == 0; });
}

GaussianScene read_ksplat(std::span<const std::byte> data, std::string_view name, const LoadOptions& options,
                          LoadReport* report) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  const Header h = read_header(bytes, data.size(), name);
  require_bytes(name, ".ksplat section headers", h.sections, kSectionHeaderBytes, data.size() - kHeaderBytes);
  std::vector<Section> sections;
  uint64_t at = kHeaderBytes + uint64_t(h.sections) * kSectionHeaderBytes;
  uint64_t splats = 0;
  int sh_degree = 0;
  for (size_t index = 0; index < h.sections; ++index) {
    Section s = read_section(bytes + kHeaderBytes + index * kSectionHeaderBytes, h, index, name);
    s.begin = at;
    if (s.bytes() > data.size() - at)
      fail(name, ".ksplat section " + std::to_string(index) + " (" + std::to_string(s.splats) +
                     " splats) ends past the file's end: the file is truncated");
    at += s.bytes();
    splats += s.splats;
    sh_degree = std::max(sh_degree, s.sh_degree);
    sections.push_back(s);
  }
  if (splats != h.splats)
    fail(name, ".ksplat header declares " + std::to_string(h.splats) + " splats, its sections hold " +
                   std::to_string(splats));
  GaussianScene scene;
  allocate_scene(scene, size_t(splats), sh_degree);
  size_t first = 0;
  for (size_t index = 0; index < sections.size(); ++index) {
    read_section_splats(bytes, h, sections[index], index, first, scene, name);
    first += sections[index].splats;
  }
  finish_scene(scene, name, options, "ksplat " + level_description(h.level),
               std::to_string(h.major) + "." + std::to_string(h.minor), report);
  return scene;
}

}  // namespace tilesplat::detail
