// tilesplat-bench --formats: the attribute comparison behind its fidelity table (matching a reordered
// file back to the reference, quaternion signs, missing SH bands), and the report as a user runs it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "formats_report.h"
#include "process_support.h"
#include "test_support.h"

namespace tilesplat {
namespace {

namespace fs = std::filesystem;
using formats::compare_attributes;

// n Gaussians spread over a 10-unit box, SH degree `degree`, every attribute random.
GaussianScene random_scene(size_t n, int degree, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  GaussianScene scene;
  scene.sh_degree = degree;
  for (size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) scene.positions.push_back(5.0f * uniform(rng));
    for (int a = 0; a < 3; ++a) scene.log_scales.push_back(uniform(rng) - 3.0f);
    float q[4], norm = 0;
    for (float& c : q) {
      c = uniform(rng);
      norm += c * c;
    }
    for (float c : q) scene.rotations.push_back(c / std::sqrt(norm));
    scene.opacity_logits.push_back(3.0f * uniform(rng));
    for (int k = 0; k < scene.sh_coefficients() * 3; ++k) scene.sh.push_back(uniform(rng));
  }
  return scene;
}

// The Gaussians of `scene` in the order `order` (file Gaussian i is scene Gaussian order[i]).
GaussianScene permuted(const GaussianScene& scene, const std::vector<size_t>& order) {
  GaussianScene out;
  out.sh_degree = scene.sh_degree;
  const size_t k = size_t(scene.sh_coefficients()) * 3;
  for (const size_t i : order) {
    out.positions.insert(out.positions.end(), &scene.positions[3 * i], &scene.positions[3 * i + 3]);
    out.log_scales.insert(out.log_scales.end(), &scene.log_scales[3 * i], &scene.log_scales[3 * i + 3]);
    out.rotations.insert(out.rotations.end(), &scene.rotations[4 * i], &scene.rotations[4 * i + 4]);
    out.opacity_logits.push_back(scene.opacity_logits[i]);
    out.sh.insert(out.sh.end(), &scene.sh[k * i], &scene.sh[k * i + k]);
  }
  return out;
}

TEST(FormatsReport, IdenticalScenesHaveNoErrorAndKeepTheirOrder) {
  const GaussianScene scene = random_scene(2000, 2, 1);
  const auto c = compare_attributes(scene, scene);
  EXPECT_TRUE(c.comparable);
  EXPECT_FALSE(c.reordered);
  EXPECT_EQ(c.reference_gaussians_matched, scene.size());
  for (double e : {c.max_abs.position, c.max_abs.log_scale, c.max_abs.rotation, c.max_abs.opacity,
                   c.max_abs.sh_dc, c.max_abs.sh_rest})
    EXPECT_EQ(e, 0);
}

TEST(FormatsReport, AReorderedFileIsMatchedBackByItsMeans) {
  const GaussianScene scene = random_scene(5000, 1, 2);
  std::vector<size_t> order(scene.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(3));
  GaussianScene file = permuted(scene, order);
  // A small quantization of the means on top, as a compressed format leaves it.
  for (float& p : file.positions) p += 1e-4f;
  const auto c = compare_attributes(scene, file);
  EXPECT_TRUE(c.comparable);
  EXPECT_TRUE(c.reordered);
  EXPECT_EQ(c.reference_gaussians_matched, scene.size());
  EXPECT_NEAR(c.max_abs.position, 1e-4, 1e-6);
  EXPECT_EQ(c.max_abs.log_scale, 0);
  EXPECT_EQ(c.max_abs.rotation, 0);
  EXPECT_EQ(c.max_abs.sh_rest, 0);
}

TEST(FormatsReport, ALossyFileThatKeepsTheOrderIsComparedByIndex) {
  const GaussianScene scene = random_scene(3000, 1, 4);
  GaussianScene file = scene;
  // Errors larger than the spacing of some neighbours: nearest-mean matching would pair some wrongly.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> noise(-0.05f, 0.05f);
  for (float& p : file.positions) p += noise(rng);
  file.log_scales[7] += 0.25f;
  file.opacity_logits[9] = scene.opacity_logits[9] + 1.0f;
  const auto c = compare_attributes(scene, file);
  EXPECT_FALSE(c.reordered);
  EXPECT_LE(c.max_abs.position, 0.05 + 1e-6);
  EXPECT_GT(c.max_abs.position, 0.04);
  EXPECT_NEAR(c.max_abs.log_scale, 0.25, 1e-6);
  const auto sigmoid = [](double x) { return 1 / (1 + std::exp(-x)); };
  EXPECT_NEAR(c.max_abs.opacity, sigmoid(scene.opacity_logits[9] + 1.0) - sigmoid(scene.opacity_logits[9]),
              1e-6);
}

TEST(FormatsReport, QuaternionSignDoesNotCountButMissingShBandsDo) {
  const GaussianScene scene = random_scene(100, 2, 6);
  GaussianScene file = scene;
  for (float& q : file.rotations) q = -q;
  // The file keeps the DC term only, as a .splat does.
  file.sh_degree = 0;
  file.sh.clear();
  for (size_t i = 0; i < scene.size(); ++i)
    for (int c = 0; c < 3; ++c) file.sh.push_back(scene.sh[i * 27 + size_t(c)]);
  const auto c = compare_attributes(scene, file);
  EXPECT_EQ(c.max_abs.rotation, 0);
  EXPECT_EQ(c.max_abs.sh_dc, 0);
  double largest_rest = 0;
  for (size_t i = 0; i < scene.size(); ++i)
    for (int k = 3; k < 27; ++k)
      largest_rest = std::max(largest_rest, std::abs(double(scene.sh[i * 27 + size_t(k)])));
  EXPECT_EQ(c.max_abs.sh_rest, largest_rest);
}

TEST(FormatsReport, ScenesOfDifferentCountsAreNotCompared) {
  const GaussianScene scene = random_scene(10, 0, 7);
  const auto c = compare_attributes(scene, random_scene(9, 0, 7));
  EXPECT_FALSE(c.comparable);
}

// The report as a user runs it, on the 64-Gaussian SH3 scene in four formats.
TEST(FormatsReport, BenchReportsEveryFileAgainstTheReference) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const fs::path shared = testing::shared_scenes();
  const fs::path out = testing::temp_dir();
  const fs::path md = out / "formats.md", csv = out / "formats.csv", svg = out / "formats.svg";
  const std::vector<std::string> names = {"playcanvas_test_64_sh3.v4.spz",
                                          "playcanvas_test_64_sh3.compressed.ply",
                                          "playcanvas_test_64_sh3.sog", "playcanvas_test_64_sh3.glb"};
  std::vector<std::string> args = {"--formats", (shared / "playcanvas_test_64_sh3.ply").string()};
  for (const auto& name : names) args.push_back((shared / "formats" / name).string());
  for (const std::string& flag :
       std::vector<std::string>{"--cameras", (shared / "cameras" / "playcanvas_test_64_sh3.json").string(),
                                "--width", "96", "--height", "54", "--warmup", "0", "--repeat", "2",
                                "--markdown", md.string(), "--csv", csv.string(), "--plot", svg.string()})
    args.push_back(flag);
  const auto result = testing::run_process("", TILESPLAT_BENCH_EXE, args);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.err.find("validation messages"), std::string::npos) << result.err;

  // One CSV line per file and view (the first and middle of the 8 views): the reference is identical
  // to itself, the float glTF within float rounding, the lossy formats measurably different.
  const std::string text = testing::read_file(csv);
  std::vector<std::vector<std::string>> lines;
  for (size_t start = text.find('\n') + 1; start < text.size();) {
    const size_t end = text.find('\n', start);
    std::vector<std::string> fields;
    std::string field;
    bool quoted = false;  // the device name has commas: CSV quotes it
    for (char ch : text.substr(start, end - start)) {
      if (ch == '"')
        quoted = !quoted;
      else if (ch == ',' && !quoted)
        fields.push_back(std::exchange(field, {}));
      else
        field += ch;
    }
    fields.push_back(field);
    lines.push_back(fields);
    start = end + 1;
  }
  ASSERT_EQ(lines.size(), 2 * (names.size() + 1)) << text;
  auto psnr = [&](size_t file, size_t view) { return std::stod(lines[2 * file + view][18]); };
  EXPECT_EQ(lines[0][2], "playcanvas_test_64_sh3.ply");
  EXPECT_EQ(lines[0][17], "view 0");
  EXPECT_EQ(lines[1][17], "view 4");
  EXPECT_TRUE(std::isinf(psnr(0, 0)) && std::isinf(psnr(0, 1))) << text;
  for (size_t f = 0; f < names.size(); ++f) {
    const auto& line = lines[2 * (f + 1)];
    EXPECT_EQ(line[2], names[f]);
    EXPECT_EQ(line[4], "64");
    EXPECT_EQ(line[5], "3");
    EXPECT_GT(std::stod(line[6]), 0);  // file bytes
    for (size_t view = 0; view < 2; ++view) EXPECT_GT(psnr(f + 1, view), 30) << names[f] << "\n" << text;
  }
  EXPECT_GT(psnr(4, 0), 100) << "the float glTF\n" << text;
  EXPECT_LT(psnr(1, 0), 100) << "SPZ quantizes\n" << text;
  EXPECT_EQ(lines[2 * 4][11], "0") << "the glTF's positions are floats\n" << text;

  const std::string markdown = testing::read_file(md);
  for (const auto& name : names) EXPECT_NE(markdown.find("| " + name + " |"), std::string::npos) << markdown;
  const std::string plot = testing::read_file(svg);
  size_t points = 0;
  for (size_t at = plot.find("class=\"point\""); at != std::string::npos;
       at = plot.find("class=\"point\"", at + 1))
    ++points;
  EXPECT_EQ(points, names.size() + 1) << plot;
}

TEST(FormatsReport, BenchNeedsAReferenceAndAFile) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const auto one =
      testing::run_process("", TILESPLAT_BENCH_EXE,
                           {"--formats", (testing::shared_scenes() / "playcanvas_test_64_sh3.ply").string()});
  EXPECT_EQ(one.exit_code, 2) << one.err;
  EXPECT_NE(one.err.find("give the lossless PLY first"), std::string::npos) << one.err;
  const auto missing = testing::run_process(
      "", TILESPLAT_BENCH_EXE,
      {"--formats", (testing::shared_scenes() / "playcanvas_test_64_sh3.ply").string(), "no_such_file.spz"});
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.err.find("no_such_file.spz"), std::string::npos) << missing.err;
}

}  // namespace
}  // namespace tilesplat
