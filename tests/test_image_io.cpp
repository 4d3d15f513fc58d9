// EXR and PNG files, atomic writes, and image comparison.
#include <gtest/gtest.h>
#include <png.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "image/atomic_file.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/version.h"

// The EXR channel checks read the header with the spec-level parser below, and additionally with
// OpenEXR itself when the test target has OpenEXR's include directories.
#if __has_include(<ImfInputFile.h>)
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfMatrixAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#define TILESPLAT_TEST_HAS_OPENEXR 1
#else
#define TILESPLAT_TEST_HAS_OPENEXR 0
#endif

namespace tilesplat {
namespace {

namespace fs = std::filesystem;
using testing::DecodedPng;
using testing::read_png_rgb;

// ---------------------------------------------------------------------------------------------
// Helpers

RenderImage make_image(int width, int height, bool with_depth, bool with_counts) {
  RenderImage image;
  image.width = width;
  image.height = height;
  image.rgba.resize(4 * image.pixels());
  for (size_t i = 0; i < image.rgba.size(); ++i)
    image.rgba[i] = 0.37f * static_cast<float>(i % 97) - 3.1f + 1e-3f * static_cast<float>(i);
  if (with_depth) {
    image.depth.resize(image.pixels());
    for (size_t i = 0; i < image.depth.size(); ++i)
      image.depth[i] = 1.5f + 0.01234567f * static_cast<float>(i);
  }
  if (with_counts) {
    image.splat_count.resize(image.pixels());
    for (size_t i = 0; i < image.splat_count.size(); ++i)
      image.splat_count[i] = static_cast<uint32_t>(i * 7919u);
  }
  return image;
}

// temp_dir() persists between runs; tests that inspect a directory's contents need it empty.
fs::path fresh_dir() {
  const fs::path dir = testing::temp_dir() / "files";
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<char> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& path, const std::vector<char>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::set<std::string> directory_entries(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.insert(entry.path().filename().string());
  return names;
}

template <typename Function>
std::string error_message_of(Function&& function) {
  try {
    function();
  } catch (const std::exception& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected an exception";
  return {};
}

template <typename T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

// A minimal reader of the EXR header as laid out in the OpenEXR file-layout document, so the
// channel list is checked independently of the library that wrote it.
struct ExrChannelInfo {
  std::string name;
  int32_t pixel_type;  // 0 UINT, 1 HALF, 2 FLOAT
  bool operator==(const ExrChannelInfo&) const = default;
};
constexpr int32_t kExrUint = 0, kExrHalf = 1, kExrFloat = 2;

struct ExrHeaderInfo {
  std::vector<ExrChannelInfo> channels;
  int compression = -1;  // 3 = ZIP_COMPRESSION
};

template <typename T>
T load_little_endian(const std::vector<char>& bytes, size_t offset) {
  static_assert(std::endian::native == std::endian::little);
  T value{};
  if (offset + sizeof(T) > bytes.size()) throw std::runtime_error("EXR header truncated");
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

std::string load_name(const std::vector<char>& bytes, size_t& offset) {
  std::string name;
  while (offset < bytes.size() && bytes[offset] != '\0') name += bytes[offset++];
  if (offset >= bytes.size()) throw std::runtime_error("EXR header truncated");
  ++offset;
  return name;
}

ExrHeaderInfo parse_exr_header(const fs::path& path) {
  const std::vector<char> bytes = read_bytes(path);
  if (load_little_endian<uint32_t>(bytes, 0) != 20000630u) throw std::runtime_error("bad EXR magic");
  ExrHeaderInfo info;
  size_t offset = 8;  // magic + version
  for (;;) {
    const std::string attribute = load_name(bytes, offset);
    if (attribute.empty()) break;
    const std::string type = load_name(bytes, offset);
    const auto size = static_cast<size_t>(load_little_endian<int32_t>(bytes, offset));
    offset += 4;
    if (attribute == "channels") {
      size_t at = offset;
      for (;;) {
        const std::string name = load_name(bytes, at);
        if (name.empty()) break;
        info.channels.push_back({name, load_little_endian<int32_t>(bytes, at)});
        at += 16;  // pixel type, pLinear + 3 reserved, xSampling, ySampling
      }
    } else if (attribute == "compression") {
      info.compression = static_cast<unsigned char>(bytes.at(offset));
    }
    offset += size;
  }
  return info;
}

// Writes an uncompressed scanline EXR of FLOAT channels by hand, to produce files our writer
// never would: missing channels, a data window that does not start at (0, 0).
struct HandChannel {
  std::string name;
  std::vector<float> values;  // width x height, row-major
};

void write_hand_made_exr(const fs::path& path, int x_min, int y_min, int width, int height,
                         std::vector<HandChannel> channels) {
  std::sort(channels.begin(), channels.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  std::vector<char> out;
  const auto put = [&](const auto& value) {
    const char* raw = reinterpret_cast<const char*>(&value);
    out.insert(out.end(), raw, raw + sizeof(value));
  };
  const auto put_name = [&](const std::string& text) {
    out.insert(out.end(), text.begin(), text.end());
    out.push_back('\0');
  };
  const auto put_attribute_start = [&](const std::string& name, const std::string& type, int32_t size) {
    put_name(name);
    put_name(type);
    put(size);
  };
  put(uint32_t{20000630u});
  put(uint32_t{2});
  int32_t chlist_size = 1;
  for (const auto& channel : channels) chlist_size += static_cast<int32_t>(channel.name.size()) + 1 + 16;
  put_attribute_start("channels", "chlist", chlist_size);
  for (const auto& channel : channels) {
    put_name(channel.name);
    put(kExrFloat);
    put(uint32_t{0});  // pLinear and reserved
    put(int32_t{1});
    put(int32_t{1});
  }
  out.push_back('\0');
  put_attribute_start("compression", "compression", 1);
  out.push_back('\0');  // NO_COMPRESSION
  for (const char* window : {"dataWindow", "displayWindow"}) {
    put_attribute_start(window, "box2i", 16);
    put(int32_t{x_min});
    put(int32_t{y_min});
    put(int32_t{x_min + width - 1});
    put(int32_t{y_min + height - 1});
  }
  put_attribute_start("lineOrder", "lineOrder", 1);
  out.push_back('\0');
  put_attribute_start("pixelAspectRatio", "float", 4);
  put(1.0f);
  put_attribute_start("screenWindowCenter", "v2f", 8);
  put(0.0f);
  put(0.0f);
  put_attribute_start("screenWindowWidth", "float", 4);
  put(1.0f);
  out.push_back('\0');

  const auto line_bytes = static_cast<int32_t>(channels.size() * static_cast<size_t>(width) * sizeof(float));
  const uint64_t first_line = out.size() + 8 * static_cast<uint64_t>(height);
  const uint64_t chunk_bytes = 8u + static_cast<uint64_t>(line_bytes);  // y, size, then the data
  for (int row = 0; row < height; ++row) put(uint64_t{first_line + static_cast<uint64_t>(row) * chunk_bytes});
  for (int row = 0; row < height; ++row) {
    put(int32_t{y_min + row});
    put(line_bytes);
    for (const auto& channel : channels)
      for (int x = 0; x < width; ++x) put(channel.values[static_cast<size_t>(row * width + x)]);
  }
  write_bytes(path, out);
}

uint8_t expected_srgb_byte(double linear) {
  const double clamped = std::clamp(linear, 0.0, 1.0);
  const double encoded =
      clamped <= 0.0031308 ? 12.92 * clamped : 1.055 * std::pow(clamped, 1.0 / 2.4) - 0.055;
  return static_cast<uint8_t>(std::floor(encoded * 255.0 + 0.5));
}

// IEC 61966-2-1's decoding, written out here so that the library's is checked against it; negatives
// mirror the curve (as extended sRGB does).
double decode_srgb(double v) {
  const double m = std::fabs(v);
  return std::copysign(m <= 0.04045 ? m / 12.92 : std::pow((m + 0.055) / 1.055, 2.4), v);
}

// A trained (display) colour as the PNG holds it without grading.
uint8_t expected_display_byte(double colour) {
  return static_cast<uint8_t>(std::floor(std::clamp(colour, 0.0, 1.0) * 255.0 + 0.5));
}

// ---------------------------------------------------------------------------------------------
// EXR

TEST(ExrIo, FloatRoundTripIsBitExact) {
  RenderImage image = make_image(13, 7, true, true);
  // Values a lossy path would disturb: signed zero, subnormals, infinities, NaN, extremes.
  image.rgba[0] = -0.0f;
  image.rgba[1] = std::numeric_limits<float>::denorm_min();
  image.rgba[2] = std::numeric_limits<float>::infinity();
  image.rgba[3] = std::numeric_limits<float>::quiet_NaN();
  image.rgba[4] = std::numeric_limits<float>::max();
  image.rgba[5] = 1.0f + std::numeric_limits<float>::epsilon();
  image.depth[0] = 0.0f;
  image.depth[1] = 123456.789f;
  // Counts are stored as FLOAT (compositing tools read UINT channels as normalised values): exact up to
  // 2^24, far above any real count (a pixel stops blending after at most ~2,350 splats of alpha >= 1/255).
  image.splat_count[0] = 1u << 24;

  // The display encoding stores the rendered values as they are (scene-linear converts them: below).
  const fs::path path = fresh_dir() / "float.exr";
  write_exr(path, image, ExrWriteOptions{.colour = ColourEncoding::kSrgbDisplay});
  EXPECT_EQ(read_exr_string_attributes(path).at("colorInteropID"), "srgb_rec709_display");
  const RenderImage back = read_exr(path);
  EXPECT_EQ(back.width, 13);
  EXPECT_EQ(back.height, 7);
  EXPECT_TRUE(same_bits(back.rgba, image.rgba));
  EXPECT_TRUE(same_bits(back.depth, image.depth));
  EXPECT_EQ(back.splat_count, image.splat_count);
}

TEST(Colour, SrgbTransferFunctionFollowsIec61966AndInvertsItself) {
  for (const double v : {0.0, 0.001, 0.04045, 0.05, 0.18, 0.5, 0.75, 1.0, 2.0, 8.0}) {
    EXPECT_NEAR(srgb_to_linear(v), decode_srgb(v), 1e-15 * std::max(1.0, decode_srgb(v))) << v;
    // The standard's two thresholds (0.04045 and 0.0031308) miss each other by 5e-9 in linear light, so
    // at 0.04045 the round trip is exact only to 3e-8; elsewhere to double rounding.
    EXPECT_NEAR(linear_to_srgb(srgb_to_linear(v)), v, (v == 0.04045 ? 1e-7 : 1e-12) * std::max(1.0, v)) << v;
    EXPECT_EQ(srgb_to_linear(-v), -srgb_to_linear(v)) << "negatives mirror the curve";
  }
  EXPECT_NEAR(srgb_to_linear(0.5), 0.21404114048223255, 1e-15);  // literal: mid-grey is 21% of the light
  EXPECT_NEAR(linear_to_srgb(0.18), 0.46135612950044164, 1e-15);
  EXPECT_TRUE(std::isnan(srgb_to_linear(std::nan(""))));
  EXPECT_EQ(to_string(ColourEncoding::kSceneLinear), "lin_rec709_scene");
  EXPECT_EQ(to_string(ColourEncoding::kSrgbDisplay), "srgb_rec709_display");
}

TEST(Colour, ConversionDecodesTheColourNotThePremultipliedValue) {
  // (colour 0.5 at coverage 0.4, premultiplied 0.2), an opaque pixel, and one without coverage.
  const std::vector<float> rgba = {0.2f, 0.4f, 0.0f, 0.4f, 0.5f, 1.0f, 0.25f, 1.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  const std::vector<float> linear =
      convert_colours(rgba, ColourEncoding::kSrgbDisplay, ColourEncoding::kSceneLinear);
  EXPECT_NEAR(linear[0], 0.4 * decode_srgb(0.5), 1e-7);
  EXPECT_NEAR(linear[1], 0.4 * decode_srgb(1.0), 1e-7);
  EXPECT_EQ(linear[3], 0.4f) << "alpha is kept";
  EXPECT_NEAR(linear[4], decode_srgb(0.5), 1e-7);
  EXPECT_NEAR(linear[6], decode_srgb(0.25), 1e-7);
  EXPECT_EQ(linear[8], 0.0f);
  const std::vector<float> back =
      convert_colours(linear, ColourEncoding::kSceneLinear, ColourEncoding::kSrgbDisplay);
  for (size_t i = 0; i < rgba.size(); ++i) EXPECT_NEAR(back[i], rgba[i], 1e-7) << i;
  // Taken as opaque (a file without alpha), the premultiplied value itself is decoded.
  const std::vector<float> opaque =
      convert_colours(rgba, ColourEncoding::kSrgbDisplay, ColourEncoding::kSceneLinear, /*opaque=*/true);
  EXPECT_NEAR(opaque[0], decode_srgb(0.2), 1e-7);
  EXPECT_EQ(convert_colours(rgba, ColourEncoding::kSceneLinear, ColourEncoding::kSceneLinear), rgba);
}

// What a compositing tool reads: scene-linear values, A * decode(C / A), said so by the header; read_exr()
// gives the rendered colours back.
TEST(ExrIo, WritesSceneLinearColoursByDefaultAndReadsThemBack) {
  RenderImage image = make_image(13, 7, true, true);
  const fs::path path = fresh_dir() / "linear.exr";
  write_exr(path, image);
  const auto attributes = read_exr_string_attributes(path);
  EXPECT_EQ(attributes.at("colorInteropID"), "lin_rec709_scene");
  const StoredExr stored = read_exr_as_stored(path);
  EXPECT_EQ(stored.encoding, ColourEncoding::kSceneLinear);
  const RenderImage back = read_exr(path);
  size_t partly_covered = 0;
  for (size_t pixel = 0; pixel < image.pixels(); ++pixel) {
    const double alpha = image.rgba[4 * pixel + 3];
    ASSERT_EQ(stored.image.rgba[4 * pixel + 3], image.rgba[4 * pixel + 3]);
    partly_covered += alpha > 0 && alpha < 1;
    for (size_t c = 0; c < 3; ++c) {
      const double colour = image.rgba[4 * pixel + c];
      const double want = alpha > 0 && alpha < 1 ? alpha * decode_srgb(colour / alpha) : decode_srgb(colour);
      EXPECT_NEAR(stored.image.rgba[4 * pixel + c], want, 1e-6 * std::max(1.0, want)) << pixel << " " << c;
      EXPECT_NEAR(back.rgba[4 * pixel + c], colour, 1e-6 * std::max(1.0, colour)) << pixel << " " << c;
    }
  }
  EXPECT_GT(partly_covered, 0u) << "the test image should have pixels of partial coverage";
  EXPECT_TRUE(same_bits(back.depth, image.depth));
  EXPECT_EQ(back.splat_count, image.splat_count);

  // Without alpha (or with A = 1), the file is opaque and its colours convert as they are.
  const fs::path opaque = fresh_dir() / "opaque.exr";
  write_exr(opaque, image, ExrWriteOptions{.alpha = false});
  const StoredExr stored_opaque = read_exr_as_stored(opaque);
  EXPECT_NEAR(stored_opaque.image.rgba[0], decode_srgb(image.rgba[0]), 1e-6);
  EXPECT_NEAR(read_exr(opaque).rgba[0], image.rgba[0], 1e-6);
}

#if TILESPLAT_TEST_HAS_OPENEXR
TEST(ExrIo, UnknownColourEncodingIsAnErrorNamingIt) {
  const fs::path path = fresh_dir() / "acescg.exr";
  {
    Imf::Header header(2, 2);
    header.channels().insert("R", Imf::Channel(Imf::FLOAT));
    header.channels().insert("G", Imf::Channel(Imf::FLOAT));
    header.channels().insert("B", Imf::Channel(Imf::FLOAT));
    header.insert("colorInteropID", Imf::StringAttribute("lin_ap1_scene"));
    std::vector<float> zeros(4, 0.0f);
    Imf::FrameBuffer frame;
    for (const char* name : {"R", "G", "B"})
      frame.insert(name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(zeros.data()), sizeof(float),
                                    2 * sizeof(float)));
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(2);
  }
  try {
    read_exr(path);
    FAIL() << "read_exr accepted colours it cannot convert";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(path.string()), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("colorInteropID 'lin_ap1_scene'"), std::string::npos)
        << error.what();
  }
}
#endif

TEST(ExrIo, HalfRoundTripKeepsHalfPrecisionAndExactDepth) {
  RenderImage image = make_image(11, 6, true, true);
  image.rgba[0] = 1e-6f;  // a half subnormal
  const fs::path path = fresh_dir() / "half.exr";
  write_exr(path, image, ExrWriteOptions{.half = true, .colour = ColourEncoding::kSrgbDisplay});
  const RenderImage back = read_exr(path);
  ASSERT_EQ(back.width, image.width);
  ASSERT_EQ(back.height, image.height);
  ASSERT_EQ(back.rgba.size(), image.rgba.size());
  bool some_value_changed = false;
  for (size_t i = 0; i < image.rgba.size(); ++i) {
    // Round to nearest with an 11-bit significand: at most half an ulp, 2^-11 relative, and
    // 2^-25 absolute in half's subnormal range.
    const double tolerance =
        std::max(std::fabs(double{image.rgba[i]}) * std::ldexp(1.0, -11), std::ldexp(1.0, -25));
    EXPECT_NEAR(back.rgba[i], image.rgba[i], tolerance) << "value " << i;
    some_value_changed |= back.rgba[i] != image.rgba[i];
  }
  EXPECT_TRUE(some_value_changed) << "the colour channels do not look like they were stored as half";
  EXPECT_TRUE(same_bits(back.depth, image.depth)) << "Z must stay FLOAT in half mode";
  EXPECT_EQ(back.splat_count, image.splat_count);
}

TEST(ExrIo, EmptyPixelsGetTheFarDepthAndAnOpaqueFrameAlphaOne) {
  RenderImage image = make_image(5, 4, true, false);
  image.rgba[3] = 0.0f;  // pixel 0 shows nothing: the renderer leaves its depth 0
  image.depth[0] = 0.0f;
  image.rgba[7] = 0.25f;  // pixel 1 is partly covered: its depth stays
  ExrWriteOptions options;
  options.empty_depth = tilesplat::kFarDepth;
  options.opaque_alpha = true;
  const fs::path path = fresh_dir() / "far.exr";
  write_exr(path, image, options);
  const RenderImage back = read_exr(path);
  EXPECT_EQ(back.depth[0], tilesplat::kFarDepth);
  for (size_t i = 1; i < image.pixels(); ++i) EXPECT_EQ(back.depth[i], image.depth[i]) << i;
  for (size_t i = 0; i < image.pixels(); ++i) {
    EXPECT_EQ(back.rgba[4 * i + 3], 1.0f) << i;
    for (size_t c = 0; c < 3; ++c) EXPECT_EQ(back.rgba[4 * i + c], image.rgba[4 * i + c]) << i;
  }
  // By default the file holds the image as it is.
  write_exr(path, image);
  EXPECT_TRUE(same_bits(read_exr(path).rgba, image.rgba));
  EXPECT_EQ(read_exr(path).depth[0], 0.0f);
}

TEST(ExrIo, WrittenFileListsExpectedChannels) {
  const fs::path dir = fresh_dir();
  const RenderImage full = make_image(4, 3, true, true);
  const RenderImage colour_only = make_image(4, 3, false, false);
  write_exr(dir / "full_float.exr", full);
  write_exr(dir / "full_half.exr", full, ExrWriteOptions{.half = true});
  write_exr(dir / "colour_only.exr", colour_only);

  using Channels = std::vector<ExrChannelInfo>;
  // EXR stores channels sorted by name.
  const Channels full_float = {{"A", kExrFloat}, {"B", kExrFloat}, {"G", kExrFloat},
                               {"R", kExrFloat}, {"Z", kExrFloat}, {"splats", kExrFloat}};
  const Channels full_half = {{"A", kExrHalf}, {"B", kExrHalf},  {"G", kExrHalf},
                              {"R", kExrHalf}, {"Z", kExrFloat}, {"splats", kExrFloat}};
  const Channels colour = {{"A", kExrFloat}, {"B", kExrFloat}, {"G", kExrFloat}, {"R", kExrFloat}};

  const std::vector<std::pair<fs::path, Channels>> cases = {
      {dir / "full_float.exr", full_float},
      {dir / "full_half.exr", full_half},
      {dir / "colour_only.exr", colour}};
  for (const auto& [path, expected] : cases) {
    const ExrHeaderInfo header = parse_exr_header(path);
    EXPECT_EQ(header.channels, expected) << path;
    EXPECT_EQ(header.compression, 3) << path << ": expected ZIP_COMPRESSION";
#if TILESPLAT_TEST_HAS_OPENEXR
    Imf::InputFile file(path.c_str());
    Channels from_openexr;
    const Imf::ChannelList& channels = file.header().channels();
    for (auto channel = channels.begin(); channel != channels.end(); ++channel)
      from_openexr.push_back({channel.name(), static_cast<int32_t>(channel.channel().type)});
    EXPECT_EQ(from_openexr, expected) << path;
    EXPECT_EQ(static_cast<int>(file.header().compression()), 3) << path;
#endif
  }
}

TEST(ExrIo, ReadsFileWithoutAlphaAndWithOffsetDataWindow) {
  const int width = 3, height = 2;
  std::vector<float> red = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f};
  std::vector<float> green = {1, 2, 3, 4, 5, 6};
  std::vector<float> blue = {-1, -2, -3, -4, -5, -6};
  std::vector<float> depth = {10, 20, 30, 40, 50, 60};
  const fs::path path = fresh_dir() / "rgbz_offset.exr";
  write_hand_made_exr(path, 5, -2, width, height, {{"R", red}, {"G", green}, {"B", blue}, {"Z", depth}});

  const RenderImage image = read_exr(path);
  ASSERT_EQ(image.width, width);
  ASSERT_EQ(image.height, height);
  ASSERT_EQ(image.rgba.size(), 4u * 6u);
  for (size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(image.rgba[4 * i + 0], red[i]) << i;
    EXPECT_EQ(image.rgba[4 * i + 1], green[i]) << i;
    EXPECT_EQ(image.rgba[4 * i + 2], blue[i]) << i;
    EXPECT_EQ(image.rgba[4 * i + 3], 1.0f) << "A defaults to 1 when absent, pixel " << i;
  }
  EXPECT_EQ(image.depth, depth);
  EXPECT_TRUE(image.splat_count.empty());
}

// A frame of RenderSettings::region: the data window inside the whole image's display window, read back
// as the region's pixels; a region that is not the image's size or leaves the display is an error.
TEST(ExrIo, ARegionIsTheDataWindowInsideTheDisplayWindow) {
  const fs::path dir = fresh_dir();
  const RenderImage image = make_image(5, 3, true, true);
  ExrWriteOptions options{.colour = ColourEncoding::kSrgbDisplay};
  options.region = {10, 20, 5, 3};
  options.display_width = 64;
  options.display_height = 48;
  write_exr(dir / "region.exr", image, options);
  const RenderImage back = read_exr(dir / "region.exr");
  EXPECT_EQ(back.width, 5);
  EXPECT_EQ(back.height, 3);
  EXPECT_TRUE(same_bits(back.rgba, image.rgba));
  EXPECT_TRUE(same_bits(back.depth, image.depth));
#if TILESPLAT_TEST_HAS_OPENEXR
  Imf::InputFile file((dir / "region.exr").c_str());
  const Imath::Box2i data = file.header().dataWindow(), display = file.header().displayWindow();
  EXPECT_EQ(data.min.x, 10);
  EXPECT_EQ(data.min.y, 20);
  EXPECT_EQ(data.max.x, 14);
  EXPECT_EQ(data.max.y, 22);
  EXPECT_EQ(display.min.x, 0);
  EXPECT_EQ(display.max.x, 63);
  EXPECT_EQ(display.max.y, 47);
#endif
  options.region = {60, 20, 5, 3};  // past the display's right edge
  EXPECT_NE(tilesplat::testing::error_of([&] {
              write_exr(dir / "outside.exr", image, options);
            }).find("region 60,20,5x3 does not lie within the 64x48 display window"),
            std::string::npos);
  options.region = {0, 0, 4, 3};  // not the image's size
  EXPECT_NE(tilesplat::testing::error_of([&] {
              write_exr(dir / "size.exr", image, options);
            }).find("is not the image's size, 5x3"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "outside.exr"));
  EXPECT_FALSE(fs::exists(dir / "size.exr"));
}

TEST(ExrIo, MissingColourChannelIsAnErrorNamingTheFile) {
  const fs::path path = fresh_dir() / "no_red.exr";
  write_hand_made_exr(path, 0, 0, 2, 1, {{"G", {1, 2}}, {"B", {3, 4}}});
  const std::string message = error_message_of([&] { read_exr(path); });
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  EXPECT_NE(message.find("no R channel"), std::string::npos) << message;
  EXPECT_THROW(read_exr(path), std::runtime_error);
}

TEST(ExrIo, MissingFileGivesClearError) {
  const fs::path path = fresh_dir() / "does_not_exist.exr";
  const std::string message = error_message_of([&] { read_exr(path); });
  EXPECT_EQ(message, "cannot read " + path.string() + ": the file does not exist");
  EXPECT_THROW(read_exr(path), std::runtime_error);
}

TEST(ExrIo, RecordsProvenanceAndTheCallersAttributes) {
  const fs::path path = fresh_dir() / "provenance.exr";
  ExrWriteOptions options;
  options.attributes = {{"commandLine", "tilesplat-render scene.ply -o provenance.exr"},
                        {"owner", "a, b \"c\""}};
  write_exr(path, make_image(4, 3, true, false), options);

  const std::map<std::string, std::string> attributes = read_exr_string_attributes(path);
  const tilesplat::BuildInfo build = tilesplat::build_info();
  EXPECT_EQ(attributes.at("tilesplatVersion"), build.version);
  EXPECT_EQ(attributes.at("tilesplatVersion"), TILESPLAT_VERSION_STRING);
  if (*build.git_commit) {
    EXPECT_EQ(attributes.at("tilesplatCommit"), build.git_commit);
  } else {
    EXPECT_EQ(attributes.count("tilesplatCommit"), 0u);
  }
  if (*build.build_type) {
    EXPECT_EQ(attributes.at("tilesplatBuildType"), build.build_type);
  }
  EXPECT_EQ(attributes.at("commandLine"), options.attributes.at("commandLine"));
  EXPECT_EQ(attributes.at("owner"), "a, b \"c\"");
  // Only string attributes are returned: the writer's own (channels, compression, ...) are not strings.
  EXPECT_EQ(attributes.count("compression"), 0u);
  EXPECT_EQ(read_exr(path).width, 4);  // and the file is an ordinary image
#if TILESPLAT_TEST_HAS_OPENEXR
  const Imf::InputFile file(path.c_str());
  EXPECT_NE(file.header().findTypedAttribute<Imf::StringAttribute>("tilesplatVersion"), nullptr);
#endif
}

// The camera an EXR records: exactly in tilesplat's attributes, and in OpenEXR's standard worldToCamera
// (y up) and worldToNDC (top-left origin, image edges at 0 and 1) to single precision.
TEST(ExrIo, CameraRoundTripsExactlyAndInOpenExrsConventions) {
  const fs::path dir = fresh_dir();
  Camera camera = look_at_camera({0.3, -1.2, -4.0}, {0.1, 0.2, 0.3}, {0, -1, 0}, 64, 48, 55.0);
  camera.cx = 29.25;  // off-centre, so that the principal point is checked too
  camera.cy = 26.5;
  ExrWriteOptions options;
  options.camera = camera;
  const fs::path path = dir / "camera.exr";
  write_exr(path, make_image(64, 48, true, true), options);
  const std::optional<Camera> back = read_exr_camera(path);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(*back, camera);  // every double to the bit

  // A lens model and its coefficients too.
  camera.model = CameraModel::kOpenCV;
  camera.distortion = {-0.1234567890123, 0.0301, 1e-4, -2.5e-4, 0.002, 0.01, -0.003, 1.0 / 3.0};
  options.camera = camera;
  write_exr(dir / "opencv.exr", make_image(64, 48, true, true), options);
  EXPECT_EQ(read_exr_camera(dir / "opencv.exr"), camera);

  // No camera given: none recorded. A missing file: an error naming it.
  write_exr(dir / "none.exr", make_image(4, 3, false, false));
  EXPECT_FALSE(read_exr_camera(dir / "none.exr").has_value());
  EXPECT_EQ(error_message_of([&] { read_exr_camera(dir / "missing.exr"); }),
            "cannot read " + (dir / "missing.exr").string() + ": the file does not exist");

#if TILESPLAT_TEST_HAS_OPENEXR
  const Imf::InputFile file(path.c_str());
  const Imf::Header& header = file.header();
  ASSERT_TRUE(Imf::hasWorldToCamera(header));
  ASSERT_TRUE(Imf::hasWorldToNDC(header));
  ASSERT_TRUE(Imf::hasChromaticities(header));
  const Imf::Chromaticities rec709;
  EXPECT_EQ(Imf::chromaticities(header).red, rec709.red);
  EXPECT_EQ(Imf::chromaticities(header).white, rec709.white);
  const Imath::M44f world_to_camera = Imf::worldToCamera(header);
  const Imath::M44f world_to_ndc = Imf::worldToNDC(header);
  for (const std::array<double, 3>& point :
       {std::array<double, 3>{0.1, 0.2, 0.3}, {0.5, -0.4, 1.0}, {-0.7, 0.9, -0.2}}) {
    const std::array<double, 3> expected = camera.to_camera(point);
    const Imath::V3f world{float(point[0]), float(point[1]), float(point[2])};
    Imath::V3f in_camera;
    world_to_camera.multVecMatrix(world, in_camera);
    EXPECT_NEAR(in_camera.x, expected[0], 1e-5);
    EXPECT_NEAR(in_camera.y, -expected[1], 1e-5);  // OpenEXR's y is up
    EXPECT_NEAR(in_camera.z, expected[2], 1e-5);
    Imath::V3f ndc;
    world_to_ndc.multVecMatrix(world, ndc);
    const double px = camera.cx + camera.fx * expected[0] / expected[2];
    const double py = camera.cy + camera.fy * expected[1] / expected[2];
    EXPECT_NEAR(ndc.x, px / camera.width, 1e-5);
    EXPECT_NEAR(ndc.y, py / camera.height, 1e-5);
  }

  // Some of the camera attributes but not all: an error naming the file and what is missing.
  const fs::path incomplete = dir / "incomplete.exr";
  {
    Imf::Header partial(2, 2);
    partial.channels().insert("R", Imf::Channel(Imf::FLOAT));
    partial.channels().insert("G", Imf::Channel(Imf::FLOAT));
    partial.channels().insert("B", Imf::Channel(Imf::FLOAT));
    partial.insert("tilesplatRotation", Imf::M33dAttribute(Imath::M33d()));
    std::vector<float> pixels(4, 0.5f);
    Imf::FrameBuffer frame;
    for (const char* channel : {"R", "G", "B"})
      frame.insert(channel, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(pixels.data()), sizeof(float),
                                       2 * sizeof(float)));
    Imf::OutputFile out(incomplete.c_str(), partial);
    out.setFrameBuffer(frame);
    out.writePixels(2);
  }
  const std::string message = error_message_of([&] { read_exr_camera(incomplete); });
  EXPECT_EQ(message.rfind("cannot read " + incomplete.string() + ": the camera attributes are incomplete", 0),
            0u)
      << message;
#endif
}

// Every compression method writes a file OpenEXR reads back; the lossless ones (and DWAA on FLOAT
// channels) give the bits back, DWAA on HALF colour stays within a visually lossless error.
TEST(ExrIo, EveryCompressionMethodWritesAReadableFile) {
  const fs::path dir = fresh_dir();
  const RenderImage image = make_image(40, 24, true, true);
  const std::vector<std::pair<ExrCompression, int>> methods = {{ExrCompression::kZip, 3},
                                                               {ExrCompression::kPiz, 4},
                                                               {ExrCompression::kDwaa, 8},
                                                               {ExrCompression::kNone, 0}};
  for (const auto& [method, code] : methods) {
    for (const bool half : {false, true}) {
      const fs::path path = dir / (to_string(method) + (half ? "_half.exr" : ".exr"));
      ExrWriteOptions options;
      options.compression = method;
      options.half = half;
      options.colour = ColourEncoding::kSrgbDisplay;  // the values as they are, so that lossless is exact
      write_exr(path, image, options);
      EXPECT_EQ(parse_exr_header(path).compression, code) << path;
      const RenderImage back = read_exr(path);
      EXPECT_TRUE(same_bits(back.depth, image.depth)) << path;
      EXPECT_EQ(back.splat_count, image.splat_count) << path;
      const bool lossy = half || method == ExrCompression::kDwaa;
      if (!lossy) {
        EXPECT_TRUE(same_bits(back.rgba, image.rgba)) << path;
        continue;
      }
      double worst_rgb = 0, worst_alpha = 0;
      for (size_t i = 0; i < image.rgba.size(); ++i) {
        const double error =
            std::fabs(double(back.rgba[i]) - image.rgba[i]) / std::max(1.0, std::fabs(double(image.rgba[i])));
        (i % 4 == 3 ? worst_alpha : worst_rgb) = std::max(i % 4 == 3 ? worst_alpha : worst_rgb, error);
      }
      EXPECT_LT(worst_rgb, method == ExrCompression::kDwaa ? 0.05 : 1e-3) << path;  // DWAA: lossy on R G B
      EXPECT_LT(worst_alpha, half ? 1e-3 : 1e-300) << path;  // alpha: only half rounding
    }
  }
  EXPECT_EQ(to_string(ExrCompression::kPiz), "piz");
}

TEST(ExrIo, AttributesTheWriterOwnsAreRejectedAndNothingIsWritten) {
  const fs::path dir = fresh_dir();
  for (const std::string name : {"", "channels", "dataWindow", "compression", "chromaticities",
                                 "colorInteropID", "worldToNDC", "tilesplatVersion", "tilesplatAnything"}) {
    const fs::path path = dir / "rejected.exr";
    ExrWriteOptions options;
    // emplace: assigning a literal through operator[] trips a GCC 12 -Wrestrict false positive.
    options.attributes.emplace(name, "x");
    const std::string message =
        error_message_of([&] { write_exr(path, make_image(2, 2, false, false), options); });
    EXPECT_EQ(message.rfind("cannot write " + path.string() + ": ", 0), 0u) << message;
    EXPECT_NE(message.find(name.empty() ? "empty name" : "'" + name + "'"), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(path)) << name;
  }
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(ExrIo, StringAttributesOfMissingOrForeignFileGiveClearErrors) {
  const fs::path dir = fresh_dir();
  const fs::path missing = dir / "missing.exr";
  EXPECT_EQ(error_message_of([&] { read_exr_string_attributes(missing); }),
            "cannot read " + missing.string() + ": the file does not exist");
  const fs::path text = dir / "text.exr";
  write_bytes(text, {'n', 'o', 't', ' ', 'e', 'x', 'r'});
  EXPECT_EQ(error_message_of([&] { read_exr_string_attributes(text); }),
            "cannot read " + text.string() + ": not an OpenEXR file");
}

TEST(ExrIo, TruncatedOrForeignFileGivesClearError) {
  const fs::path dir = fresh_dir();
  const fs::path complete = dir / "complete.exr";
  write_exr(complete, make_image(64, 48, true, true));
  const std::vector<char> bytes = read_bytes(complete);

  std::vector<fs::path> broken;
  for (const size_t kept : {size_t{0}, size_t{3}, size_t{40}, bytes.size() / 3, bytes.size() - 5}) {
    broken.push_back(dir / ("truncated_" + std::to_string(kept) + ".exr"));
    write_bytes(broken.back(),
                std::vector<char>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(kept)));
  }
  broken.push_back(dir / "text.exr");
  write_bytes(broken.back(), {'n', 'o', 't', ' ', 'a', 'n', ' ', 'e', 'x', 'r', '\n'});

  for (const fs::path& path : broken) {
    const std::string message = error_message_of([&] { read_exr(path); });
    EXPECT_EQ(message.rfind("cannot read " + path.string() + ": ", 0), 0u) << message;
  }
}

TEST(ExrIo, ReadsSharedReferenceImages) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const fs::path reference_dir = testing::shared_scenes() / "reference";
  std::vector<fs::path> files;
  if (fs::is_directory(reference_dir))
    for (const auto& entry : fs::directory_iterator(reference_dir))
      if (entry.path().extension() == ".exr") files.push_back(entry.path());
  if (files.empty()) TILESPLAT_SKIP_OR_FAIL("no reference images in " << reference_dir);
  std::sort(files.begin(), files.end());

  for (const fs::path& path : files) {
    const RenderImage image = read_exr(path);
    EXPECT_EQ(image.width, 480) << path;
    EXPECT_EQ(image.height, 270) << path;
    ASSERT_EQ(image.rgba.size(), 4 * image.pixels()) << path;
    const size_t non_finite = static_cast<size_t>(
        std::count_if(image.rgba.begin(), image.rgba.end(), [](float v) { return !std::isfinite(v); }));
    EXPECT_EQ(non_finite, 0u) << path;
    float max_alpha = 0;
    for (size_t pixel = 0; pixel < image.pixels(); ++pixel)
      max_alpha = std::max(max_alpha, image.rgba[4 * pixel + 3]);
    EXPECT_GT(max_alpha, 0.0f) << path << ": nothing was rendered";
  }
}

// ---------------------------------------------------------------------------------------------
// Atomic writes

TEST(AtomicWrite, MissingDirectoryThrowsClearErrorAndCreatesNothing) {
  const fs::path dir = fresh_dir();
  const fs::path missing = dir / "missing";
  const fs::path exr = missing / "x.exr";
  EXPECT_EQ(error_message_of([&] { write_exr(exr, make_image(2, 2, false, false)); }),
            "cannot write " + exr.string() + ": directory '" + missing.string() + "' does not exist");
  const fs::path png = missing / "x.png";
  EXPECT_EQ(error_message_of([&] { write_png_preview(png, make_image(2, 2, false, false)); }),
            "cannot write " + png.string() + ": directory '" + missing.string() + "' does not exist");
  EXPECT_THROW(write_exr(exr, make_image(2, 2, false, false)), std::runtime_error);
  EXPECT_FALSE(fs::exists(missing));
  EXPECT_TRUE(directory_entries(dir).empty());
}

TEST(AtomicWrite, InvalidImageLeavesNoFiles) {
  const fs::path dir = fresh_dir();
  const fs::path exr = dir / "bad.exr";
  const fs::path png = dir / "bad.png";

  RenderImage empty;
  RenderImage short_rgba = make_image(4, 4, true, true);
  short_rgba.rgba.pop_back();
  RenderImage bad_depth = make_image(4, 4, true, false);
  bad_depth.depth.resize(3);
  RenderImage bad_counts = make_image(4, 4, false, true);
  bad_counts.splat_count.resize(17);

  for (const RenderImage* image : {&empty, &short_rgba, &bad_depth, &bad_counts}) {
    const std::string message = error_message_of([&] { write_exr(exr, *image); });
    EXPECT_EQ(message.rfind("cannot write " + exr.string() + ": ", 0), 0u) << message;
    EXPECT_THROW(write_exr(exr, *image, ExrWriteOptions{.half = true}), std::runtime_error);
  }
  for (const RenderImage* image : {&empty, &short_rgba}) {
    const std::string message = error_message_of([&] { write_png_preview(png, *image); });
    EXPECT_EQ(message.rfind("cannot write " + png.string() + ": ", 0), 0u) << message;
  }
  for (double stops : {double(std::nanf("")), 21.0, -1e300})
    EXPECT_EQ(error_message_of([&] { write_png_preview(png, make_image(2, 2, false, false), {.exposure_stops = stops}); })
                  .find("cannot write " + png.string() + ": exposure"),
              0u)
        << stops;
  EXPECT_TRUE(directory_entries(dir).empty());
}

TEST(AtomicWrite, WriterFailingHalfWayLeavesNeitherTargetNorTempFile) {
  const fs::path dir = fresh_dir();
  const fs::path target = dir / "out.bin";
  fs::path temp_seen;
  const std::string message = error_message_of([&] {
    detail::write_file_atomically(target, [&](const fs::path& temp) {
      temp_seen = temp;
      write_bytes(temp, {'p', 'a', 'r', 't'});
      throw std::runtime_error("disk on fire");
    });
  });
  EXPECT_EQ(message, "cannot write " + target.string() + ": disk on fire");
  EXPECT_EQ(temp_seen.parent_path(), dir) << "the temporary file must be beside the target";
  EXPECT_EQ(temp_seen.filename().string().rfind(".out.bin.tmp-", 0), 0u) << temp_seen;
  EXPECT_TRUE(directory_entries(dir).empty());

  // Non-std exceptions are cleaned up after too.
  EXPECT_THROW(detail::write_file_atomically(target,
                                             [&](const fs::path& temp) {
                                               write_bytes(temp, {'x'});
                                               throw 42;
                                             }),
               std::runtime_error);
  EXPECT_TRUE(directory_entries(dir).empty());
}

TEST(AtomicWrite, FailedOverwriteKeepsExistingTarget) {
  const fs::path dir = fresh_dir();
  const fs::path target = dir / "keep.exr";
  const RenderImage original = make_image(5, 4, true, false);
  write_exr(target, original);
  const std::vector<char> original_bytes = read_bytes(target);
  ASSERT_FALSE(original_bytes.empty());

  RenderImage invalid = make_image(5, 4, false, false);
  invalid.rgba.resize(3);
  EXPECT_THROW(write_exr(target, invalid), std::runtime_error);
  EXPECT_THROW(detail::write_file_atomically(target,
                                             [&](const fs::path& temp) {
                                               write_bytes(temp, {'h', 'a', 'l', 'f'});
                                               throw std::runtime_error("interrupted");
                                             }),
               std::runtime_error);
  EXPECT_EQ(read_bytes(target), original_bytes);
  EXPECT_EQ(directory_entries(dir), std::set<std::string>{"keep.exr"});

  // A successful overwrite does replace it, again leaving no temporary file behind.
  write_exr(target, make_image(2, 2, false, false));
  EXPECT_EQ(read_exr(target).width, 2);
  EXPECT_EQ(directory_entries(dir), std::set<std::string>{"keep.exr"});
}

TEST(AtomicWrite, PathWithoutDirectoryWritesToCurrentDirectory) {
  const fs::path dir = fresh_dir();
  {
    // Restores the working directory even when the write throws, so later tests are unaffected.
    struct WorkingDirectoryGuard {
      fs::path previous = fs::current_path();
      ~WorkingDirectoryGuard() { fs::current_path(previous); }
    } guard;
    fs::current_path(dir);
    detail::write_file_atomically("plain.txt", [](const fs::path& temp) { write_bytes(temp, {'o', 'k'}); });
  }
  EXPECT_EQ(read_bytes(dir / "plain.txt"), (std::vector<char>{'o', 'k'}));
  EXPECT_EQ(directory_entries(dir), std::set<std::string>{"plain.txt"});
}

// The public writer of contents (the apps' CSV, JSON, SVG and manifests): whole contents, replaced
// whole, a clear error for a missing directory, and nothing left behind either way.
TEST(AtomicWrite, ContentsWriterReplacesWholeAndLeavesNoTemporaryFile) {
  const fs::path dir = fresh_dir();
  const fs::path target = dir / "results.json";
  tilesplat::write_file_atomically(target, "{\"first\": 1}\n");
  EXPECT_EQ(read_bytes(target), (std::vector<char>{'{', '"', 'f', 'i', 'r', 's', 't', '"', ':', ' ', '1', '}', '\n'}));
  const std::string large(3 << 20, 'x');  // several write() calls
  tilesplat::write_file_atomically(target, large);
  EXPECT_EQ(fs::file_size(target), large.size());
  tilesplat::write_file_atomically(target, "");
  EXPECT_EQ(fs::file_size(target), 0u);
  EXPECT_EQ(directory_entries(dir), std::set<std::string>{"results.json"});

  const fs::path missing = dir / "missing" / "out.csv";
  EXPECT_EQ(error_message_of([&] { tilesplat::write_file_atomically(missing, "a,b\n"); }),
            "cannot write " + missing.string() + ": directory '" + (dir / "missing").string() + "' does not exist");
  EXPECT_EQ(directory_entries(dir), std::set<std::string>{"results.json"});
}

// ---------------------------------------------------------------------------------------------
// PNG previews

TEST(PngPreview, WritesTheTrainedColoursAsTheyAre) {
  // Rendered colours are display values already: the preview is round(255 * clamp(c)), no encoding.
  const std::vector<float> colours = {
      0.0f,  1.0f,  0.5f, 0.0031308f, 0.2f, 0.0001f, 2.0f, -1.0f, std::numeric_limits<float>::quiet_NaN(),
      0.04f, 0.75f, 0.01f};
  RenderImage image;
  image.width = 2;
  image.height = 2;
  image.rgba.resize(16);
  for (size_t pixel = 0; pixel < 4; ++pixel) {
    for (size_t c = 0; c < 3; ++c) image.rgba[4 * pixel + c] = colours[3 * pixel + c];
    image.rgba[4 * pixel + 3] = 0.25f;  // alpha is dropped, not applied
  }
  const fs::path path = fresh_dir() / "preview.png";
  write_png_preview(path, image);

  const std::vector<char> bytes = read_bytes(path);
  ASSERT_GE(bytes.size(), 24u);
  const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  EXPECT_EQ(std::memcmp(bytes.data(), signature, 8), 0);
  EXPECT_EQ(std::string(bytes.data() + 12, 4), "IHDR");
  const auto big_endian_at = [&](size_t offset) {
    uint32_t value = 0;
    for (size_t i = 0; i < 4; ++i) value = (value << 8) | static_cast<unsigned char>(bytes[offset + i]);
    return value;
  };
  EXPECT_EQ(big_endian_at(16), 2u);  // width
  EXPECT_EQ(big_endian_at(20), 2u);  // height
  EXPECT_EQ(static_cast<unsigned char>(bytes[24]), 8u);  // bit depth
  EXPECT_EQ(static_cast<unsigned char>(bytes[25]), 2u);  // colour type: RGB
  // The bytes are sRGB-encoded values, and the file says so (an sRGB chunk), as training photographs are.
  EXPECT_NE(std::string(bytes.begin(), bytes.end()).find("sRGB"), std::string::npos);

  const DecodedPng decoded = read_png_rgb(path);
  ASSERT_EQ(decoded.width, 2u);
  ASSERT_EQ(decoded.height, 2u);
  ASSERT_EQ(decoded.rgb.size(), 12u);
  for (size_t i = 0; i < colours.size(); ++i) {
    const double value = std::isnan(colours[i]) ? 0.0 : double{colours[i]};
    EXPECT_EQ(decoded.rgb[i], expected_display_byte(value)) << "colour " << colours[i];
  }
  // As literal values: a second sRGB encoding would make 0.5 188 and 0.0031308 10.
  EXPECT_EQ(decoded.rgb[0], 0);
  EXPECT_EQ(decoded.rgb[1], 255);
  EXPECT_EQ(decoded.rgb[2], 128);
  EXPECT_EQ(decoded.rgb[3], 1);
  EXPECT_EQ(decoded.rgb[4], 51);
  EXPECT_EQ(decoded.rgb[6], 255) << "over-range values clamp to white";
  EXPECT_EQ(decoded.rgb[7], 0) << "negative values clamp to black";
  EXPECT_EQ(decoded.rgb[8], 0) << "NaN becomes black";
}

TEST(PngPreview, ExposureScalesLinearLight) {
  // A stop doubles the light: the colour is decoded, scaled and encoded again.
  RenderImage image;
  image.width = 1;
  image.height = 1;
  image.rgba = {0.25f, 0.125f, 1.0f, 1.0f};
  const fs::path path = fresh_dir() / "exposed.png";
  write_png_preview(path, image, {.exposure_stops = 1.0});  // times 2
  const DecodedPng decoded = read_png_rgb(path);
  ASSERT_EQ(decoded.rgb.size(), 3u);
  EXPECT_EQ(decoded.rgb[0], expected_srgb_byte(2 * decode_srgb(0.25)));
  EXPECT_EQ(decoded.rgb[1], expected_srgb_byte(2 * decode_srgb(0.125)));
  EXPECT_EQ(decoded.rgb[2], 255);
  EXPECT_EQ(decoded.rgb[0], 90);  // 0.25 -> 0.0508 linear -> 0.1016 -> 0.3518: not 0.5 (127)

  write_png_preview(path, image, {.exposure_stops = -2.0});  // times 1/4
  const DecodedPng darker = read_png_rgb(path);
  EXPECT_EQ(darker.rgb[0], expected_srgb_byte(decode_srgb(0.25) / 4));
  EXPECT_EQ(darker.rgb[2], expected_srgb_byte(0.25));
}

TEST(PngPreview, PreviewPixelsAreThePngsBytes) {
  // preview_pixels() gives what write_png_preview() writes, graded or not, without a file.
  RenderImage image;
  image.width = 3;
  image.height = 2;
  for (int i = 0; i < 6; ++i)
    image.rgba.insert(image.rgba.end(),
                      {0.1f * float(i), 0.9f - 0.15f * float(i), 1.5f - 0.3f * float(i), 1.0f});
  const fs::path path = fresh_dir() / "preview.png";
  for (const PreviewOptions options :
       {PreviewOptions{}, PreviewOptions{.exposure_stops = 1.5, .tone_map = ToneMap::kAces}}) {
    write_png_preview(path, image, options);
    const std::vector<uint8_t> pixels = preview_pixels(image, options);
    EXPECT_EQ(pixels, read_png_rgb(path).rgb) << options.exposure_stops;
    EXPECT_EQ(pixels.size(), 18u);
  }
  EXPECT_EQ(preview_pixels(image)[3], 26);  // pixel 1's red, 0.1 as it is: round(25.5)
  EXPECT_THROW(preview_pixels(image, {.exposure_stops = 21}), std::invalid_argument);
  image.rgba.pop_back();
  EXPECT_THROW(preview_pixels(image), std::invalid_argument);
}

TEST(ToneMap, CurvesFollowTheirFormulasAndStayInRange) {
  // Reinhard: x / (1 + x). ACES (Narkowicz): x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), at most 1.
  for (double x : {0.01, 0.18, 0.5, 1.0, 4.0, 100.0}) {
    EXPECT_DOUBLE_EQ(apply_tone_map(ToneMap::kReinhard, x), x / (1 + x)) << x;
    EXPECT_DOUBLE_EQ(apply_tone_map(ToneMap::kAces, x),
                     std::min(1.0, x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)))
        << x;
    EXPECT_DOUBLE_EQ(apply_tone_map(ToneMap::kNone, x), x) << x;
  }
  // Monotonic, from 0 to at most 1; garbage in gives black or white, never NaN.
  for (ToneMap curve : {ToneMap::kAces, ToneMap::kReinhard}) {
    double previous = 0;
    for (double x = 0; x < 50; x += 0.01) {
      const double y = apply_tone_map(curve, x);
      EXPECT_GE(y, previous) << to_string(curve) << " at " << x;
      EXPECT_LE(y, 1.0) << to_string(curve) << " at " << x;
      previous = y;
    }
    EXPECT_EQ(apply_tone_map(curve, std::nan("")), 0.0);
    EXPECT_EQ(apply_tone_map(curve, -3.0), 0.0);
    EXPECT_EQ(apply_tone_map(curve, std::numeric_limits<double>::infinity()), 1.0);
  }
  EXPECT_EQ(to_string(ToneMap::kAces), "aces");
  EXPECT_EQ(to_string(ToneMap::kReinhard), "reinhard");
  EXPECT_EQ(to_string(ToneMap::kNone), "none");
}

TEST(PngPreview, ToneMapCompressesHighlightsInsteadOfClipping) {
  RenderImage image;
  image.width = 3;
  image.height = 1;
  image.rgba = {0.18f, 0.18f, 0.18f, 1.0f, 2.0f, 2.0f, 2.0f, 1.0f, 8.0f, 8.0f, 8.0f, 1.0f};
  const fs::path path = fresh_dir() / "tone.png";
  write_png_preview(path, image);
  const DecodedPng clipped = read_png_rgb(path);
  EXPECT_EQ(clipped.rgb[3], 255);  // 2.0 and 8.0 both clip to white
  EXPECT_EQ(clipped.rgb[6], 255);

  // The curves act on linear light: the decoded colour.
  write_png_preview(path, image, {.tone_map = ToneMap::kReinhard});
  const DecodedPng reinhard = read_png_rgb(path);
  auto reinhard_of = [](double c) { return decode_srgb(c) / (1 + decode_srgb(c)); };
  EXPECT_EQ(reinhard.rgb[0], expected_srgb_byte(reinhard_of(0.18)));
  EXPECT_EQ(reinhard.rgb[3], expected_srgb_byte(reinhard_of(2.0)));
  EXPECT_EQ(reinhard.rgb[6], expected_srgb_byte(reinhard_of(8.0)));
  EXPECT_LT(reinhard.rgb[3], reinhard.rgb[6]);  // highlights stay distinct

  write_png_preview(path, image, {.exposure_stops = -1.0, .tone_map = ToneMap::kAces});
  const DecodedPng aces = read_png_rgb(path);
  EXPECT_EQ(aces.rgb[0], expected_srgb_byte(apply_tone_map(ToneMap::kAces, decode_srgb(0.18) / 2)));
  EXPECT_EQ(aces.rgb[3], expected_srgb_byte(apply_tone_map(ToneMap::kAces, decode_srgb(2.0) / 2)));
  EXPECT_LT(aces.rgb[3], 255);
}

// ---------------------------------------------------------------------------------------------
// Comparison

TEST(CompareImages, IdenticalImagesHaveInfinitePsnrAndNoError) {
  const RenderImage image = make_image(9, 5, false, false);
  const ImageDifference difference = compare_images(image, image);
  EXPECT_TRUE(std::isinf(difference.psnr_db) && difference.psnr_db > 0);
  EXPECT_EQ(difference.max_abs, 0.0);
  EXPECT_EQ(difference.max_abs_alpha, 0.0);
  EXPECT_EQ(difference.rmse, 0.0);
}

TEST(CompareImages, SinglePixelDifferenceIsLocatedAndMeasured) {
  const RenderImage a = make_image(8, 4, false, false);
  RenderImage b = a;
  const int x = 5, y = 2, channel = 1;
  const double delta = 0.25;
  b.rgba[4 * static_cast<size_t>(y * 8 + x) + channel] += static_cast<float>(delta);
  const double actual_delta = double{b.rgba[4 * static_cast<size_t>(y * 8 + x) + channel]} -
                              double{a.rgba[4 * static_cast<size_t>(y * 8 + x) + channel]};

  const ImageDifference difference = compare_images(a, b);
  EXPECT_DOUBLE_EQ(difference.max_abs, actual_delta);
  EXPECT_NEAR(difference.max_abs, delta, 1e-6);
  EXPECT_EQ(difference.worst_x, x);
  EXPECT_EQ(difference.worst_y, y);
  EXPECT_EQ(difference.worst_channel, channel);
  EXPECT_EQ(difference.max_abs_alpha, 0.0);
  const double mse = actual_delta * actual_delta / (3.0 * 8 * 4);
  EXPECT_NEAR(difference.rmse, std::sqrt(mse), 1e-12);
  EXPECT_NEAR(difference.psnr_db, 10.0 * std::log10(1.0 / mse), 1e-9);
  EXPECT_NEAR(difference.psnr_db, 31.864, 0.001);  // 10 log10(96 / 0.0625)

  // An alpha-only difference leaves the RGB metrics alone.
  RenderImage c = a;
  c.rgba[3] += 0.5f;
  const ImageDifference alpha_only = compare_images(a, c);
  EXPECT_NEAR(alpha_only.max_abs_alpha, 0.5, 1e-6);
  EXPECT_EQ(alpha_only.max_abs, 0.0);
  EXPECT_TRUE(std::isinf(alpha_only.psnr_db));
}

TEST(CompareImages, SizeMismatchThrowsNamingBothSizes) {
  const RenderImage a = make_image(4, 3, false, false);
  const RenderImage b = make_image(3, 4, false, false);
  EXPECT_THROW(compare_images(a, b), std::invalid_argument);
  const std::string message = error_message_of([&] { compare_images(a, b); });
  EXPECT_NE(message.find("4x3"), std::string::npos) << message;
  EXPECT_NE(message.find("3x4"), std::string::npos) << message;

  RenderImage short_rgba = a;
  short_rgba.rgba.resize(5);
  EXPECT_THROW(compare_images(a, short_rgba), std::invalid_argument);
}

TEST(CompareImages, NonFiniteValuesFailLoudly) {
  const RenderImage a = make_image(6, 3, false, false);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<std::pair<size_t, float>> poisons = {
      {4 * 7 + 2, nan}, {4 * 3 + 0, inf}, {4 * 9 + 3, nan}};
  for (const auto& [index, value] : poisons) {
    for (const bool poison_first : {true, false}) {
      RenderImage poisoned = a;
      poisoned.rgba[index] = value;
      const ImageDifference difference =
          poison_first ? compare_images(poisoned, a) : compare_images(a, poisoned);
      EXPECT_FALSE(difference.psnr_db >= -1e300) << "index " << index;
      EXPECT_FALSE(difference.psnr_db >= 0.0);
      EXPECT_EQ(difference.max_abs, std::numeric_limits<double>::infinity());
      EXPECT_FALSE(difference.rmse <= 1e300);
      EXPECT_EQ(difference.worst_x, static_cast<int>((index / 4) % 6));
      EXPECT_EQ(difference.worst_y, static_cast<int>((index / 4) / 6));
      EXPECT_EQ(difference.worst_channel, static_cast<int>(index % 4));
    }
  }
  // Even a NaN in the same place in both images is a failure, not a match.
  RenderImage both = a;
  both.rgba[0] = nan;
  EXPECT_FALSE(compare_images(both, both).psnr_db >= 0.0);
}

}  // namespace
}  // namespace tilesplat
