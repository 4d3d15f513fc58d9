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
#include <string>
#include <vector>

#include "scene/scene_readers.h"
#include "scene/scene_reading.h"

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

// Inflates the gzip stream into `out` until it holds `wanted` bytes; false if it ends before.
bool inflate_prefix(std::vector<unsigned char>& out, size_t wanted, z_stream& stream) {
  const size_t start = out.size();
  out.resize(wanted);
  stream.next_out = out.data() + start;
  stream.avail_out = static_cast<uInt>(wanted - start);
  while (stream.avail_out > 0) {
    const int result = inflate(&stream, Z_NO_FLUSH);
    if (result == Z_STREAM_END) break;
    if (result != Z_OK) return false;
    if (stream.avail_in == 0) return false;
  }
  return stream.avail_out == 0;
}

// Versions 2 and 3: the header and arrays, inflated (or, uncompressed, as they are).
std::vector<unsigned char> legacy_payload(std::span<const std::byte> data, std::string_view name,
                                          SpzHeader* header) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  const bool gzip = data.size() >= 2 && bytes[0] == 0x1f && bytes[1] == 0x8b;
  if (!gzip) {
    if (data.size() < kLegacyHeaderSize) fail(name, "truncated SPZ header");
    *header = parse_header(name, bytes);
    const Layout layout = layout_of(*header);
    require_bytes(name, "SPZ attributes", 1, layout.total(), data.size() - kLegacyHeaderSize);
    return std::vector<unsigned char>(bytes + kLegacyHeaderSize, bytes + kLegacyHeaderSize + layout.total());
  }
  z_stream stream{};
  if (inflateInit2(&stream, 16 + MAX_WBITS) != Z_OK) fail(name, "cannot start gzip decompression");
  struct End {
    z_stream* s;
    ~End() { inflateEnd(s); }
  } end{&stream};
  stream.next_in = const_cast<Bytef*>(bytes);
  stream.avail_in = static_cast<uInt>(std::min<size_t>(data.size(), std::numeric_limits<uInt>::max()));
  std::vector<unsigned char> payload;
  if (!inflate_prefix(payload, kLegacyHeaderSize, stream))
    fail(name, "truncated or corrupt gzip stream: it ends before the 16-byte SPZ header");
  *header = parse_header(name, payload.data());
  if (header->version == 4)
    fail(name, "an SPZ version 4 header inside gzip (version 4 files are not gzipped)");
  const Layout layout = layout_of(*header);
  check_plausible(name, layout, data.size());
  if (!inflate_prefix(payload, kLegacyHeaderSize + layout.total(), stream))
    fail(name, "truncated or corrupt gzip stream: it ends before the " + std::to_string(header->count) +
                   " Gaussians the header declares (" + std::to_string(layout.total()) + " bytes)");
  payload.erase(payload.begin(), payload.begin() + kLegacyHeaderSize);
  return payload;
}

// Version 4: the TOC's streams, each zstd-decompressed to the size the count implies.
std::vector<unsigned char> zstd_payload(std::span<const std::byte> data, std::string_view name,
                                        SpzHeader* header) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  if (data.size() < kHeaderSize)
    fail(name, "truncated SPZ version 4 header (" + std::to_string(data.size()) + " bytes)");
  *header = parse_header(name, bytes);
  if (header->version != 4)
    fail(name,
         "SPZ version " + std::to_string(header->version) + " without gzip (only version 4 is uncompressed)");
  const size_t streams = bytes[15];
  const uint32_t toc = load_le<uint32_t>(bytes + 16);
  const Layout layout = layout_of(*header);
  const uint64_t expected[6] = {layout.positions, layout.alphas,    layout.colours,
                                layout.scales,    layout.rotations, layout.sh};
  const size_t expected_streams = header->sh_degree > 0 ? 6 : 5;
  if (streams != expected_streams)
    fail(name, "SPZ version 4 with " + std::to_string(streams) + " streams; expected " +
                   std::to_string(expected_streams) + " for SH degree " + std::to_string(header->sh_degree));
  if (toc < kHeaderSize || toc > data.size() || data.size() - toc < streams * 16)
    fail(name, "SPZ table of contents at byte " + std::to_string(toc) + " lies outside the " +
                   std::to_string(data.size()) + "-byte file");
  check_plausible(name, layout, data.size());
  std::vector<unsigned char> payload(layout.total());
  size_t in = toc + streams * 16;
  size_t out = 0;
  ZSTD_DCtx* context = ZSTD_createDCtx();
  struct Free {
    ZSTD_DCtx* c;
    ~Free() { ZSTD_freeDCtx(c); }
  } free_context{context};
  static constexpr const char* kStreamNames[6] = {"positions", "alphas",    "colours",
                                                  "scales",    "rotations", "SH"};
  for (size_t s = 0; s < streams; ++s) {
    const uint64_t compressed = load_le<uint64_t>(bytes + toc + 16 * s);
    const uint64_t uncompressed = load_le<uint64_t>(bytes + toc + 16 * s + 8);
    const std::string stream_name = std::string("SPZ ") + kStreamNames[s] + " stream";
    if (uncompressed != expected[s])
      fail(name, stream_name + " declares " + std::to_string(uncompressed) + " bytes; " +
                     std::to_string(header->count) + " Gaussians need " + std::to_string(expected[s]));
    if (compressed > data.size() - in)
      fail(name, stream_name + " (" + std::to_string(compressed) + " bytes) runs past the end of the file");
    const size_t produced =
        ZSTD_decompressDCtx(context, payload.data() + out, uncompressed, bytes + in, compressed);
    if (ZSTD_isError(produced)) fail(name, stream_name + " is corrupt: " + ZSTD_getErrorName(produced));
    if (produced != uncompressed)
      fail(name, stream_name + " decompresses to " + std::to_string(produced) + " bytes, not the " +
                     std::to_string(uncompressed) + " declared");
    in += compressed;
    out += uncompressed;
  }
  return payload;
}

}  // namespace

bool is_spz(std::span<const std::byte> data) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  return (data.size() >= 4 && load_le<uint32_t>(bytes) == kMagic) ||
         (data.size() >= 2 && bytes[0] == 0x1f && bytes[1] == 0x8b);
}

GaussianScene read_spz(std::span<const std::byte> data, std::string_view name, const LoadOptions& options,
                       LoadReport* report) {
  if (data.empty()) fail(name, "empty file, not an SPZ file");
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  const bool plain_v4 =
      data.size() >= 8 && load_le<uint32_t>(bytes) == kMagic && load_le<uint32_t>(bytes + 4) == 4;
  SpzHeader header;
  const std::vector<unsigned char> payload =
      plain_v4 ? zstd_payload(data, name, &header) : legacy_payload(data, name, &header);
  const Layout layout = layout_of(header);
  const unsigned char* positions = payload.data();
  const unsigned char* alphas = positions + layout.positions;
  const unsigned char* colours = alphas + layout.alphas;
  const unsigned char* scales = colours + layout.colours;
  const unsigned char* rotations = scales + layout.scales;
  const unsigned char* sh = rotations + layout.rotations;

  const size_t count = header.count;
  GaussianScene scene;
  allocate_scene(scene, count, header.sh_degree);
  const size_t coefficients = static_cast<size_t>(scene.sh_coefficients());
  constexpr double kColourScale = 0.15;
  constexpr float kFlip[3] = {1, -1, -1};  // RUB -> RDF
  for (size_t i = 0; i < count; ++i) {
    for (size_t a = 0; a < 3; ++a) {
      const unsigned char* p = positions + 9 * i + 3 * a;
      int32_t fixed = static_cast<int32_t>(p[0] | (p[1] << 8) | (p[2] << 16));
      if (fixed & 0x800000) fixed -= 1 << 24;
      scene.positions[3 * i + a] = kFlip[a] * static_cast<float>(std::ldexp(fixed, -header.fractional_bits));
      scene.log_scales[3 * i + a] = static_cast<float>(scales[3 * i + a] / 16.0 - 10.0);
      scene.sh[3 * coefficients * i + a] =
          static_cast<float>((colours[3 * i + a] / 255.0 - 0.5) / kColourScale);
    }
    scene.opacity_logits[i] = static_cast<float>(clamped_logit(alphas[i] / 255.0));

    double xyzw[4] = {0, 0, 0, 0};
    if (header.version == 2) {
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
    float* q = scene.rotations.data() + 4 * i;
    q[0] = static_cast<float>(xyzw[3]);
    for (size_t j = 0; j < 3; ++j) q[1 + j] = kFlip[j] * static_cast<float>(xyzw[j]);

    const unsigned char* coefficients_in = sh + 3 * (coefficients - 1) * i;
    float* coefficients_out = scene.sh.data() + 3 * coefficients * i + 3;
    for (size_t k = 0; k + 1 < coefficients; ++k)
      for (size_t c = 0; c < 3; ++c)
        coefficients_out[3 * k + c] =
            kRubToRdfSh[k] * static_cast<float>((coefficients_in[3 * k + c] - 128) / 128.0);
  }
  const bool extensions = (header.flags & kFlagHasExtensions) != 0;
  std::string version = std::to_string(header.version);
  finish_scene(scene, name, options, "spz", version, report);
  if (report && extensions) report->ignored_properties.push_back("SPZ extension records (flag 0x2)");
  return scene;
}

}  // namespace tilesplat::detail
