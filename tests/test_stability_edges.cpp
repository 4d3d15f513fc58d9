// The stability suite's hard cases through every path a frame leaves by (issue 58): a frame that is finite
// in memory must stay finite in every file and array it becomes. Colours far outside [0, 1] (SH DC of 1e20,
// 400, -1e20, 1e30) and depths past half's range (a scene 1e5 units away) render once; the frame then goes
// through the EXR in scene-linear and display values, float and half, the PNG preview plain and graded, and
// each file is read back: finite everywhere, equal to the frame where the type holds the value, and where it
// does not, the type's largest finite value with the value's sign, counted (SaturatedValues) and recorded in
// the EXR's header. The host's images (render_to_image) are test_vulkan_interop.cpp's, the Python arrays
// python/tests/test_api.py's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "test_support.h"
#include "tilesplat/image.h"
#include "tilesplat/renderer.h"

namespace tilesplat {
namespace {

namespace fs = std::filesystem;

constexpr double kFloatMax = std::numeric_limits<float>::max();
constexpr double kHalfMax = 65504.0;

// Three overlapping splats in a row, the middle one of colour (SH DC) `dc` and in front, `depth` units from
// the camera, each about 8 pixels across at 64x48 whatever the depth: their edges give pixels of every
// coverage, which the scene-linear conversion divides by.
GaussianScene three_splats(float dc, double depth) {
  GaussianScene scene;
  scene.sh_degree = 0;
  const double spread = 0.1 * depth;  // the row spans the same pixels at any depth
  const float log_scale = float(std::log(0.05 * depth));
  for (int i = 0; i < 3; ++i) {
    scene.positions.insert(scene.positions.end(), {float(spread * (i - 1)), float(0.02 * depth * (i - 1)),
                                                   float(depth * (1 + 0.01 * std::abs(i - 1)))});
    scene.log_scales.insert(scene.log_scales.end(), {log_scale, log_scale, log_scale});
    scene.rotations.insert(scene.rotations.end(), {1, 0, 0, 0});
    scene.opacity_logits.push_back(4.0f);  // alpha 0.98: a DC of 400 decodes past half at the centre
    if (i == 1)
      scene.sh.insert(scene.sh.end(), {dc, dc, dc});
    else
      scene.sh.insert(scene.sh.end(), {0.8f, -0.2f, 0.3f});
  }
  return scene;
}

struct EdgeCase {
  std::string name;
  float dc;      // the middle splat's SH DC
  double depth;  // units in front of the camera
  // What the case is for: its scene-linear colours pass float's range, or half's (so that a check that
  // counts nothing cannot pass for one that counted right).
  bool past_float = false;
  bool past_half = false;
};

void PrintTo(const EdgeCase& c, std::ostream* os) { *os << c.name; }

// The sRGB decoding (IEC 61966-2-1, odd in the sign) in double: the scene-linear value of a premultiplied
// display value at coverage `alpha`, computed here on its own rather than through the library.
double scene_linear(double value, double alpha, bool opaque) {
  auto decode = [](double x) {
    const double m = std::abs(x);
    return std::copysign(m <= 0.04045 ? m / 12.92 : std::pow((m + 0.055) / 1.055, 2.4), x);
  };
  const bool divide = !opaque && alpha > 0.0 && alpha < 1.0;
  return divide ? alpha * decode(value / alpha) : decode(value);
}

// What a type stores of a value: itself if it fits, else the largest finite value with its sign.
double saturated_to(double value, double largest) {
  return std::abs(value) > largest ? std::copysign(largest, value) : value;
}

size_t non_finite(const std::vector<float>& values) {
  size_t count = 0;
  for (const float v : values) count += !std::isfinite(v);
  return count;
}

// Each value within the type's rounding of what it must hold (float: the conversion's own rounding; half:
// 11 bits).
void expect_values(const std::vector<float>& stored, const std::vector<double>& expected, double relative,
                   const std::string& what) {
  ASSERT_EQ(stored.size(), expected.size()) << what;
  size_t wrong = 0;
  for (size_t i = 0; i < stored.size(); ++i) {
    const double tolerance = std::abs(expected[i]) * relative + 0x1p-24;  // half's subnormal spacing
    if (std::abs(double(stored[i]) - expected[i]) > tolerance && wrong++ < 5)
      ADD_FAILURE() << what << ": value " << i << " is " << stored[i] << ", expected " << expected[i];
  }
  EXPECT_EQ(wrong, 0u) << what;
}

class EdgeOutputs : public ::testing::TestWithParam<EdgeCase> {
 protected:
  void SetUp() override {
    const EdgeCase& c = GetParam();
    Renderer& renderer = testing::validated_renderer();
    messages_ = renderer.validation_messages();
    renderer.set_scene(three_splats(c.dc, c.depth));
    RenderSettings settings;
    settings.depth = settings.splat_count = true;
    frame_ = renderer.render(testing::axis_camera(64, 48, 60), settings);
    ASSERT_EQ(non_finite(frame_.rgba), 0u) << "the frame in memory";
    ASSERT_EQ(non_finite(frame_.depth), 0u) << "the frame's depth in memory";
    EXPECT_EQ(renderer.last_frame_stats().saturated.total(), 0u) << "render() returns floats: nothing saturates";
    dir_ = testing::temp_dir() / ("edge_" + c.name);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    EXPECT_EQ(testing::validated_renderer().validation_messages(), messages_) << "validation messages";
  }

  // Writes the frame as `options` say, reads it back as stored and checks what every file must hold:
  // finite values, depth and counts as in memory, and the header's record of what saturated.
  StoredExr write_and_read(const std::string& name, const ExrWriteOptions& options, SaturatedValues& saturated) {
    const fs::path path = dir_ / name;
    saturated = write_exr(path, frame_, options);
    StoredExr stored = read_exr_as_stored(path);
    EXPECT_EQ(non_finite(stored.image.rgba), 0u) << name << ": R G B A";
    EXPECT_EQ(non_finite(stored.image.depth), 0u) << name << ": Z";
    EXPECT_EQ(stored.image.depth, frame_.depth) << name << ": Z is stored as float, as rendered";
    EXPECT_EQ(stored.image.splat_count, frame_.splat_count) << name;
    const auto attributes = read_exr_string_attributes(path);
    const auto record = attributes.find(kSaturatedAttribute);
    if (saturated.total() == 0) {
      EXPECT_EQ(record, attributes.end()) << name << ": nothing saturated, nothing recorded";
    } else if (record == attributes.end()) {
      ADD_FAILURE() << name << ": " << saturated.describe() << " saturated and the header does not say so";
    } else {
      for (const auto& [channel, count] : saturated.channels)
        EXPECT_NE(record->second.find(channel + " " + std::to_string(count)), std::string::npos)
            << name << ": " << record->second;
      EXPECT_NE(record->second.find(options.half ? "(half)" : "(float)"), std::string::npos) << record->second;
    }
    return stored;
  }

  // The values a file of `encoding` and type (largest finite value `largest`) must hold, and how many of
  // them saturate, per channel.
  std::vector<double> expected_values(ColourEncoding encoding, double largest, SaturatedValues& saturated) const {
    std::vector<double> expected(frame_.rgba.size());
    for (size_t i = 0; i < expected.size(); ++i) {
      const size_t channel = i % 4;
      const double alpha = frame_.rgba[i - channel + 3];
      double value = frame_.rgba[i];
      if (channel < 3 && encoding == ColourEncoding::kSceneLinear) value = scene_linear(value, alpha, false);
      // Past the type's range (half's lies within float's): the largest finite value, counted once.
      if (std::abs(value) > largest) ++saturated.channels[std::string(1, "RGBA"[channel])];
      expected[i] = saturated_to(value, largest);
    }
    return expected;
  }

  // The scene-linear EXR of `options` (float or half, its largest finite value `largest`, its rounding
  // `relative`): each value the independent decoding, saturated where past `largest` and counted as
  // expected; `must_saturate` says whether the case passes that range at all.
  void expect_scene_linear_exr(const std::string& type, const ExrWriteOptions& options, double largest,
                               double relative, bool must_saturate) {
    SaturatedValues saturated, expected_saturated;
    const StoredExr stored = write_and_read("linear_" + type + ".exr", options, saturated);
    EXPECT_EQ(stored.encoding, ColourEncoding::kSceneLinear);
    const std::vector<double> expected = expected_values(ColourEncoding::kSceneLinear, largest, expected_saturated);
    expect_values(stored.image.rgba, expected, relative, "scene-linear " + type);
    EXPECT_EQ(saturated.channels, expected_saturated.channels) << saturated.describe();
    EXPECT_EQ(saturated.total() > 0, must_saturate) << saturated.describe();
    std::printf("[ measure  ] %-22s scene-linear %s: %s saturated\n", GetParam().name.c_str(), type.c_str(),
                saturated.describe().c_str());
  }

  RenderImage frame_;
  fs::path dir_;
  uint64_t messages_ = 0;
};

TEST_P(EdgeOutputs, SceneLinearFloatExrIsFiniteAndSaturatesPastFloat) {
  expect_scene_linear_exr("float", {}, kFloatMax, 1e-6, GetParam().past_float);
}

TEST_P(EdgeOutputs, SceneLinearHalfExrIsFiniteAndSaturatesPastHalf) {
  expect_scene_linear_exr("half", {.half = true}, kHalfMax, 0x1p-11, GetParam().past_half);
}

TEST_P(EdgeOutputs, DisplayExrIsTheFrameItself) {
  SaturatedValues saturated, expected_saturated;
  const StoredExr display =
      write_and_read("display_float.exr", {.colour = ColourEncoding::kSrgbDisplay}, saturated);
  EXPECT_EQ(display.image.rgba, frame_.rgba) << "display values as rendered, bit for bit";
  EXPECT_EQ(saturated.total(), 0u);

  const StoredExr half =
      write_and_read("display_half.exr", {.half = true, .colour = ColourEncoding::kSrgbDisplay}, saturated);
  const std::vector<double> expected = expected_values(ColourEncoding::kSrgbDisplay, kHalfMax, expected_saturated);
  expect_values(half.image.rgba, expected, 0x1p-11, "display half");
  EXPECT_EQ(saturated.channels, expected_saturated.channels) << saturated.describe();
}

TEST_P(EdgeOutputs, ReadBackWhereRepresentableIsTheFrame) {
  // read_exr() encodes the scene-linear file back to display values: where nothing saturated, the frame.
  SaturatedValues saturated;
  write_and_read("roundtrip.exr", {}, saturated);
  const RenderImage back = read_exr(dir_ / "roundtrip.exr");
  ASSERT_EQ(back.rgba.size(), frame_.rgba.size());
  size_t compared = 0;
  for (size_t i = 0; i < back.rgba.size(); ++i) {
    const double alpha = frame_.rgba[i - i % 4 + 3];
    if (i % 4 < 3 && std::abs(scene_linear(frame_.rgba[i], alpha, false)) > kFloatMax) continue;
    EXPECT_NEAR(back.rgba[i], frame_.rgba[i], 1e-5 * std::max(1.0, std::abs(double(frame_.rgba[i])))) << i;
    ++compared;
  }
  EXPECT_GT(compared, frame_.rgba.size() / 2);
}

TEST_P(EdgeOutputs, PngPreviewsPlainAndGradedAreTheClampedColour) {
  struct Grade {
    const char* name;
    PreviewOptions options;
  };
  const Grade grades[] = {{"plain", {}},
                          {"exposure+4_aces", {.exposure_stops = 4, .tone_map = ToneMap::kAces}},
                          {"exposure-6_reinhard", {.exposure_stops = -6, .tone_map = ToneMap::kReinhard}},
                          {"exposure+20_none", {.exposure_stops = 20, .tone_map = ToneMap::kNone}}};
  for (const Grade& grade : grades) {
    const fs::path png = dir_ / (std::string(grade.name) + ".png");
    write_png_preview(png, frame_, grade.options);
    const std::vector<uint8_t> pixels = preview_pixels(frame_, grade.options);
    EXPECT_EQ(testing::read_png_rgb(png).rgb, pixels) << grade.name << ": the file is the preview";
    // A colour far above 1 is white under every grade that does not darken it, never black (the NaN of an
    // overflowed conversion would be black); one at or below 0 is black.
    for (size_t p = 0; p < frame_.pixels(); ++p)
      for (size_t c = 0; c < 3; ++c) {
        const float value = frame_.rgba[4 * p + c];
        if (value > 1e3f && grade.options.exposure_stops >= 0) {
          ASSERT_EQ(pixels[3 * p + c], 255) << grade.name << " pixel " << p << " value " << value;
        }
        if (value <= 0.0f) {
          ASSERT_EQ(pixels[3 * p + c], 0) << grade.name << " pixel " << p;
        }
      }
  }
}

std::vector<EdgeCase> edge_cases() {
  return {
      // The issue's file: the scene-linear EXR held inf in 71,241 of its values.
      {"Colour1e20", 1e20f, 3.0, true, true},
      // Display ~113, past half's range once decoded (~8e4 of linear light).
      {"Colour400", 400.0f, 3.0, false, true},
      // Clamped to 0 at the projection, as 3DGS clamps colours.
      {"ColourMinus1e20", -1e20f, 3.0, false, false},
      {"Colour1e30", 1e30f, 3.0, true, true},
      // Z past half's 65,504: the Z channel stays float.
      {"Depth1e5", 0.8f, 1e5, false, false},
  };
}

INSTANTIATE_TEST_SUITE_P(Stability, EdgeOutputs, ::testing::ValuesIn(edge_cases()),
                         [](const auto& param_info) { return param_info.param.name; });

// The depth case is what it says: depths past half's range, and rendered.
TEST(StabilityEdgeCases, DepthCaseLiesPastHalfsRange) {
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(three_splats(0.8f, 1e5));
  RenderSettings settings;
  settings.depth = true;
  const RenderImage image = renderer.render(testing::axis_camera(64, 48, 60), settings);
  float deepest = 0;
  for (const float z : image.depth) deepest = std::max(deepest, z);
  EXPECT_GT(deepest, kHalfMax);
}

// Lens samples accumulated on the GPU (RenderSettings::accumulate_samples, sample_accumulate.comp) of
// colours whose linear values pass float's range: each mean is finite, and the colours past it are
// saturated and counted (FrameStats::saturated); colours that fit (and negative ones, which the blend
// clamps to black) count nothing and equal the host's mean of the same samples (LinearFrameMean, in one
// call). Where the linear colour passed float's range the two saturate alike but not at the same point
// (the shader the colour, the host the premultiplied value in double), so there both are only finite and
// at least the display value of float's largest linear colour.
TEST(StabilityEdgeCases, AccumulatedSamplesOfHugeColoursAreFiniteAndCounted) {
  Renderer& renderer = testing::validated_renderer();
  const uint64_t messages = renderer.validation_messages();
  const Camera camera = testing::axis_camera(64, 48, 60);
  const double largest_display = 1.055 * std::pow(kFloatMax, 1 / 2.4) - 0.055;  // about 1.2e16
  const struct {
    float dc;
    bool past_float;
  } cases[] = {{1e20f, true}, {1e30f, true}, {-1e20f, false}, {0.8f, false}};
  for (const auto& c : cases) {
    char what_text[32];
    std::snprintf(what_text, sizeof(what_text), "dc %g", double(c.dc));
    const std::string what = what_text;
    renderer.set_scene(three_splats(c.dc, 2.0));
    RenderSettings settings;
    settings.lens = {
        .aperture_diameter = 0.02, .focus_distance = 2.0, .samples = 3, .pattern = SamplePattern::kSobol};
    const RenderImage host_mean = renderer.render(camera, settings);  // the host's float64 mean
    EXPECT_EQ(non_finite(host_mean.rgba), 0u) << what;
    settings.accumulate_samples = true;
    settings.lens.samples = 1;
    RenderImage accumulated;
    for (int call = 0; call < 3; ++call) {
      accumulated = renderer.render(camera, settings);
      const SaturatedValues& saturated = renderer.last_frame_stats().saturated;
      EXPECT_EQ(non_finite(accumulated.rgba), 0u) << what << ", call " << call;
      if (!c.past_float) {
        EXPECT_EQ(saturated.total(), 0u) << what << ": " << saturated.describe();
      } else {
        EXPECT_EQ(saturated.channels.size(), 1u) << what << ": " << saturated.describe();
        EXPECT_GT(saturated.channels.count("linear sample mean RGB"), 0u) << what << ", call " << call;
      }
    }
    ASSERT_EQ(renderer.last_frame_stats().accumulated_samples, 3u);
    size_t compared = 0, saturated_values = 0;
    std::vector<float> fits, fits_host;
    for (size_t i = 0; i < accumulated.rgba.size(); ++i) {
      const double alpha = host_mean.rgba[i - i % 4 + 3];
      if (i % 4 != 3 && host_mean.rgba[i] > 1e15 * std::max(alpha, 1e-30)) {  // decoded past about 1e36
        ++saturated_values;
        EXPECT_GE(accumulated.rgba[i], 0.99 * alpha * largest_display) << what << ": value " << i;
        continue;
      }
      fits.push_back(accumulated.rgba[i]);
      fits_host.push_back(host_mean.rgba[i]);
      ++compared;
    }
    EXPECT_EQ(saturated_values > 0, c.past_float) << what;
    expect_values(fits, std::vector<double>(fits_host.begin(), fits_host.end()), 2e-5, what);
    std::printf("[ measure  ] %s: %zu values equal the host's mean, %zu saturated\n", what.c_str(), compared,
                saturated_values);
  }
  EXPECT_EQ(renderer.validation_messages(), messages);
}

TEST(SaturatedValues, CountsPerChannelAndDescribesThem) {
  SaturatedValues a;
  EXPECT_EQ(a.total(), 0u);
  EXPECT_EQ(a.describe(), "none");
  a.channels["R"] = 2;
  SaturatedValues b;
  b.channels["R"] = 1;
  b.channels["Z"] = 4;
  a += b;
  EXPECT_EQ(a.total(), 7u);
  EXPECT_EQ(a.channels.at("R"), 3u);
  EXPECT_EQ(a.describe(), "7 values (R 3, Z 4)");
}

// convert_colours saturates a decoding past float's range and counts it per channel.
TEST(SaturatedValues, ConvertColoursSaturatesPastFloat) {
  const std::vector<float> rgba = {1e20f, -1e20f, 0.5f, 1.0f, 1e20f, 2.0f, 0.0f, 0.5f};
  SaturatedValues saturated;
  const std::vector<float> linear =
      convert_colours(rgba, ColourEncoding::kSrgbDisplay, ColourEncoding::kSceneLinear, false, &saturated);
  EXPECT_EQ(linear[0], std::numeric_limits<float>::max());
  EXPECT_EQ(linear[1], -std::numeric_limits<float>::max());
  EXPECT_FLOAT_EQ(linear[2], float(scene_linear(0.5, 1.0, false)));
  EXPECT_EQ(linear[4], std::numeric_limits<float>::max());  // 0.5 * decode(2e20): past float too
  EXPECT_EQ(saturated.channels, (std::map<std::string, uint64_t>{{"G", 1}, {"R", 2}}));
  for (const float v : linear) EXPECT_TRUE(std::isfinite(v));
}

}  // namespace
}  // namespace tilesplat
