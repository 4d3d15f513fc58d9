// Reader for Niantic .spz files, versions 2, 3 and 4.
//
// Versions 2 and 3: one gzip stream (zlib) of a 16-byte header (magic "NGSP", version, count, SH
// degree, fractional bits, flags, reserved) and the attribute arrays one after another. Version 4:
// a plain 32-byte header (the same fields, then the number of streams and the offset of a table of
// contents), the TOC of (compressed, uncompressed) uint64 sizes, and one zstd stream per attribute.
// The attributes, per Gaussian:
//   positions  3 x 24-bit signed fixed point, `fractional bits` after the point
//   alphas     uint8 sigmoid(opacity) * 255
//   colours    3 x uint8, 0.5 + 0.15 * dc (SPZ's own colour scale, not SH_C0)
//   scales     3 x uint8, log scale = byte / 16 - 10
//   rotations  version 2: 3 x uint8 x y z as (q + 1) * 127.5, w >= 0 derived;
//              versions 3 and 4: uint32 smallest three (2 bits: the largest component's index in
//              x y z w; then 10 bits each of the others, a sign and 9 bits of magnitude / sqrt 2)
//   SH         (degree+1)^2 - 1 coefficients x RGB as uint8 (byte - 128) / 128, coefficient-major
// SPZ stores RUB axes (x right, y up, z back) unless an extension says otherwise; the engine's are
// the trainer's RDF, so y and z flip: positions, quaternions (w x -y -z) and the SH bands (each
// basis function's parity in y and z).
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scene/scene_readers.h"
#include "scene/scene_reading.h"
#include "scene/spz_packed.h"

namespace tilesplat::detail {
namespace {

constexpr uint32_t kMagic = 0x5053474e;  // "NGSP" little-endian
constexpr size_t kLegacyHeaderSize = 16;
constexpr size_t kHeaderSize = 32;
constexpr uint8_t kFlagHasExtensions = 0x2;
// A compressed stream can hold at most this many bytes per byte of file (deflate's limit is about
// 1032; zstd's is higher but no real splat stream comes near): counts past it are refused before
// anything is allocated, so a tiny file cannot make the reader allocate gigabytes.
constexpr uint64_t kMaxExpansion = 1032;

// Sign of each SH basis function (k = 1..15, the engine's order) when y and z flip.
constexpr float kRubToRdfSh[15] = {-1, -1, 1, -1, 1, 1, -1, 1, -1, 1, -1, -1, 1, -1, 1};

struct SpzHeader {
  uint32_t version = 0;
  uint32_t count = 0;
  int sh_degree = 0;
  int fractional_bits = 0;
  uint8_t flags = 0;
};

struct Layout {
  uint64_t positions, alphas, colours, scales, rotations, sh;
  uint64_t total() const { return positions + alphas + colours + scales + rotations + sh; }
};

Layout layout_of(const SpzHeader& header) {
  const uint64_t n = header.count;
  const uint64_t rest = 3 * (static_cast<uint64_t>((header.sh_degree + 1) * (header.sh_degree + 1)) - 1);
  return {9 * n, n, 3 * n, 3 * n, (header.version == 2 ? 3 : 4) * n, rest * n};
}

SpzHeader parse_header(std::string_view name, const unsigned char* bytes) {
  SpzHeader header;
  if (load_le<uint32_t>(bytes) != kMagic) fail(name, "not an SPZ file (no 'NGSP' magic)");
  header.version = load_le<uint32_t>(bytes + 4);
  header.count = load_le<uint32_t>(bytes + 8);
  header.sh_degree = bytes[12];
  header.fractional_bits = bytes[13];
  header.flags = bytes[14];
  if (header.version < 2 || header.version > 4)
    fail(name, "unsupported SPZ version " + std::to_string(header.version) + " (supported: 2, 3, 4)");
  if (header.sh_degree > 3)
    fail(name, "SPZ SH degree " + std::to_string(header.sh_degree) + " is not supported (at most 3)");
  if (header.fractional_bits > 24)
    fail(name, "SPZ fractional bits " + std::to_string(header.fractional_bits) + " is out of range (0..24)");
  return header;
}

void check_plausible(std::string_view name, const Layout& layout, size_t file_size) {
  if (layout.total() / kMaxExpansion > file_size)
    fail(name, "the header declares " + std::to_string(layout.positions / 9) + " Gaussians (" +
                   std::to_string(layout.total()) + " bytes of attributes), more than a " +
                   std::to_string(file_size) + "-byte file can hold compressed; refusing to decompress it");
}

// The gzip stream of versions 2 and 3, inflated into caller-given arrays one after another.
class Inflater {
 public:
  // `file`, where given, is where `input` is mapped from: its pages are let go of once inflated.
  Inflater(std::span<const unsigned char> input, std::string_view name, FileContents* file = nullptr)
      : input_(input), file_(file) {
    if (inflateInit2(&stream_, 16 + MAX_WBITS) != Z_OK) fail(name, "cannot start gzip decompression");
  }
  Inflater(const Inflater&) = delete;
  Inflater& operator=(const Inflater&) = delete;
  ~Inflater() { inflateEnd(&stream_); }

  // Fills [out, out + size) from the stream; false if it ends or breaks before.
  bool read(unsigned char* out, size_t size) {
    while (size > 0) {
      const uInt slice = static_cast<uInt>(std::min<size_t>(size, kMaxSlice));
      stream_.next_out = out;
      stream_.avail_out = slice;
      while (stream_.avail_out > 0) {
        if (stream_.avail_in == 0) {  // fed in slices: zlib counts in uInt, and each is let go of after
          if (consumed_ == input_.size()) return false;
          if (file_) file_->release_before(consumed_);
          const size_t more = std::min<size_t>(input_.size() - consumed_, kInputSlice);
          stream_.next_in = const_cast<Bytef*>(input_.data() + consumed_);
          stream_.avail_in = static_cast<uInt>(more);
          consumed_ += more;
        }
        const int result = inflate(&stream_, Z_NO_FLUSH);
        if (result == Z_STREAM_END && stream_.avail_out > 0) return false;
        if (result != Z_OK && result != Z_STREAM_END) return false;
      }
      out += slice;
      size -= slice;
    }
    return true;
  }

 private:
  static constexpr size_t kMaxSlice = size_t(1) << 30;
  static constexpr size_t kInputSlice = size_t(64) << 20;
  std::span<const unsigned char> input_;
  FileContents* file_;
  size_t consumed_ = 0;
  z_stream stream_{};
};

// Version 4: one zstd stream of the table of contents, decompressed to exactly its declared size.
class ZstdStreams {
 public:
  // `contents`, where given, is where `file` is mapped from: its pages are let go of once decompressed.
  ZstdStreams(std::span<const unsigned char> file, SpzHeader header, std::string_view name,
              FileContents* contents)
      : file_(file),
        header_(header),
        name_(name),
        contents_(contents),
        context_(ZSTD_createDCtx(), &ZSTD_freeDCtx) {
    const unsigned char* bytes = file.data();
    const size_t streams = bytes[15];
    toc_ = load_le<uint32_t>(bytes + 16);
    const size_t expected_streams = header.sh_degree > 0 ? 6 : 5;
    if (streams != expected_streams)
      fail(name, "SPZ version 4 with " + std::to_string(streams) + " streams; expected " +
                     std::to_string(expected_streams) + " for SH degree " + std::to_string(header.sh_degree));
    if (toc_ < kHeaderSize || toc_ > file.size() || file.size() - toc_ < streams * 16)
      fail(name, "SPZ table of contents at byte " + std::to_string(toc_) + " lies outside the " +
                     std::to_string(file.size()) + "-byte file");
    next_input_ = toc_ + streams * 16;
  }

  // The next stream (`index` in the table), which must decompress to `size` bytes, into `out`.
  void read(size_t index, unsigned char* out, uint64_t size) {
    static constexpr const char* kStreamNames[6] = {"positions", "alphas",    "colours",
                                                    "scales",    "rotations", "SH"};
    const unsigned char* entry = file_.data() + toc_ + 16 * index;
    const uint64_t compressed = load_le<uint64_t>(entry);
    const uint64_t uncompressed = load_le<uint64_t>(entry + 8);
    const std::string stream_name = std::string("SPZ ") + kStreamNames[index] + " stream";
    if (uncompressed != size)
      fail(name_, stream_name + " declares " + std::to_string(uncompressed) + " bytes; " +
                      std::to_string(header_.count) + " Gaussians need " + std::to_string(size));
    if (compressed > file_.size() - next_input_)
      fail(name_, stream_name + " (" + std::to_string(compressed) + " bytes) runs past the end of the file");
    const size_t produced =
        ZSTD_decompressDCtx(context_.get(), out, size, file_.data() + next_input_, compressed);
    if (ZSTD_isError(produced)) fail(name_, stream_name + " is corrupt: " + ZSTD_getErrorName(produced));
    if (produced != size)
      fail(name_, stream_name + " decompresses to " + std::to_string(produced) + " bytes, not the " +
                      std::to_string(size) + " declared");
    next_input_ += compressed;
    if (contents_) contents_->release_before(next_input_);
  }

 private:
  std::span<const unsigned char> file_;
  SpzHeader header_;
  std::string_view name_;
  FileContents* contents_;
  // A member, so that it is freed when the constructor's checks throw.
  std::unique_ptr<ZSTD_DCtx, size_t (*)(ZSTD_DCtx*)> context_;
  uint32_t toc_ = 0;
  size_t next_input_ = 0;
};

constexpr float kFlip[3] = {1, -1, -1};  // RUB -> RDF

// The 24-bit fixed-point positions, in the engine's axes.
std::vector<float> decode_positions(const unsigned char* packed, size_t count, int fractional_bits) {
  std::vector<float> positions(3 * count);
  for (size_t i = 0; i < 3 * count; ++i) {
    const unsigned char* p = packed + 3 * i;
    int32_t fixed = static_cast<int32_t>(p[0] | (p[1] << 8) | (p[2] << 16));
    if (fixed & 0x800000) fixed -= 1 << 24;
    positions[i] = kFlip[i % 3] * static_cast<float>(std::ldexp(fixed, -fractional_bits));
  }
  return positions;
}

}  // namespace

SpzPacked::SpzPacked(std::span<const std::byte> data, std::string_view name, FileContents* file) {
  if (data.empty()) fail(name, "empty file, not an SPZ file");
  const std::span<const unsigned char> bytes(reinterpret_cast<const unsigned char*>(data.data()),
                                             data.size());
  const bool gzip = bytes.size() >= 2 && bytes[0] == 0x1f && bytes[1] == 0x8b;
  const bool plain_v4 = bytes.size() >= 8 && load_le<uint32_t>(bytes.data()) == kMagic &&
                        load_le<uint32_t>(bytes.data() + 4) == 4;
  SpzHeader header;
  std::optional<Inflater> inflater;
  std::optional<ZstdStreams> streams;
  size_t plain_offset = kLegacyHeaderSize;  // where an uncompressed version 2 or 3 file's next array starts
  if (gzip) {
    inflater.emplace(bytes, name, file);
    unsigned char header_bytes[kLegacyHeaderSize];
    if (!inflater->read(header_bytes, kLegacyHeaderSize))
      fail(name, "truncated or corrupt gzip stream: it ends before the 16-byte SPZ header");
    header = parse_header(name, header_bytes);
    if (header.version == 4)
      fail(name, "an SPZ version 4 header inside gzip (version 4 files are not gzipped)");
  } else if (plain_v4) {
    if (bytes.size() < kHeaderSize)
      fail(name, "truncated SPZ version 4 header (" + std::to_string(bytes.size()) + " bytes)");
    header = parse_header(name, bytes.data());
  } else {
    if (bytes.size() < kLegacyHeaderSize) fail(name, "truncated SPZ header");
    header = parse_header(name, bytes.data());
  }
  const Layout layout = layout_of(header);
  if (plain_v4) streams.emplace(bytes, header, name, file);
  if (gzip || plain_v4) check_plausible(name, layout, bytes.size());
  if (!gzip && !plain_v4)
    require_bytes(name, "SPZ attributes", 1, layout.total(), bytes.size() - kLegacyHeaderSize);

  // Reads the next array of `size` bytes (the table's stream `index` in version 4) into `out`.
  auto read_array = [&](size_t index, unsigned char* out, uint64_t size) {
    if (inflater) {
      if (!inflater->read(out, size))
        fail(name, "truncated or corrupt gzip stream: it ends before the " + std::to_string(header.count) +
                       " Gaussians the header declares (" + std::to_string(layout.total()) + " bytes)");
    } else if (streams) {
      streams->read(index, out, size);
    } else {
      std::copy_n(bytes.data() + plain_offset, size, out);
      plain_offset += size;
      if (file) file->release_before(plain_offset);
    }
  };
  version_ = header.version;
  count_ = header.count;
  sh_degree_ = header.sh_degree;
  has_extensions_ = (header.flags & kFlagHasExtensions) != 0;
  {
    std::vector<unsigned char> packed_positions(layout.positions);
    read_array(0, packed_positions.data(), layout.positions);
    positions_ = decode_positions(packed_positions.data(), count_, header.fractional_bits);
  }
  attributes_.resize(layout.total() - layout.positions);
  const uint64_t sizes[5] = {layout.alphas, layout.colours, layout.scales, layout.rotations, layout.sh};
  unsigned char* out = attributes_.data();
  for (size_t index = 1; index <= 5; ++index) {
    if (sizes[index - 1] == 0 && index == 5 && streams) break;  // version 4 has no SH stream at degree 0
    read_array(index, out, sizes[index - 1]);
    out += sizes[index - 1];
  }
}

DeclaredCounts read_spz_counts(std::span<const std::byte> data, std::string_view name) {
  const std::span<const unsigned char> bytes(reinterpret_cast<const unsigned char*>(data.data()),
                                             data.size());
  unsigned char header_bytes[kLegacyHeaderSize];
  if (bytes.size() >= 2 && bytes[0] == 0x1f && bytes[1] == 0x8b) {
    Inflater inflater(bytes, name);
    if (!inflater.read(header_bytes, kLegacyHeaderSize))
      fail(name, "truncated or corrupt gzip stream: it ends before the 16-byte SPZ header");
  } else {
    if (bytes.size() < kLegacyHeaderSize) fail(name, "truncated SPZ header");
    std::copy_n(bytes.data(), kLegacyHeaderSize, header_bytes);
  }
  const SpzHeader header = parse_header(name, header_bytes);
  return {header.count, header.sh_degree};
}

template <typename IndexOf>
GaussianScene SpzPacked::decode_each(size_t count, IndexOf index_of) const {
  const size_t n = count_;
  const unsigned char* alphas = attributes_.data();
  const unsigned char* colours = alphas + n;
  const unsigned char* scales = colours + 3 * n;
  const unsigned char* rotations = scales + 3 * n;
  const unsigned char* sh = rotations + (version_ == 2 ? 3 : 4) * n;

  GaussianScene scene;
  allocate_scene(scene, count, sh_degree_);
  const size_t coefficients = static_cast<size_t>(scene.sh_coefficients());
  constexpr double kColourScale = 0.15;
  for (size_t out = 0; out < count; ++out) {
    const size_t i = index_of(out);
    for (size_t a = 0; a < 3; ++a) {
      scene.positions[3 * out + a] = positions_[3 * i + a];
      scene.log_scales[3 * out + a] = static_cast<float>(scales[3 * i + a] / 16.0 - 10.0);
      scene.sh[3 * coefficients * out + a] =
          static_cast<float>((colours[3 * i + a] / 255.0 - 0.5) / kColourScale);
    }
    scene.opacity_logits[out] = static_cast<float>(clamped_logit(alphas[i] / 255.0));

    double xyzw[4] = {0, 0, 0, 0};
    if (version_ == 2) {
      const unsigned char* r = rotations + 3 * i;
      for (size_t j = 0; j < 3; ++j) xyzw[j] = r[j] / 127.5 - 1.0;
      xyzw[3] = std::sqrt(std::max(0.0, 1.0 - (xyzw[0] * xyzw[0] + xyzw[1] * xyzw[1] + xyzw[2] * xyzw[2])));
    } else {
      uint32_t packed = load_le<uint32_t>(rotations + 4 * i);
      const uint32_t largest = packed >> 30;
      double sum = 0;
      for (int j = 3; j >= 0; --j) {
        if (static_cast<uint32_t>(j) == largest) continue;
        const double magnitude = std::sqrt(0.5) * (packed & 511u) / 511.0;
        xyzw[j] = (packed >> 9) & 1u ? -magnitude : magnitude;
        sum += xyzw[j] * xyzw[j];
        packed >>= 10;
      }
      xyzw[largest] = std::sqrt(std::max(0.0, 1.0 - sum));
    }
    float* q = scene.rotations.data() + 4 * out;
    q[0] = static_cast<float>(xyzw[3]);
    for (size_t j = 0; j < 3; ++j) q[1 + j] = kFlip[j] * static_cast<float>(xyzw[j]);

    const unsigned char* coefficients_in = sh + 3 * (coefficients - 1) * i;
    float* coefficients_out = scene.sh.data() + 3 * coefficients * out + 3;
    for (size_t k = 0; k + 1 < coefficients; ++k)
      for (size_t c = 0; c < 3; ++c)
        coefficients_out[3 * k + c] =
            kRubToRdfSh[k] * static_cast<float>((coefficients_in[3 * k + c] - 128) / 128.0);
  }
  return scene;
}

GaussianScene SpzPacked::decode(std::span<const uint32_t> indices) const {
  return decode_each(indices.size(), [&](size_t k) { return size_t(indices[k]); });
}

GaussianScene SpzPacked::decode_all() const {
  return decode_each(count_, [](size_t k) { return k; });
}

bool is_spz(std::span<const std::byte> data) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  return (data.size() >= 4 && load_le<uint32_t>(bytes) == kMagic) ||
         (data.size() >= 2 && bytes[0] == 0x1f && bytes[1] == 0x8b);
}

GaussianScene read_spz(std::span<const std::byte> data, std::string_view name, const LoadOptions& options,
                       LoadReport* report, FileContents* file) {
  const SpzPacked packed(data, name, file);
  GaussianScene scene = packed.decode_all();
  finish_scene(scene, name, options, "spz", std::to_string(packed.version()), report);
  if (report && packed.has_extensions()) report->ignored_properties.push_back(kSpzExtensionsIgnored);
  return scene;
}

}  // namespace tilesplat::detail
