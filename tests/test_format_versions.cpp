// The older versions of two compressed formats, which no shared file exercises: SPZ version 2 (a gzip
// stream; rotations as three bytes x y z) and SOG version 1 (meta.json with per-channel mins and maxs
// instead of codebooks). The test writes each from the bundled 64-Gaussian SH3 PLY by the formats'
// layouts (Niantic's spz README and load-spz.cc; PlayCanvas's SOG description and the meta.json of
// published v1 scenes), loads it, and compares every value with the PLY's within the quantization
// step the format allows: the PLY is the ground truth, the encoder here follows the text, and the
// reader is what is checked.
#include <gtest/gtest.h>
#include <webp/encode.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "process_support.h"
#include "test_math.h"
#include "test_support.h"
#include "tilesplat/scene.h"

namespace {

namespace fs = std::filesystem;
using tilesplat::GaussianScene;

GaussianScene bundled_scene() {
  return tilesplat::load_scene(tilesplat::testing::bundled_sh3());
}

double sigmoid(double x) {
  return 1 / (1 + std::exp(-x));
}

uint8_t quantize(double value, double low, double high, int levels = 255) {
  const double t = high > low ? (value - low) / (high - low) : 0;
  return static_cast<uint8_t>(std::lround(std::clamp(t, 0.0, 1.0) * levels));
}

using tilesplat::testing::math::Matrix3;
Matrix3 rotation_of(const float* wxyz) {
  return tilesplat::testing::math::quaternion_matrix(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
}
void expect_same_rotation(const float* actual, const float* expected, double tolerance, size_t gaussian) {
  const Matrix3 a = rotation_of(actual), b = rotation_of(expected);
  for (size_t k = 0; k < 9; ++k)
    EXPECT_NEAR(a[k], b[k], tolerance) << "Gaussian " << gaussian << " rotation " << k;
}

// ---------------------------------------------------------------------------------------------
// SPZ version 2

// The sign of each SH basis function (k = 1..15, 3DGS order) under y -> -y, z -> -z (SPZ's RUB axes
// against the trainer's RDF): (-1)^(the function's degree in y plus its degree in z).
constexpr int kShYzDegree[15] = {1, 1, 0,        // y, z, x
                                 1, 2, 2, 1, 0,  // xy, yz, 2z^2-x^2-y^2 (even), xz, x^2-y^2 (even)
                                 1, 2, 1, 1, 2,
                                 1, 0};  // y(3x^2-y^2), xyz, y(4z^2-..), z(..), x(4z^2-..), z(x^2-y^2), x(..)
double rub_sign(size_t k) {
  return kShYzDegree[k] % 2 ? -1.0 : 1.0;
}

std::vector<uint8_t> gzip(const std::vector<uint8_t>& raw) {
  z_stream stream{};
  EXPECT_EQ(deflateInit2(&stream, Z_BEST_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY), Z_OK);
  std::vector<uint8_t> out(deflateBound(&stream, uLong(raw.size())) + 32);
  stream.next_in = const_cast<Bytef*>(raw.data());
  stream.avail_in = uInt(raw.size());
  stream.next_out = out.data();
  stream.avail_out = uInt(out.size());
  EXPECT_EQ(deflate(&stream, Z_FINISH), Z_STREAM_END);
  out.resize(stream.total_out);
  deflateEnd(&stream);
  return out;
}

template <typename T>
void put(std::vector<uint8_t>& bytes, T value) {
  const size_t at = bytes.size();
  bytes.resize(at + sizeof(T));
  std::memcpy(bytes.data() + at, &value, sizeof(T));
}

TEST(FormatVersions, SpzVersion2ReadsWithinItsQuantization) {
  const GaussianScene ply = bundled_scene();
  const size_t n = ply.size();
  ASSERT_EQ(ply.sh_degree, 3);
  constexpr int kFractionalBits = 12;
  constexpr double kColourScale = 0.15;  // SPZ's DC scale
  const double flip[3] = {1, -1, -1};    // RDF -> RUB

  std::vector<uint8_t> raw;
  put<uint32_t>(raw, 0x5053474e);  // "NGSP"
  put<uint32_t>(raw, 2);           // version
  put<uint32_t>(raw, uint32_t(n));
  put<uint8_t>(raw, 3);  // SH degree
  put<uint8_t>(raw, kFractionalBits);
  put<uint8_t>(raw, 0);  // flags
  put<uint8_t>(raw, 0);  // reserved
  for (size_t i = 0; i < n; ++i)
    for (size_t a = 0; a < 3; ++a) {
      const auto fixed = int32_t(std::lround(flip[a] * ply.positions[3 * i + a] * (1 << kFractionalBits)));
      for (int b = 0; b < 3; ++b) raw.push_back(uint8_t((fixed >> (8 * b)) & 0xff));
    }
  for (size_t i = 0; i < n; ++i) raw.push_back(uint8_t(std::lround(sigmoid(ply.opacity_logits[i]) * 255)));
  const size_t stride = 3 * 16;
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < 3; ++c) raw.push_back(quantize(0.5 + kColourScale * ply.sh[stride * i + c], 0, 1));
  for (size_t i = 0; i < n; ++i)
    for (size_t a = 0; a < 3; ++a) raw.push_back(quantize((ply.log_scales[3 * i + a] + 10) * 16, 0, 255));
  for (size_t i = 0; i < n; ++i) {
    const float* q = ply.rotations.data() + 4 * i;  // w x y z, unit
    const double sign = q[0] < 0 ? -1 : 1;          // w >= 0, so that it can be derived
    for (size_t j = 0; j < 3; ++j) raw.push_back(quantize(sign * flip[j] * q[1 + j], -1, 1));
  }
  for (size_t i = 0; i < n; ++i)
    for (size_t k = 1; k < 16; ++k)
      for (size_t c = 0; c < 3; ++c)
        raw.push_back(uint8_t(
            std::clamp(std::lround(rub_sign(k - 1) * ply.sh[stride * i + 3 * k + c] * 128 + 128), 0L, 255L)));

  const fs::path out = tilesplat::testing::fresh_output_dir() / "v2.spz";
  const std::vector<uint8_t> file = gzip(raw);
  std::ofstream(out, std::ios::binary)
      .write(reinterpret_cast<const char*>(file.data()), std::streamsize(file.size()));
  tilesplat::LoadReport report;
  const GaussianScene spz = tilesplat::load_scene(out, {}, &report);
  EXPECT_EQ(report.format, "spz");
  EXPECT_EQ(report.version, "2");
  ASSERT_EQ(spz.size(), n);
  ASSERT_EQ(spz.sh_degree, 3);
  size_t sh_checked = 0;
  for (size_t i = 0; i < n; ++i) {
    for (size_t a = 0; a < 3; ++a) {
      EXPECT_NEAR(spz.positions[3 * i + a], ply.positions[3 * i + a], 0.5 / (1 << kFractionalBits) + 1e-6)
          << i;
      if (ply.log_scales[3 * i + a] > -10 && ply.log_scales[3 * i + a] < 5.9) {
        EXPECT_NEAR(spz.log_scales[3 * i + a], ply.log_scales[3 * i + a], 0.5 / 16 + 1e-6) << i;
      }
      const double dc = ply.sh[stride * i + a];
      if (std::abs(kColourScale * dc) < 0.49) {
        EXPECT_NEAR(spz.sh[stride * i + a], dc, 0.5 / 255 / kColourScale + 1e-6) << i;
      }
    }
    EXPECT_NEAR(sigmoid(spz.opacity_logits[i]), sigmoid(ply.opacity_logits[i]), 0.5 / 255 + 1e-6) << i;
    // Three bytes of 1/127.5 each, and w derived from them: a rotation matrix within about 2e-2.
    expect_same_rotation(spz.rotations.data() + 4 * i, ply.rotations.data() + 4 * i, 2e-2, i);
    for (size_t k = 1; k < 16; ++k)
      for (size_t c = 0; c < 3; ++c) {
        const double value = ply.sh[stride * i + 3 * k + c];
        if (std::abs(value) >= 0.99) continue;  // clamped by the byte
        EXPECT_NEAR(spz.sh[stride * i + 3 * k + c], value, 0.5 / 128 + 1e-6) << i << " coefficient " << k;
        ++sh_checked;
      }
  }
  EXPECT_GT(sh_checked, n * 45 / 2) << "most SH values should lie within a byte's range";
}

// ---------------------------------------------------------------------------------------------
// SOG version 1

// Lossless and exact: without `exact` the encoder may change the R G B of texels whose alpha is 0,
// which in sh0.webp are the colours of the least opaque Gaussians.
std::vector<uint8_t> lossless_webp(const std::vector<uint8_t>& rgba, int width, int height) {
  WebPConfig config;
  EXPECT_TRUE(WebPConfigInit(&config));
  config.lossless = 1;
  config.exact = 1;
  WebPPicture picture;
  EXPECT_TRUE(WebPPictureInit(&picture));
  picture.use_argb = 1;
  picture.width = width;
  picture.height = height;
  EXPECT_TRUE(WebPPictureImportRGBA(&picture, rgba.data(), 4 * width));
  WebPMemoryWriter writer;
  WebPMemoryWriterInit(&writer);
  picture.writer = WebPMemoryWrite;
  picture.custom_ptr = &writer;
  EXPECT_TRUE(WebPEncode(&config, &picture)) << "WebP error " << picture.error_code;
  std::vector<uint8_t> bytes(writer.mem, writer.mem + writer.size);
  WebPMemoryWriterClear(&writer);
  WebPPictureFree(&picture);
  return bytes;
}

void write_bytes(const fs::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

double log_transform(double v) {
  return std::copysign(std::log(std::abs(v) + 1), v);
}

TEST(FormatVersions, SogVersion1ReadsWithinItsQuantization) {
  const GaussianScene ply = bundled_scene();
  const size_t n = ply.size();
  ASSERT_EQ(n, 64u);
  const int width = 8, height = 8;  // texel i is Gaussian i, row-major
  const size_t stride = 3 * 16;
  const fs::path dir = tilesplat::testing::fresh_output_dir();
  auto image = [&](const char* name, auto&& texel) {
    std::vector<uint8_t> rgba(4 * n, 255);
    for (size_t i = 0; i < n; ++i) texel(i, rgba.data() + 4 * i);
    write_bytes(dir / name, lossless_webp(rgba, width, height));
  };
  auto ranges = [&](size_t channels, auto&& value) {
    std::vector<double> low(channels, INFINITY), high(channels, -INFINITY);
    for (size_t i = 0; i < n; ++i)
      for (size_t c = 0; c < channels; ++c) {
        low[c] = std::min(low[c], value(i, c));
        high[c] = std::max(high[c], value(i, c));
      }
    return std::pair{low, high};
  };

  // means: 16 bits of the log-transformed position over its range, low bytes and high bytes.
  const auto mean = [&](size_t i, size_t a) { return log_transform(ply.positions[3 * i + a]); };
  const auto [mean_low, mean_high] = ranges(3, mean);
  auto mean_bits = [&](size_t i, size_t a) {
    return uint16_t(std::lround((mean(i, a) - mean_low[a]) / (mean_high[a] - mean_low[a]) * 65535));
  };
  image("means_l.webp", [&](size_t i, uint8_t* t) {
    for (size_t a = 0; a < 3; ++a) t[a] = uint8_t(mean_bits(i, a) & 0xff);
  });
  image("means_u.webp", [&](size_t i, uint8_t* t) {
    for (size_t a = 0; a < 3; ++a) t[a] = uint8_t(mean_bits(i, a) >> 8);
  });
  // scales: log scales over their per-axis range.
  const auto scale = [&](size_t i, size_t a) { return double(ply.log_scales[3 * i + a]); };
  const auto [scale_low, scale_high] = ranges(3, scale);
  image("scales.webp", [&](size_t i, uint8_t* t) {
    for (size_t a = 0; a < 3; ++a) t[a] = quantize(scale(i, a), scale_low[a], scale_high[a]);
  });
  // quats: the three smallest of w x y z (the largest made positive) as (c / sqrt2 + 1) * 127.5, and
  // A = 252 + the largest's index.
  image("quats.webp", [&](size_t i, uint8_t* t) {
    const float* q = ply.rotations.data() + 4 * i;
    size_t largest = 0;
    for (size_t j = 1; j < 4; ++j)
      if (std::abs(q[j]) > std::abs(q[largest])) largest = j;
    const double sign = q[largest] < 0 ? -1 : 1;
    for (size_t j = 0, k = 0; j < 4; ++j)
      if (j != largest) t[k++] = quantize(sign * q[j] * std::sqrt(2.0), -1, 1);
    t[3] = uint8_t(252 + largest);
  });
  // sh0: the DC coefficients and the opacity logit, each over its range.
  const auto colour = [&](size_t i, size_t c) {
    return c < 3 ? double(ply.sh[stride * i + c]) : double(ply.opacity_logits[i]);
  };
  const auto [colour_low, colour_high] = ranges(4, colour);
  image("sh0.webp", [&](size_t i, uint8_t* t) {
    for (size_t c = 0; c < 4; ++c) t[c] = quantize(colour(i, c), colour_low[c], colour_high[c]);
  });
  // shN: a palette of one entry per Gaussian (64 entries: one row of 64 x 15 texels), quantized over the
  // global range, and labels (16 bits in R G) pointing Gaussian i at entry i.
  double rest_low = INFINITY, rest_high = -INFINITY;
  for (size_t i = 0; i < n; ++i)
    for (size_t k = 3; k < stride; ++k) {
      rest_low = std::min(rest_low, double(ply.sh[stride * i + k]));
      rest_high = std::max(rest_high, double(ply.sh[stride * i + k]));
    }
  std::vector<uint8_t> centroids(4 * 64 * 15, 255);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < 15; ++j)
      for (size_t c = 0; c < 3; ++c)
        centroids[4 * (i * 15 + j) + c] = quantize(ply.sh[stride * i + 3 * (j + 1) + c], rest_low, rest_high);
  write_bytes(dir / "shN_centroids.webp", lossless_webp(centroids, 64 * 15, 1));
  image("shN_labels.webp", [&](size_t i, uint8_t* t) {
    t[0] = uint8_t(i & 0xff);
    t[1] = uint8_t(i >> 8);
    t[2] = 0;
  });

  using nlohmann::json;
  auto shape = [&](std::initializer_list<size_t> dims) { return json(std::vector<size_t>(dims)); };
  const json meta = {{"means",
                      {{"shape", shape({n, 3})},
                       {"dtype", "float32"},
                       {"mins", mean_low},
                       {"maxs", mean_high},
                       {"files", {"means_l.webp", "means_u.webp"}}}},
                     {"scales",
                      {{"shape", shape({n, 3})},
                       {"dtype", "float32"},
                       {"mins", scale_low},
                       {"maxs", scale_high},
                       {"files", {"scales.webp"}}}},
                     {"quats",
                      {{"shape", shape({n, 4})},
                       {"dtype", "uint8"},
                       {"encoding", "quaternion_packed"},
                       {"files", {"quats.webp"}}}},
                     {"sh0",
                      {{"shape", shape({n, 1, 4})},
                       {"dtype", "float32"},
                       {"mins", colour_low},
                       {"maxs", colour_high},
                       {"files", {"sh0.webp"}}}},
                     {"shN",
                      {{"shape", shape({n, 45})},
                       {"dtype", "float32"},
                       {"mins", rest_low},
                       {"maxs", rest_high},
                       {"quantization", 8},
                       {"files", {"shN_centroids.webp", "shN_labels.webp"}}}}};
  std::ofstream(dir / "meta.json") << meta.dump(2);

  tilesplat::LoadReport report;
  const GaussianScene sog = tilesplat::load_scene(dir / "meta.json", {}, &report);
  EXPECT_EQ(report.version, "1");
  ASSERT_EQ(sog.size(), n);
  ASSERT_EQ(sog.sh_degree, 3);
  for (size_t i = 0; i < n; ++i) {
    for (size_t a = 0; a < 3; ++a) {
      // Half a 16-bit step of the log-transformed value, times the slope exp(|u|) of its inverse.
      const double step = (mean_high[a] - mean_low[a]) / 65535 / 2 * std::exp(std::abs(mean(i, a)));
      EXPECT_NEAR(sog.positions[3 * i + a], ply.positions[3 * i + a], step * 1.01 + 1e-6) << i;
      EXPECT_NEAR(sog.log_scales[3 * i + a], scale(i, a), (scale_high[a] - scale_low[a]) / 255 / 2 + 1e-5)
          << i;
    }
    for (size_t c = 0; c < 3; ++c)
      EXPECT_NEAR(sog.sh[stride * i + c], colour(i, c), (colour_high[c] - colour_low[c]) / 255 / 2 + 1e-5)
          << i;
    EXPECT_NEAR(sog.opacity_logits[i], colour(i, 3), (colour_high[3] - colour_low[3]) / 255 / 2 + 1e-5) << i;
    expect_same_rotation(sog.rotations.data() + 4 * i, ply.rotations.data() + 4 * i, 1.5e-2, i);
    for (size_t k = 3; k < stride; ++k)
      EXPECT_NEAR(sog.sh[stride * i + k], ply.sh[stride * i + k], (rest_high - rest_low) / 255 / 2 + 1e-5)
          << i << " value " << k;
  }
}

}  // namespace
