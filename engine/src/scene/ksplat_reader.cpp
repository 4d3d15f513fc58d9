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

#include "scene/ksplat_packed.h"
#include "scene/scene_readers.h"
#include "scene/scene_reading.h"

namespace tilesplat::detail {
namespace {

constexpr size_t kHeaderBytes = 4096;
constexpr size_t kSectionHeaderBytes = 1024;
constexpr size_t kUsedHeaderBytes = 44;  // words 0 to 10; the rest of the header is zero
constexpr double kDefaultShHalfRange = 1.5;  // GaussianSplats3D's SphericalHarmonics8BitCompressionRange / 2
// A scale that float16 rounded to zero was below its smallest subnormal, 2^-24: it is read as half that.
constexpr double kLogHalfUnderflow = -25 * 0.6931471805599453;

// Bytes of a splat at `level` with SH of `degree` (0, 1 or 2): 0, 9 or 24 SH values beyond DC.
uint64_t bytes_per_splat(unsigned level, int degree) {
  const uint64_t sh_values = degree == 0 ? 0 : degree == 1 ? 9 : 24;
  if (level == 0) return 12 + 12 + 16 + 4 + 4 * sh_values;
  return 6 + 6 + 8 + 4 + (level == 1 ? 2 : 1) * sh_values;
}

// Index of SH coefficient k (1 to 8) of channel c in a splat's stored SH: channel-major per degree.
size_t stored_sh_index(int k, int c) { return k <= 3 ? size_t(3 * c + (k - 1)) : size_t(9 + 5 * c + (k - 4)); }

double half_at(const unsigned char* at) { return double(glm::unpackHalf1x16(load_le<uint16_t>(at))); }

using Section = KsplatPacked::Section;

Section read_section(const unsigned char* at, unsigned level, size_t index, std::string_view name) {
  const std::string which = ".ksplat section " + std::to_string(index) + ": ";
  Section s;
  s.splats = load_le<uint32_t>(at + 4);
  s.bucket_size = load_le<uint32_t>(at + 8);
  s.buckets = load_le<uint32_t>(at + 12);
  s.block_size = load_le<float>(at + 16);
  s.bucket_bytes = load_le<uint16_t>(at + 20);
  s.position_range = load_le<uint32_t>(at + 24);
  if (s.position_range == 0) s.position_range = level == 0 ? 1 : 32767;
  s.full_buckets = load_le<uint32_t>(at + 32);
  s.partial_buckets = load_le<uint32_t>(at + 36);
  s.sh_degree = load_le<uint16_t>(at + 40);
  if (s.sh_degree > 2) fail(name, which + "SH degree " + std::to_string(s.sh_degree) + " (the format has 0 to 2)");
  s.bytes_per_splat = bytes_per_splat(level, s.sh_degree);
  if (level >= 1) {
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

// The partly full buckets' lengths as running ends, after the full buckets' splats; they must end at the
// section's last splat.
void read_buckets(const unsigned char* bytes, Section& s, std::string_view name, size_t index) {
  uint64_t end = uint64_t(s.full_buckets) * s.bucket_size;
  s.partial_ends.reserve(s.partial_buckets);
  for (uint32_t p = 0; p < s.partial_buckets; ++p) {
    end += load_le<uint32_t>(bytes + s.begin + 4 * uint64_t(p));
    if (end > s.splats) break;
    s.partial_ends.push_back(uint32_t(end));
  }
  if (end != s.splats)
    fail(name, ".ksplat section " + std::to_string(index) + ": its buckets hold " +
                   (end > s.splats ? "more than" : std::to_string(end) + " splats, not") + " its " +
                   std::to_string(s.splats) + " splats");
}

}  // namespace

uint64_t KsplatPacked::Section::bytes() const {
  return uint64_t(partial_buckets) * 4 + uint64_t(bucket_bytes) * buckets + bytes_per_splat * splats;
}

KsplatPacked::KsplatPacked(std::span<const std::byte> data, std::string_view name)
    : bytes_(reinterpret_cast<const unsigned char*>(data.data())) {
  if (data.size() < kHeaderBytes)
    fail(name, "not a whole .ksplat file: " + std::to_string(data.size()) +
                   " bytes, less than its 4096-byte header");
  major_ = bytes_[0];
  minor_ = bytes_[1];
  const uint32_t sections = load_le<uint32_t>(bytes_ + 4);
  const uint32_t declared_splats = load_le<uint32_t>(bytes_ + 12);
  level_ = load_le<uint16_t>(bytes_ + 20);
  sh_min_ = load_le<float>(bytes_ + 36);
  sh_max_ = load_le<float>(bytes_ + 40);
  // JavaScript's `x || default`: 0 and NaN take the default.
  if (!(sh_min_ != 0)) sh_min_ = float(-kDefaultShHalfRange);
  if (!(sh_max_ != 0)) sh_max_ = float(kDefaultShHalfRange);
  if (major_ != 0 || minor_ < 1)
    fail(name, ".ksplat version " + version() +
                   " is not supported (only 0.1 and later 0.x, as GaussianSplats3D's viewer reads)");
  if (level_ > 2) fail(name, ".ksplat compression level " + std::to_string(level_) + " is not 0, 1 or 2");
  if (sections == 0) fail(name, ".ksplat header declares no sections");
  if (!std::isfinite(sh_min_) || !std::isfinite(sh_max_) || sh_min_ >= sh_max_)
    fail(name, ".ksplat header's SH range [" + std::to_string(sh_min_) + ", " + std::to_string(sh_max_) +
                   "] is not an interval");
  require_bytes(name, ".ksplat section headers", sections, kSectionHeaderBytes, data.size() - kHeaderBytes);
  uint64_t at = kHeaderBytes + uint64_t(sections) * kSectionHeaderBytes;
  for (size_t index = 0; index < sections; ++index) {
    Section s = read_section(bytes_ + kHeaderBytes + index * kSectionHeaderBytes, level_, index, name);
    s.begin = at;
    if (s.bytes() > data.size() - at)
      fail(name, ".ksplat section " + std::to_string(index) + " (" + std::to_string(s.splats) +
                     " splats) ends past the file's end: the file is truncated");
    if (level_ >= 1) read_buckets(bytes_, s, name, index);
    s.first_splat = size_;
    at += s.bytes();
    size_ += s.splats;
    sh_degree_ = std::max(sh_degree_, s.sh_degree);
    sections_.push_back(std::move(s));
  }
  if (size_ != declared_splats)
    fail(name, ".ksplat header declares " + std::to_string(declared_splats) + " splats, its sections hold " +
                   std::to_string(size_));
}

std::string KsplatPacked::format() const {
  switch (level_) {
    case 0: return "ksplat level 0 (float32)";
    case 1: return "ksplat level 1 (float16, 16-bit positions in buckets)";
    default: return "ksplat level 2 (float16, 16-bit positions in buckets, 8-bit SH)";
  }
}

std::string KsplatPacked::version() const { return std::to_string(major_) + "." + std::to_string(minor_); }

void KsplatPacked::decode_splat(size_t index, size_t i, GaussianScene& scene) const {
  // The section (the last whose first splat is at or before `index`) and the splat's place in it.
  const auto after = std::upper_bound(sections_.begin(), sections_.end(), index,
                                      [](size_t v, const Section& s) { return v < s.first_splat; });
  const Section& s = *(after - 1);
  const size_t j = index - s.first_splat;
  const unsigned char* centres = bytes_ + s.begin + 4 * uint64_t(s.partial_buckets);
  const unsigned char* splat = centres + uint64_t(s.bucket_bytes) * s.buckets + j * s.bytes_per_splat;
  auto log_scale = [&](double scale) {
    return to_float(level_ >= 1 && scale == 0 ? kLogHalfUnderflow : std::log(scale));
  };
  const unsigned char* colour = nullptr;
  const unsigned char* sh = nullptr;
  if (level_ == 0) {
    for (size_t a = 0; a < 3; ++a) {
      scene.positions[3 * i + a] = load_le<float>(splat + 4 * a);
      scene.log_scales[3 * i + a] = log_scale(load_le<float>(splat + 12 + 4 * a));
    }
    for (size_t a = 0; a < 4; ++a) scene.rotations[4 * i + a] = load_le<float>(splat + 24 + 4 * a);
    colour = splat + 40;
    sh = splat + 44;
  } else {
    const uint64_t full_splats = uint64_t(s.full_buckets) * s.bucket_size;
    const size_t bucket =
        j < full_splats ? j / s.bucket_size
                        : s.full_buckets + size_t(std::upper_bound(s.partial_ends.begin(), s.partial_ends.end(),
                                                                   uint32_t(j)) -
                                                  s.partial_ends.begin());
    const unsigned char* centre = centres + 12 * uint64_t(bucket);
    const double step = double(s.block_size) / 2 / double(s.position_range);
    for (size_t a = 0; a < 3; ++a) {
      const double stored = load_le<uint16_t>(splat + 2 * a);
      scene.positions[3 * i + a] =
          to_float((stored - double(s.position_range)) * step + double(load_le<float>(centre + 4 * a)));
      scene.log_scales[3 * i + a] = log_scale(half_at(splat + 6 + 2 * a));
    }
    for (size_t a = 0; a < 4; ++a) scene.rotations[4 * i + a] = float(half_at(splat + 12 + 2 * a));
    colour = splat + 20;
    sh = splat + 24;
  }
  const size_t k_count = size_t(scene.sh_coefficients());
  for (size_t c = 0; c < 3; ++c) scene.sh[i * k_count * 3 + c] = dc_of_colour_byte(colour[c]);
  scene.opacity_logits[i] = float(clamped_logit(colour[3] / 255.0));
  const int stored_k = (s.sh_degree + 1) * (s.sh_degree + 1);
  for (int k = 1; k < stored_k; ++k)
    for (int c = 0; c < 3; ++c) {
      const size_t at = stored_sh_index(k, c);
      double value = 0;
      if (level_ == 0)
        value = load_le<float>(sh + 4 * at);
      else if (level_ == 1)
        value = half_at(sh + 2 * at);
      else
        value = sh[at] / 255.0 * (double(sh_max_) - double(sh_min_)) + double(sh_min_);
      scene.sh[(i * k_count + size_t(k)) * 3 + size_t(c)] = to_float(value);
    }
}

template <typename IndexOf>
GaussianScene KsplatPacked::decode_each(size_t count, IndexOf index_of) const {
  GaussianScene scene;
  allocate_scene(scene, count, sh_degree_);
  for (size_t i = 0; i < count; ++i) decode_splat(index_of(i), i, scene);
  return scene;
}

GaussianScene KsplatPacked::decode(std::span<const uint32_t> indices) const {
  return decode_each(indices.size(), [&](size_t i) { return size_t(indices[i]); });
}

GaussianScene KsplatPacked::decode_range(size_t first, size_t end) const {
  return decode_each(end - first, [&](size_t i) { return first + i; });
}

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
  const KsplatPacked packed(data, name);
  GaussianScene scene = packed.decode_range(0, packed.size());
  finish_scene(scene, name, options, packed.format(), packed.version(), report);
  return scene;
}

}  // namespace tilesplat::detail
