// The colour pipeline end to end (docs/colour.md): the PNG holds the trained colours, round(255 * clamp(C)),
// of the float64 reference; the EXR holds their scene-linear decoding and says so; --exr-colour display keeps
// the rendered values. The expected values come from the float64 reference and from the sRGB formulas
// written out here, not from the library's conversion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "process_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace {

namespace fs = std::filesystem;
using tilesplat::testing::bundled_playbot;
using tilesplat::testing::bundled_playbot_cameras;
using tilesplat::testing::fresh_output_dir;
using tilesplat::testing::run_process;

constexpr const char* kRenderExe = TILESPLAT_RENDER_EXE;
constexpr int kWidth = 160, kHeight = 90;

// IEC 61966-2-1's encoding of linear light.
double encode_srgb(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

tilesplat::Camera view_camera(int view) {
  return tilesplat::resize_camera(
      tilesplat::load_cameras_json(bundled_playbot_cameras()).at(size_t(view)).camera, kWidth, kHeight);
}

std::vector<std::string> render_args(int view, const fs::path& exr) {
  return {bundled_playbot().string(),
          "--cameras",
          bundled_playbot_cameras().string(),
          "--view",
          std::to_string(view),
          "--width",
          std::to_string(kWidth),
          "--height",
          std::to_string(kHeight),
          "-o",
          exr.string()};
}

// The PNG of the GPU render is the float64 reference's colour rounded to bytes. The GPU's colours differ
// from the reference by at most ~1e-3 (README: 6.5e-4 on the test scenes), a quarter of a level: a byte
// may take the other neighbour only where the reference's value lies that close to a rounding boundary.
TEST(ColourPipeline, PngIsTheReferenceColourRoundedToBytes) {
  const fs::path out = fresh_output_dir();
  for (const int view : {0, 3}) {
    std::vector<std::string> args = render_args(view, out / "gpu.exr");
    args.insert(args.end(), {"--png", (out / "gpu.png").string()});
    const auto gpu = run_process("", kRenderExe, args);
    ASSERT_EQ(gpu.exit_code, 0) << gpu.err;
    // The reference itself through the app: exactly round(255 * clamp(C)) of its float colours.
    args = render_args(view, out / "ref.exr");
    args.insert(args.end(), {"--reference", "--png", (out / "ref.png").string()});
    const auto ref = run_process("", kRenderExe, args);
    ASSERT_EQ(ref.exit_code, 0) << ref.err;

    const tilesplat::RenderImage reference =
        tilesplat::render_reference(tilesplat::load_scene(bundled_playbot()), view_camera(view));
    const auto gpu_png = tilesplat::testing::read_png_rgb(out / "gpu.png");
    const auto ref_png = tilesplat::testing::read_png_rgb(out / "ref.png");
    ASSERT_EQ(gpu_png.width, unsigned(kWidth));
    ASSERT_EQ(gpu_png.height, unsigned(kHeight));
    ASSERT_EQ(ref_png.rgb.size(), gpu_png.rgb.size());
    size_t exact = 0, straddling = 0, mid_grey_to_bright = 0;
    for (size_t pixel = 0; pixel < reference.pixels(); ++pixel)
      for (size_t c = 0; c < 3; ++c) {
        const double scaled = 255.0 * std::clamp(double(reference.rgba[4 * pixel + c]), 0.0, 1.0);
        const long want = std::lround(scaled);
        const int ref_byte = ref_png.rgb[3 * pixel + c];
        const int gpu_byte = gpu_png.rgb[3 * pixel + c];
        ASSERT_EQ(ref_byte, want) << "reference pixel " << pixel << " channel " << c;
        if (gpu_byte == want) {
          ++exact;
          continue;
        }
        ++straddling;
        ASSERT_EQ(std::abs(gpu_byte - want), 1) << "pixel " << pixel << " channel " << c << ": " << scaled;
        const double boundary = double(gpu_byte + want) / 2.0;  // the half between the two bytes
        ASSERT_LT(std::abs(scaled - boundary), 0.25)
            << "pixel " << pixel << " channel " << c << ": " << scaled;
      }
    // A second sRGB encoding would lift every mid-tone by tens of levels: count the values it would change.
    for (size_t pixel = 0; pixel < reference.pixels(); ++pixel)
      for (size_t c = 0; c < 3; ++c) {
        const double value = std::clamp(double(reference.rgba[4 * pixel + c]), 0.0, 1.0);
        mid_grey_to_bright += std::lround(255 * encode_srgb(value)) - std::lround(255 * value) > 10;
      }
    std::printf(
        "[ measure  ] view %d: %zu values exact, %zu off by one at a rounding boundary; a second "
        "encoding would brighten %zu by more than 10 levels\n",
        view, exact, straddling, mid_grey_to_bright);
    EXPECT_LE(straddling, exact / 100);
    EXPECT_GT(mid_grey_to_bright, reference.pixels() / 20) << "the view should have mid-tones";
  }
}

// The EXR holds scene-linear values, A * decode(C / A), and names the encoding; encoded back with the sRGB
// function they give the rendered colour C within 1e-5 wherever A > 0.01.
TEST(ColourPipeline, ExrHoldsSceneLinearColoursThatEncodeBackToTheRender) {
  const fs::path out = fresh_output_dir();
  const auto result = run_process("", kRenderExe, render_args(2, out / "linear.exr"));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  tilesplat::Renderer& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(tilesplat::load_scene(bundled_playbot()));
  const tilesplat::RenderImage rendered = renderer.render(view_camera(2));

  EXPECT_EQ(tilesplat::read_exr_string_attributes(out / "linear.exr").at("colorInteropID"),
            "lin_rec709_scene");
  const tilesplat::StoredExr stored = tilesplat::read_exr_as_stored(out / "linear.exr");
  ASSERT_EQ(stored.image.rgba.size(), rendered.rgba.size());
  size_t checked = 0, darker = 0;
  double worst = 0;
  for (size_t pixel = 0; pixel < rendered.pixels(); ++pixel) {
    const double alpha = stored.image.rgba[4 * pixel + 3];
    ASSERT_EQ(alpha, rendered.rgba[4 * pixel + 3]);
    if (!(alpha > 0.01)) continue;
    for (size_t c = 0; c < 3; ++c) {
      const double linear = stored.image.rgba[4 * pixel + c];
      const double colour = rendered.rgba[4 * pixel + c];
      worst = std::max(worst, std::abs(alpha * encode_srgb(linear / alpha) - colour));
      darker += linear < colour - 0.01;  // linear light is below the display value in the mid-tones
      ++checked;
    }
  }
  std::printf("[ measure  ] %zu values checked, largest |A encode(L / A) - C| %.3g\n", checked, worst);
  EXPECT_GT(checked, rendered.pixels() / 4);
  EXPECT_LE(worst, 1e-5);
  EXPECT_GT(darker, checked / 4) << "the file's values look like display values, not linear light";
}

TEST(ColourPipeline, ExrColourDisplayKeepsTheRenderedValues) {
  const fs::path out = fresh_output_dir();
  std::vector<std::string> args = render_args(2, out / "display.exr");
  args.insert(args.end(), {"--exr-colour", "display"});
  const auto result = run_process("", kRenderExe, args);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  tilesplat::Renderer& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(tilesplat::load_scene(bundled_playbot()));
  EXPECT_EQ(tilesplat::read_exr_string_attributes(out / "display.exr").at("colorInteropID"),
            "srgb_rec709_display");
  EXPECT_EQ(tilesplat::read_exr_as_stored(out / "display.exr").image.rgba,
            renderer.render(view_camera(2)).rgba);

  args = render_args(2, out / "bad.exr");
  args.insert(args.end(), {"--exr-colour", "acescg"});
  const auto bad = run_process("", kRenderExe, args);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--exr-colour must be linear or display, got 'acescg'"), std::string::npos)
      << bad.err;
  EXPECT_FALSE(fs::exists(out / "bad.exr"));
}

}  // namespace
