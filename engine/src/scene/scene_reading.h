// What every scene reader shares: reading the file, failing with the file's name, the byte-level
// helpers of binary formats, and the one post-processing step that turns decoded values into the
// GaussianScene every renderer sees (the non-finite policy and quaternion normalization).
//
// Readers decode into the engine's activations (positions, log scales, opacity logits, SH DC and
// rest coefficients coefficient-major with RGB innermost, quaternions w-first), then call
// finish_scene(). Decoded values are computed in double and rounded once to float, as the formats'
// reference decoders (JavaScript numbers) do, so a reader matches their decodings to the bit.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tilesplat/scene.h"

namespace tilesplat::detail {

[[noreturn]] inline void fail(std::string_view name, const std::string& what) {
  throw SceneError(std::string(name) + ": " + what);
}

// The whole file in memory: mapped where the platform can (no copy, and the page cache serves
// it), else read with one call. A mapped file that another process truncates while it is being
// decoded raises SIGBUS; scene files are not rewritten in place, so the speed is worth it.
class FileContents {
 public:
  FileContents() = default;
  FileContents(const FileContents&) = delete;
  FileContents& operator=(const FileContents&) = delete;
  ~FileContents();

  // Returns an error message, empty on success.
  std::string open(const std::filesystem::path& path);

  // Lets go of bytes [0, end) of a mapped file (rounded down to whole pages): they stop counting as the
  // process's resident memory, and are read from the file again if touched. Nothing for a file read
  // into memory.
  void release_before(size_t end);
  // Lets go of every page of a mapped file, whatever was touched before (a file read in parts, whose
  // parts are scattered through it). Nothing for a file read into memory.
  void release_all() const;

  const unsigned char* data() const { return data_; }
  size_t size() const { return size_; }
  std::span<const std::byte> bytes() const { return std::as_bytes(std::span(data_, size_)); }

 private:
  const unsigned char* data_ = nullptr;
  size_t size_ = 0;
  void* mapping_ = nullptr;
  size_t released_ = 0;  // bytes at the mapping's start let go of (release_before)
  std::unique_ptr<unsigned char[]> buffer_;
};

// Checks that `path` names a readable regular file and maps or reads it; throws SceneError.
void open_scene_file(const std::filesystem::path& path, FileContents& contents);

// Whether a file name that another file gives (an unbundled SOG's image, a LOD set's chunk) is a plain
// path beside that file: not empty, not absolute, no "..". Only such names are followed.
bool is_path_beside(const std::string& name);

// Little-endian loads from unaligned bytes (every binary splat format is little-endian).
template <typename T>
T load_le(const unsigned char* bytes) {
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) {
    unsigned char reversed[sizeof(T)];
    for (size_t i = 0; i < sizeof(T); ++i) reversed[i] = bytes[sizeof(T) - 1 - i];
    std::memcpy(&value, reversed, sizeof(T));
  }
  return value;
}

// A double outside float's range becomes +-inf explicitly: the plain cast would be undefined.
float to_float(double value);

// log(p / (1 - p)) with p clamped to [1e-6, 1 - 1e-6]: how 8-bit opacities (0 and 255 included)
// become logits in the .splat, .spz and SOG reference decoders, so that no file yields an infinity.
double clamped_logit(double p);

// SH band 0's constant: a Gaussian's colour is 0.5 + kShC0 * dc (before the higher bands).
inline constexpr double kShC0 = 0.28209479177387814;

// The DC coefficient of an 8-bit display colour `byte` = (0.5 + kShC0 * dc) * 255, as .splat and .ksplat
// store it.
inline float dc_of_colour_byte(unsigned char byte) { return float((byte / 255.0 - 0.5) / kShC0); }

// Sizes every array of `scene` for `count` Gaussians of `sh_degree` (no normals).
void allocate_scene(GaussianScene& scene, size_t count, int sh_degree);

// Fails unless `count` items of `bytes_each` fit in `available` bytes: the check that comes before
// any allocation sized by a count read from a file.
void require_bytes(std::string_view name, std::string_view what, uint64_t count, uint64_t bytes_each,
                   uint64_t available);

// Counts the Gaussians dropped for non-finite values, per property, or throws in strict mode.
class NonFiniteTally {
 public:
  NonFiniteTally(std::string_view name, const LoadOptions& options) : name_(name), options_(options) {}
  // Gaussian `index` of the file has `value` (non-finite) in `property`, its first bad property.
  void record(size_t index, const std::string& property, float value);
  size_t dropped() const { return dropped_; }
  std::vector<DroppedProperty> take() { return std::move(by_property_); }

 private:
  std::string_view name_;
  const LoadOptions& options_;
  size_t dropped_ = 0;
  std::vector<DroppedProperty> by_property_;
};

// Records each Gaussian of `scene` with a non-finite value in `tally` (which throws in strict mode), as
// Gaussian `first + i` of its file, and returns their indices in `scene`, ascending.
std::vector<size_t> non_finite_gaussians(const GaussianScene& scene, size_t first, NonFiniteTally& tally);

// Unit quaternions, w first. A quaternion whose components are all below FLT_MIN in magnitude
// (zero or denormal) becomes the identity, as float32 normalization makes it in gsplat and the
// original CUDA rasterizer, and as projection.comp and the float64 reference treat it. Others are
// normalized in double (their squares cannot overflow or underflow there).
void normalize_rotations(GaussianScene& scene);

// compute_bounds of a scene whose positions (x, y, z of each Gaussian) are `positions`.
Bounds bounds_of_positions(std::span<const float> positions);

// The post-processing every reader but PLY's (which filters while it decodes) ends with: drops
// (or, strict, rejects) Gaussians with a non-finite value, naming the first bad one by its PLY
// property name, normalizes the rotations and fills `report`.
void finish_scene(GaussianScene& scene, std::string_view name, const LoadOptions& options, std::string format,
                  std::string version, LoadReport* report);

}  // namespace tilesplat::detail
