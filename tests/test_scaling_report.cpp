// tilesplat-bench --scaling: the fit that splits each pass's time into parts per Gaussian, per pair
// and per pixel, the tiled scene behind the largest Gaussian counts, and the report as a user runs it.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "process_support.h"
#include "scaling_report.h"
#include "test_support.h"

namespace tilesplat {
namespace {

namespace fs = std::filesystem;
using testing::bundled_sh3;
using testing::fresh_output_dir;
using testing::read_file;

constexpr const char* kBenchExe = TILESPLAT_BENCH_EXE;

testing::ProcessResult run_exe(const char* exe, const std::vector<std::string>& args) {
  return testing::run_process("", exe, args);
}
bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

scaling::Point point(uint64_t gaussians, uint64_t pairs, int width, int height, double projection_ms,
                     double composite_ms, uint64_t bytes) {
  scaling::Point p;
  p.scene = "synthetic";
  p.gaussians = gaussians;
  p.pairs = pairs;
  p.size = {width, height};
  p.passes = {{"projection", projection_ms}, {"composite", composite_ms}};
  p.frame_ms = projection_ms + composite_ms;
  p.device_bytes = bytes;
  return p;
}

TEST(ScalingReport, FitRecoversTheCostsPerGaussianPairAndPixel) {
  // projection = 100 ns per Gaussian + 0.5 ms; composite = 50 ns per pair + 20 ns per pixel;
  // memory = 400 B per Gaussian + 24 B per pixel + 1 MiB.
  std::vector<scaling::Point> points;
  for (uint64_t g : {2000ull, 30000ull, 500000ull, 2000000ull})
    for (auto [w, h] : {std::pair{960, 540}, std::pair{1920, 1080}, std::pair{3840, 2160}}) {
      const uint64_t pixels = uint64_t(w) * uint64_t(h);
      const uint64_t pairs = g * 3 + pixels / 50 + (g % 7) * 1000;  // not a combination of the others
      points.push_back(point(g, pairs, w, h, 100e-6 * double(g) + 0.5,
                             50e-6 * double(pairs) + 20e-6 * double(pixels),
                             400 * g + 24 * pixels + (1u << 20)));
    }
  const std::vector<scaling::Fit> fits = scaling::fit(points);
  ASSERT_EQ(fits.size(), 4u);  // projection, composite, gpu frame, device memory
  EXPECT_EQ(fits[0].what, "projection");
  EXPECT_NEAR(fits[0].per_gaussian * 1e6, 100.0, 1e-6);  // ns per Gaussian
  EXPECT_NEAR(fits[0].fixed, 0.5, 1e-9);
  EXPECT_NEAR(fits[0].per_pair, 0.0, 1e-12);
  EXPECT_EQ(fits[1].what, "composite");
  EXPECT_NEAR(fits[1].per_pair * 1e6, 50.0, 1e-6);
  EXPECT_NEAR(fits[1].per_pixel * 1e6, 20.0, 1e-6);
  EXPECT_NEAR(fits[1].r2, 1.0, 1e-9);
  EXPECT_EQ(fits[3].what, "device memory");
  EXPECT_NEAR(fits[3].per_gaussian, 400.0, 1e-6);
  EXPECT_NEAR(fits[3].per_pixel, 24.0, 1e-6);
  EXPECT_NEAR(fits[3].fixed, double(1u << 20), 1e-3);
  EXPECT_EQ(scaling::dominant_pass(points.back()), "composite");
}

TEST(ScalingReport, FitNeverGivesANegativeCost) {
  // Time falls with the pixel count here: a plain least-squares fit would give it a negative cost.
  std::vector<scaling::Point> points = {point(1000, 5000, 100, 100, 1.0, 5.0, 1),
                                        point(2000, 9000, 200, 200, 2.0, 4.0, 1),
                                        point(4000, 20000, 400, 400, 4.0, 3.0, 1)};
  for (const scaling::Fit& f : scaling::fit(points)) {
    EXPECT_GE(f.per_gaussian, 0.0) << f.what;
    EXPECT_GE(f.per_pair, 0.0) << f.what;
    EXPECT_GE(f.per_pixel, 0.0) << f.what;
    EXPECT_GE(f.fixed, 0.0) << f.what;
  }
}

TEST(ScalingReport, TiledSceneHoldsCopiesSideBySide) {
  GaussianScene scene;
  scene.sh_degree = 0;
  scene.positions = {0, 0, 0, 2, 1, 4};
  scene.log_scales = {0, 0, 0, 0, 0, 0};
  scene.rotations = {1, 0, 0, 0, 1, 0, 0, 0};
  scene.opacity_logits = {0.5f, -0.5f};
  scene.sh = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f};
  const GaussianScene tiled = scaling::tile_scene(scene, 4);
  ASSERT_EQ(tiled.size(), 8u);
  EXPECT_EQ(tiled.sh.size(), 24u);
  // A 2 x 2 grid, 1.05 extents apart in x (2) and z (4); y unchanged.
  EXPECT_FLOAT_EQ(tiled.positions[3 * 2 + 0], 2.1f);  // copy 1, Gaussian 0
  EXPECT_FLOAT_EQ(tiled.positions[3 * 4 + 2], 4.2f);  // copy 2, Gaussian 0
  EXPECT_FLOAT_EQ(tiled.positions[3 * 7 + 1], 1.0f);  // copy 3, Gaussian 1
  EXPECT_FLOAT_EQ(tiled.opacity_logits[7], -0.5f);
  EXPECT_THROW(scaling::tile_scene(scene, 0), std::invalid_argument);
}

TEST(CliBench, ScalingReportMeasuresEverySceneAtEverySizeAndFits) {
  const auto out = fresh_output_dir();
  const fs::path md = out / "scaling.md", csv = out / "scaling.csv", svg = out / "scaling.svg";
  const auto result =
      run_exe(kBenchExe, {bundled_sh3().string(), "--scaling", "--tile-copies", "4", "--resolutions",
                          "64x36,128x72", "--warmup", "1", "--repeat", "1", "--markdown", md.string(),
                          "--csv", csv.string(), "--plot", svg.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  for (const char* text :
       {"64x36", "128x72", "x4 (tiled)", "ns/Gaussian", "ns/pixel", "composite", "device memory", "dominant"})
    EXPECT_TRUE(contains(result.out, text)) << text << "\n" << result.out;
  EXPECT_TRUE(contains(read_file(md), "| what | per Gaussian (ns) |")) << read_file(md);
  EXPECT_TRUE(contains(read_file(csv), ",128,72,")) << read_file(csv);
  for (const fs::path& chart : {svg, out / "scaling_pixels.svg", out / "scaling_memory.svg"})
    EXPECT_TRUE(contains(read_file(chart), "class=\"series\"")) << chart;
  EXPECT_FALSE(contains(result.err, "validation messages")) << result.err;

  const auto copies = run_exe(kBenchExe, {bundled_sh3().string(), "--tile-copies", "4"});
  EXPECT_EQ(copies.exit_code, 2) << copies.err;
  EXPECT_TRUE(contains(copies.err, "--tile-copies applies only with --scaling")) << copies.err;
  const auto view = run_exe(kBenchExe, {bundled_sh3().string(), "--scaling", "--view", "0"});
  EXPECT_EQ(view.exit_code, 2) << view.err;
  const auto with_effects = run_exe(kBenchExe, {bundled_sh3().string(), "--scaling", "--effects"});
  EXPECT_EQ(with_effects.exit_code, 2) << with_effects.err;
}

}  // namespace
}  // namespace tilesplat
