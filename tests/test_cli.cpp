// Runs tilesplat-render and tilesplat-bench as processes: exit codes, error messages, outputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "cli.h"
#include "process_support.h"
#include "sha256.h"
#include "test_support.h"
#include "tilesplat/image.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene_description.h"
#include "tilesplat/shutter.h"
#include "tilesplat/version.h"

namespace {

namespace fs = std::filesystem;
namespace cli = tilesplat::cli;
using tilesplat::testing::bundled_playbot;
using tilesplat::testing::bundled_playbot_cameras;
using tilesplat::testing::bundled_sh3;
using tilesplat::testing::bundled_sh3_cameras;
using tilesplat::testing::temp_dir;
using tilesplat::testing::entries;
using tilesplat::testing::expect_one_error_line;
using tilesplat::testing::fresh_output_dir;
using tilesplat::testing::line_count;
using tilesplat::testing::ProcessResult;
using tilesplat::testing::read_file;
using tilesplat::testing::run_process;

constexpr const char* kRenderExe = TILESPLAT_RENDER_EXE;
constexpr const char* kBenchExe = TILESPLAT_BENCH_EXE;

ProcessResult run_exe(const char* exe, const std::vector<std::string>& args) { return run_process("", exe, args); }

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

size_t views_in(const fs::path& cameras_json) {
  const std::string text = read_file(cameras_json);
  size_t count = 0;
  for (size_t pos = text.find("\"img_name\""); pos != std::string::npos; pos = text.find("\"img_name\"", pos + 1))
    ++count;
  return count;
}

// ---------------------------------------------------------------------------------------------
// --help

TEST(CliRender, HelpListsEveryFlag) {
  const auto result = run_exe(kRenderExe, {"--help"});
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(contains(result.out, "usage: tilesplat-render")) << result.out;
  for (const char* flag :
       {"-o,",        "--output",     "--png",          "--exposure",  "--half",       "--no-depth",
        "--no-count", "--background", "--reference",    "--stats",     "--cameras",    "--view",
        "--width",    "--height",     "--azimuth",      "--elevation", "--fov",        "--distance",
        "--strict",   "--device",     "--list-devices", "--sort",      "--validation", "--help",
        "SCENE.ply",  "--tone-map",   "--antialiasing", "--max-alpha", "--stochastic"})
    EXPECT_TRUE(contains(result.out, flag)) << "--help does not mention " << flag << "\n" << result.out;
  EXPECT_TRUE(result.err.empty()) << result.err;
}

// --sample-curve: an averaged effect's sample counts against the frame of 1,024 samples, per effect and
// sample pattern.
TEST(CliBench, SampleCurveHoldsEachCountToManySamples) {
  const auto out = fresh_output_dir();
  for (const char* effect : {"lens", "time", "lens-sobol", "time-sobol"}) {
    const fs::path csv = out / (std::string(effect) + ".csv");
    const auto run =
        run_exe(kBenchExe, {bundled_sh3().string(), "--sample-curve", std::string(effect) + ":1,4,16",
                            "--width", "64", "--height", "48", "--warmup", "0", "--repeat", "1", "--csv",
                            csv.string(), "--plot", (out / "curve.svg").string()});
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_TRUE(contains(run.out, "GPU ms per sample")) << run.out;
    // Each row: ..., effect, samples, gpu_ms, gpu_ms_per_sample, psnr_db, max_abs, provenance...
    std::istringstream lines(tilesplat::testing::read_file(csv));
    std::string line;
    std::getline(lines, line);
    EXPECT_TRUE(contains(line, "effect,samples,gpu_ms,gpu_ms_per_sample,psnr_db,max_abs")) << line;
    std::vector<double> psnr;
    for (const std::string samples : {"1", "4", "16"}) {
      ASSERT_TRUE(std::getline(lines, line));
      std::string key = ",";  // (appended: GCC 12 warns falsely on a chain of + here)
      key.append(effect).append(",").append(samples).append(",");
      const size_t at = line.find(key);
      ASSERT_NE(at, std::string::npos) << line;
      std::istringstream fields(line.substr(at + key.size()));
      std::string gpu_ms, per_sample, db;
      std::getline(fields, gpu_ms, ',');
      std::getline(fields, per_sample, ',');
      std::getline(fields, db, ',');
      EXPECT_NEAR(std::stod(per_sample) * std::stod(samples), std::stod(gpu_ms),
                  1e-3 * std::stod(gpu_ms) + 1e-3);
      psnr.push_back(std::stod(db));
    }
    // More samples, nearer the image of many.
    EXPECT_LT(psnr[0], psnr[1]) << effect;
    EXPECT_LT(psnr[1], psnr[2]) << effect;
    EXPECT_TRUE(contains(tilesplat::testing::read_file(out / "curve.svg"), effect));
  }
  const auto bad = run_exe(kBenchExe, {bundled_sh3().string(), "--sample-curve", "aperture"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_TRUE(contains(bad.err, "--sample-curve takes 'lens' or 'time'")) << bad.err;
  const auto both = run_exe(kBenchExe, {bundled_sh3().string(), "--sample-curve", "lens", "--effects"});
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_TRUE(contains(both.err, "are separate runs")) << both.err;
  const auto count = run_exe(kBenchExe, {bundled_sh3().string(), "--sample-curve", "lens:0"});
  EXPECT_EQ(count.exit_code, 2) << count.err;
}

TEST(CliBench, HelpListsEveryFlag) {
  const auto result = run_exe(kBenchExe, {"--help"});
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(contains(result.out, "usage: tilesplat-bench")) << result.out;
  for (const char* flag : {"--warmup",
                           "--repeat",
                           "--csv",
                           "--json",
                           "--plot",
                           "--cameras",
                           "--view",
                           "--views",
                           "--orbit",
                           "--resolutions",
                           "--width",
                           "--height",
                           "--azimuth",
                           "--elevation",
                           "--fov",
                           "--distance",
                           "--strict",
                           "--device",
                           "--list-devices",
                           "--sort",
                           "--validation",
                           "--help",
                           "SCENE.ply...",
                           "--sort-bench",
                           "--sort-sizes",
                           "--key-bits",
                           "--effects",
                           "--antialiasing",
                           "--accuracy",
                           "--path",
                           "--path-frames",
                           "--path-step",
                           "--consistency-angle",
                           "--scaling",
                           "--tile-copies",
                           "--fisheye",
                           "--orthographic",
                           "--equirectangular",
                           "--lod-curve",
                           "--lod"})
    EXPECT_TRUE(contains(result.out, flag)) << "--help does not mention " << flag << "\n" << result.out;
}

// ---------------------------------------------------------------------------------------------
// Usage errors: exit 2, one line, nothing written

TEST(CliRender, UnknownFlagIsUsageError) {
  const auto out = fresh_output_dir();
  const auto result = run_exe(kRenderExe, {bundled_sh3().string(), "--foo", "-o", (out / "x.exr").string()});
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_TRUE(contains(result.err, "tilesplat-render: error: unknown flag '--foo' (see --help)")) << result.err;
  expect_one_error_line(result, "tilesplat-render");
  EXPECT_TRUE(entries(out).empty());
}

TEST(CliBench, UnknownFlagIsUsageError) {
  const auto result = run_exe(kBenchExe, {bundled_sh3().string(), "--foo"});
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_TRUE(contains(result.err, "tilesplat-bench: error: unknown flag '--foo' (see --help)")) << result.err;
  expect_one_error_line(result, "tilesplat-bench");
}

TEST(CliRender, MissingOutputIsUsageError) {
  const auto result = run_exe(kRenderExe, {bundled_sh3().string()});
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_TRUE(contains(result.err, "-o")) << result.err;
  expect_one_error_line(result, "tilesplat-render");
}

TEST(CliRender, MissingSceneArgumentIsUsageError) {
  const auto out = fresh_output_dir();
  const auto result = run_exe(kRenderExe, {"-o", (out / "x.exr").string()});
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_TRUE(contains(result.err, "SCENE")) << result.err;
  expect_one_error_line(result, "tilesplat-render");
}

TEST(CliRender, MissingFlagValueIsUsageError) {
  const auto out = fresh_output_dir();
  const auto result = run_exe(kRenderExe, {bundled_sh3().string(), "-o", (out / "x.exr").string(), "--width"});
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_TRUE(contains(result.err, "--width expects a value")) << result.err;
  expect_one_error_line(result, "tilesplat-render");
}

TEST(CliRender, BadBackgroundIsRejected) {
  const auto out = fresh_output_dir();
  for (const char* background : {"1,2", "a,b,c", "1,nan,0", "1,2,3,4", "0.5,inf,0"}) {
    const auto result = run_exe(
        kRenderExe, {bundled_sh3().string(), "-o", (out / "x.exr").string(), "--background", background});
    EXPECT_EQ(result.exit_code, 2) << background << ": " << result.err;
    EXPECT_TRUE(contains(result.err, "--background expects")) << result.err;
    EXPECT_TRUE(contains(result.err, background)) << result.err;
    expect_one_error_line(result, "tilesplat-render");
  }
  EXPECT_TRUE(entries(out).empty());
}

TEST(CliRender, BadSizeIsRejected) {
  const auto out = fresh_output_dir();
  const std::string exr = (out / "x.exr").string();
  struct Case {
    std::vector<std::string> flags;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"--width", "0"}, "--width expects a positive integer, got '0'"},
      {{"--width", "abc"}, "--width expects a positive integer, got 'abc'"},
      {{"--height", "-5"}, "--height expects a positive integer, got '-5'"},
      {{"--height", "70000"}, "--height must be at most 65536"},
      {{"--width", "12.5"}, "--width expects a positive integer, got '12.5'"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> args = {bundled_sh3().string(), "-o", exr};
    args.insert(args.end(), c.flags.begin(), c.flags.end());
    const auto result = run_exe(kRenderExe, args);
    EXPECT_EQ(result.exit_code, 2) << c.flags[0] << " " << c.flags[1] << ": " << result.err;
    EXPECT_TRUE(contains(result.err, c.message)) << result.err;
    expect_one_error_line(result, "tilesplat-render");
  }
  EXPECT_TRUE(entries(out).empty());
}

TEST(CliRender, OrbitFlagsConflictWithCameras) {
  const auto out = fresh_output_dir();
  const auto result = run_exe(kRenderExe, {bundled_sh3().string(), "--cameras", bundled_sh3_cameras().string(),
                                           "--azimuth", "30", "-o", (out / "x.exr").string()});
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_TRUE(contains(result.err, "--azimuth")) << result.err;
  const auto view_alone = run_exe(kRenderExe, {bundled_sh3().string(), "--view", "1", "-o", (out / "x.exr").string()});
  EXPECT_EQ(view_alone.exit_code, 2) << view_alone.err;
  EXPECT_TRUE(contains(view_alone.err, "--cameras")) << view_alone.err;
}

TEST(CliBench, RejectsBadCountsAndSorts) {
  const auto zero_repeat = run_exe(kBenchExe, {bundled_sh3().string(), "--repeat", "0"});
  EXPECT_EQ(zero_repeat.exit_code, 2) << zero_repeat.err;
  EXPECT_TRUE(contains(zero_repeat.err, "--repeat expects a positive integer, got '0'")) << zero_repeat.err;

  const auto bad_sort = run_exe(kBenchExe, {bundled_sh3().string(), "--sort", "no-such-sort"});
  EXPECT_EQ(bad_sort.exit_code, 2) << bad_sort.err;
  EXPECT_TRUE(contains(bad_sort.err, "unknown sort strategy 'no-such-sort'")) << bad_sort.err;
  expect_one_error_line(bad_sort, "tilesplat-bench");
}

TEST(CliBench, RejectsBadResolutions) {
  for (const std::string sizes : {"0x720", "1920", "-5x3", "1920x1080,abc", "1280x"}) {
    const auto result = run_exe(kBenchExe, {bundled_sh3().string(), "--resolutions", sizes});
    EXPECT_EQ(result.exit_code, 2) << sizes << ": " << result.err;
    EXPECT_TRUE(contains(result.err, "--resolutions expects WxH sizes")) << result.err;
    std::string quoted = "'";
    quoted += sizes;
    quoted += "'";
    EXPECT_TRUE(contains(result.err, quoted)) << result.err;
    expect_one_error_line(result, "tilesplat-bench");
  }
  const auto with_width = run_exe(kBenchExe, {bundled_sh3().string(), "--resolutions", "64x36", "--width", "64"});
  EXPECT_EQ(with_width.exit_code, 2) << with_width.err;
  EXPECT_TRUE(contains(with_width.err, "--resolutions and --width cannot be combined")) << with_width.err;
}

TEST(CliBench, RejectsBadCameraPaths) {
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::string scene = bundled_sh3().string();
  const std::string cameras = bundled_sh3_cameras().string();
  const std::vector<Case> cases = {
      {{scene, "--views", "0,1"}, "--views needs --cameras"},
      {{scene, "--cameras", cameras, "--view", "0", "--views", "1"}, "--view and --views cannot be combined"},
      {{scene, "--cameras", cameras, "--orbit", "3"}, "--orbit applies only to the orbit camera"},
      {{scene, "--orbit", "0"}, "--orbit expects a positive integer, got '0'"},
      {{scene, "--cameras", cameras, "--views", "0,x"}, "--views expects a non-negative integer, got 'x'"},
      {{scene, scene, "--cameras", cameras, "--cameras", cameras, "--cameras", cameras},
       "--cameras was given 3 times for 2 scenes"},
      {{scene, "--cameras", cameras, "--views", "0," + std::to_string(views_in(bundled_sh3_cameras()))},
       "is out of range"},
      {{scene, "--plot", (temp_dir() / "p.png").string()}, "--plot writes SVG"},
      {{scene, "--csv", (temp_dir() / "same.csv").string(), "--json", (temp_dir() / "same.csv").string()},
       "name the same file"},
  };
  for (const auto& c : cases) {
    const auto result = run_exe(kBenchExe, c.args);
    EXPECT_EQ(result.exit_code, 2) << c.message << ": " << result.err;
    EXPECT_TRUE(contains(result.err, c.message)) << result.err;
    expect_one_error_line(result, "tilesplat-bench");
  }
}

// ---------------------------------------------------------------------------------------------
// Runtime errors: exit 1, the file named, nothing written

TEST(CliRender, MissingSceneFileFails) {
  const auto out = fresh_output_dir();
  const fs::path missing = temp_dir() / "no_such_scene.ply";
  fs::remove(missing);
  const auto result = run_exe(kRenderExe, {missing.string(), "-o", (out / "x.exr").string()});
  EXPECT_EQ(result.exit_code, 1) << result.err;
  EXPECT_TRUE(contains(result.err, "no_such_scene.ply")) << result.err;
  expect_one_error_line(result, "tilesplat-render");
  EXPECT_TRUE(entries(out).empty());
}

TEST(CliRender, TruncatedPlyFails) {
  const auto out = fresh_output_dir();
  const std::string bytes = read_file(bundled_sh3());
  ASSERT_GT(bytes.size(), 1000u);
  const fs::path truncated = temp_dir() / "truncated_sh3.ply";
  {
    std::ofstream file(truncated, std::ios::binary | std::ios::trunc);
    file.write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  }
  const auto result = run_exe(kRenderExe, {truncated.string(), "--cameras", bundled_sh3_cameras().string(), "-o",
                                           (out / "x.exr").string(), "--png", (out / "x.png").string()});
  EXPECT_EQ(result.exit_code, 1) << result.err;
  EXPECT_TRUE(contains(result.err, "truncated_sh3.ply")) << result.err;
  expect_one_error_line(result, "tilesplat-render");
  EXPECT_TRUE(entries(out).empty());
}

TEST(CliRender, OutOfRangeViewNamesTheCount) {
  const auto out = fresh_output_dir();
  const size_t views = views_in(bundled_sh3_cameras());
  ASSERT_GT(views, 0u);
  const auto result = run_exe(kRenderExe, {bundled_sh3().string(), "--cameras", bundled_sh3_cameras().string(),
                                           "--view", std::to_string(views), "-o", (out / "x.exr").string()});
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_TRUE(contains(result.err, std::to_string(views) + " views")) << result.err;
  EXPECT_TRUE(contains(result.err, bundled_sh3_cameras().filename().string())) << result.err;
  expect_one_error_line(result, "tilesplat-render");
  EXPECT_TRUE(entries(out).empty());
}

TEST(CliRender, OutputIntoMissingDirectoryFails) {
  const auto out = fresh_output_dir();
  const fs::path exr = out / "no_such_dir" / "x.exr";
  const auto result = run_exe(kRenderExe, {bundled_sh3().string(), "-o", exr.string()});
  EXPECT_EQ(result.exit_code, 1) << result.err;
  EXPECT_TRUE(contains(result.err, "no_such_dir")) << result.err;
  expect_one_error_line(result, "tilesplat-render");
  EXPECT_FALSE(fs::exists(out / "no_such_dir"));
  EXPECT_TRUE(entries(out).empty());
}

// ---------------------------------------------------------------------------------------------
// Real runs (need the GPU renderer)

TEST(CliRender, RendersExrAndPngPreview) {
  const auto out = fresh_output_dir();
  const fs::path exr = out / "x.exr";
  const fs::path png = out / "x.png";
  const auto result =
      run_exe(kRenderExe, {bundled_sh3().string(), "--cameras", bundled_sh3_cameras().string(), "--view", "0",
                           "--width", "160", "--height", "90", "-o", exr.string(), "--png", png.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  ASSERT_TRUE(fs::exists(exr));
  ASSERT_TRUE(fs::exists(png));
  EXPECT_GT(fs::file_size(exr), 0u);
  EXPECT_GT(fs::file_size(png), 0u);
  // Only the two outputs: no temporary left beside them.
  EXPECT_EQ(entries(out), (std::vector<std::string>{"x.exr", "x.png"}));
  EXPECT_TRUE(contains(result.err, "160x90")) << result.err;
  EXPECT_TRUE(contains(result.err, "x.exr")) << result.err;
  EXPECT_FALSE(contains(result.err, "validation messages")) << result.err;
}

TEST(CliBench, EffectsTableMeasuresEachEffectBesideItsNeverHadItRow) {
  const auto out = fresh_output_dir();
  const fs::path md = out / "effects.md";
  const fs::path csv = out / "effects.csv";
  const auto result =
      run_exe(kBenchExe, {bundled_sh3().string(), "--effects", "--width", "64", "--height", "36", "--warmup", "1",
                          "--repeat", "1", "--sort", "radix", "--markdown", md.string(), "--csv", csv.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  for (const char* row : {"base (all off, SH3)",
                          "sh0 ",
                          "sh1 ",
                          "sh2 ",
                          "sh0 [stored SH0]",
                          "lights: 1 directional + 1 point",
                          "lights off [no normals]",
                          "antialiased",
                          "mip",
                          "+depth",
                          "+splat count",
                          "stochastic, 1 frame",
                          "stochastic_composite",
                          "tile_binning",
                          "camera: opencv",
                          "camera: opencv, all coefficients 0 (off)",
                          "depth of field, aperture 0 (off)",
                          "motion blur, shutter closed (off)",
                          "camera: fisheye, 180 degrees",
                          "camera: orthographic",
                          "camera: equirectangular",
                          "depth of field, 8 lens samples",
                          "motion blur, 8 time samples",
                          "rolling shutter, 8 bands"})
    EXPECT_TRUE(contains(result.out, row)) << row << "\n" << result.out;
  // Every row is a whole frame: the projection and both sorts are measured, never skipped.
  for (const char* pass : {"projection", "depth_sort", "tile_sort", "composite"})
    EXPECT_TRUE(contains(result.out, pass)) << pass << "\n" << result.out;
  const std::string markdown = read_file(md);
  EXPECT_TRUE(contains(markdown, "| sh0 [stored SH0] |")) << markdown;
  const std::string csv_text = read_file(csv);
  EXPECT_TRUE(contains(csv_text, "mip,,projection,")) << csv_text;
  EXPECT_FALSE(contains(result.err, "validation messages")) << result.err;

  const auto two = run_exe(kBenchExe, {bundled_sh3().string(), bundled_sh3().string(), "--effects"});
  EXPECT_EQ(two.exit_code, 2) << two.err;
  EXPECT_TRUE(contains(two.err, "--effects measures one SCENE")) << two.err;
  const auto with_accuracy = run_exe(kBenchExe, {bundled_sh3().string(), "--effects", "--accuracy"});
  EXPECT_EQ(with_accuracy.exit_code, 2) << with_accuracy.err;
}

// --memory-budget: the same EXR in parts (docs/big-scenes.md), the parts and peaks in --stats, sizes
// with units, and what cannot work refused before anything is written.
TEST(CliRender, AFrameLargerThanTheDeviceRendersInPartsWithoutABudget) {
  const auto out = fresh_output_dir();
  auto render = [&](const std::string& prefix, const std::string& name) {
    return tilesplat::testing::run_process(prefix, kRenderExe,
                                           {bundled_playbot().string(), "--width", "160", "--height", "90",
                                            "--stats", "-o", (out / name).string()});
  };
  const auto whole = render("", "whole.exr");
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  EXPECT_TRUE(contains(whole.out, "scene parts                         1\n")) << whole.out;
  // On a device whose largest allocation (1 MiB) is below the scene's spherical harmonics (3.3 MB).
  const auto parts = render("env TILESPLAT_MAX_ALLOCATION=1M ", "parts.exr");
  ASSERT_EQ(parts.exit_code, 0) << parts.err;
  EXPECT_FALSE(contains(parts.out, "scene parts                         1\n")) << parts.out;
  const tilesplat::RenderImage expected = tilesplat::read_exr(out / "whole.exr");
  const tilesplat::RenderImage in_parts = tilesplat::read_exr(out / "parts.exr");
  EXPECT_EQ(in_parts.rgba, expected.rgba);
  EXPECT_EQ(in_parts.depth, expected.depth);
  // A frame whose per-pixel buffers pass it renders in bands of rows, each in parts.
  const auto images = render("env TILESPLAT_MAX_ALLOCATION=256K ", "images.exr");
  ASSERT_EQ(images.exit_code, 0) << images.err;
  EXPECT_TRUE(contains(images.out, "image bands                         6\n")) << images.out;
  const tilesplat::RenderImage in_bands = tilesplat::read_exr(out / "images.exr");
  EXPECT_EQ(in_bands.rgba, expected.rgba);
  EXPECT_EQ(in_bands.depth, expected.depth);
  // One whose one row of tiles passes it cannot be split further: a clear error, and no file.
  const auto tiny = render("env TILESPLAT_MAX_ALLOCATION=64K ", "tiny.exr");
  EXPECT_NE(tiny.exit_code, 0);
  EXPECT_TRUE(contains(tiny.err, "more than the device's largest allocation (65536 bytes)")) << tiny.err;
  EXPECT_FALSE(fs::exists(out / "tiny.exr"));
}

// --region: the whole frame's pixels, written as the EXR's data window; recorded in renderSettings; bad
// regions refused before anything is written.
TEST(CliRender, RegionRendersTheWholeFramesPixels) {
  const auto out = fresh_output_dir();
  auto render = [&](std::vector<std::string> extra, const std::string& name) {
    std::vector<std::string> args = {bundled_playbot().string(), "--width", "160", "--height", "90", "-o",
                                     (out / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_exe(kRenderExe, args);
  };
  ASSERT_EQ(render({}, "whole.exr").exit_code, 0);
  const auto region =
      render({"--region", "10,20,100x30", "--png", (out / "region.png").string()}, "region.exr");
  ASSERT_EQ(region.exit_code, 0) << region.err;
  EXPECT_TRUE(contains(region.err, "160x90 (region 10,20,100x30)")) << region.err;
  const tilesplat::RenderImage whole = tilesplat::read_exr(out / "whole.exr");
  const tilesplat::RenderImage part = tilesplat::read_exr(out / "region.exr");
  ASSERT_EQ(part.width, 100);
  ASSERT_EQ(part.height, 30);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 100; ++x)
      for (size_t c = 0; c < 4; ++c)
        ASSERT_EQ(part.rgba[4 * (size_t(y) * 100 + size_t(x)) + c],
                  whole.rgba[4 * (size_t(y + 20) * 160 + size_t(x + 10)) + c]);
  EXPECT_TRUE(contains(tilesplat::read_exr_string_attributes(out / "region.exr").at("renderSettings"),
                       " region=10,20,100x30"));
  EXPECT_EQ(tilesplat::testing::read_png_rgb(out / "region.png").width, 100u);
  const auto past = render({"--region", "100,0,100x10"}, "past.exr");
  EXPECT_EQ(past.exit_code, 2);
  EXPECT_TRUE(contains(past.err, "--region 100,0,100x10: it reaches past the 160x90 image")) << past.err;
  const auto malformed = render({"--region", "1,2,3"}, "malformed.exr");
  EXPECT_EQ(malformed.exit_code, 2);
  EXPECT_TRUE(contains(malformed.err, "--region: region '1,2,3': expected x,y,WIDTHxHEIGHT"))
      << malformed.err;
  EXPECT_FALSE(fs::exists(out / "past.exr"));
  EXPECT_FALSE(fs::exists(out / "malformed.exr"));
}

TEST(CliRender, MemoryBudgetRendersTheSameImageInParts) {
  const auto out = fresh_output_dir();
  auto render = [&](const std::vector<std::string>& extra, const std::string& name) {
    std::vector<std::string> args = {bundled_playbot().string(), "--width", "160", "--height", "90", "-o",
                                     (out / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_exe(kRenderExe, args);
  };
  ASSERT_EQ(render({}, "whole.exr").exit_code, 0);
  const auto parts = render({"--memory-budget", "4M", "--stats"}, "parts.exr");
  ASSERT_EQ(parts.exit_code, 0) << parts.err;
  EXPECT_TRUE(contains(parts.out, "scene parts")) << parts.out;
  EXPECT_FALSE(contains(parts.out, "scene parts                         1\n")) << parts.out;
  EXPECT_TRUE(contains(parts.out, "peak device memory")) << parts.out;
  EXPECT_TRUE(contains(parts.out, "peak resident memory")) << parts.out;
  const tilesplat::RenderImage whole = tilesplat::read_exr(out / "whole.exr");
  const tilesplat::RenderImage in_parts = tilesplat::read_exr(out / "parts.exr");
  EXPECT_EQ(in_parts.rgba, whole.rgba);
  EXPECT_EQ(in_parts.depth, whole.depth);
  EXPECT_EQ(render({"--memory-budget", "0.5GiB"}, "half_gib.exr").exit_code, 0);
  EXPECT_EQ(tilesplat::read_exr(out / "half_gib.exr").rgba, whole.rgba);

  const auto bad_unit = render({"--memory-budget", "12X"}, "bad.exr");
  EXPECT_EQ(bad_unit.exit_code, 2) << bad_unit.err;
  EXPECT_TRUE(contains(bad_unit.err,
                       "--memory-budget expects a size in bytes (512M, 1.5G, 8GiB, 1048576), got '12X'"))
      << bad_unit.err;
  const auto too_small = render({"--memory-budget", "64K"}, "small.exr");
  EXPECT_NE(too_small.exit_code, 0);
  EXPECT_TRUE(contains(too_small.err, "leaves no room for a Gaussian")) << too_small.err;
  const auto raster = render({"--memory-budget", "4M", "--compositor", "raster"}, "raster.exr");
  EXPECT_NE(raster.exit_code, 0);
  EXPECT_TRUE(contains(raster.err, "raster compositor has no per-pixel state")) << raster.err;
  const auto reference = render({"--memory-budget", "4M", "--reference"}, "reference.exr");
  EXPECT_EQ(reference.exit_code, 2) << reference.err;
  for (const char* name : {"bad.exr", "small.exr", "raster.exr", "reference.exr"})
    EXPECT_FALSE(fs::exists(out / name)) << name;

  // A scene file under a budget: its models stay placed copies of their file, never merged.
  const fs::path two = tilesplat::testing::bundled_scene_dir() / "two_playbots.json";
  auto scene_file = [&](const std::vector<std::string>& extra, const std::string& name) {
    std::vector<std::string> args = {two.string(),         "--view", "0", "--width", "320", "-o",
                                     (out / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_exe(kRenderExe, args);
  };
  ASSERT_EQ(scene_file({}, "two_whole.exr").exit_code, 0);
  const auto placed = scene_file({"--memory-budget", "8M", "--stats"}, "two_parts.exr");
  ASSERT_EQ(placed.exit_code, 0) << placed.err;
  EXPECT_TRUE(contains(placed.err, "62,000 Gaussians (SH2), 2 placed copies of 1 file")) << placed.err;
  EXPECT_FALSE(contains(placed.out, "scene parts                         1\n")) << placed.out;
  EXPECT_EQ(tilesplat::read_exr(out / "two_parts.exr").rgba, tilesplat::read_exr(out / "two_whole.exr").rgba);
  // Without a budget, on a device whose largest allocation (1 MiB) the copies' frame passes: they stay
  // placed copies too, taken part by part (FrameRenderer::decide_holding), into the same image.
  const auto small_device =
      tilesplat::testing::run_process("env TILESPLAT_MAX_ALLOCATION=1M ", kRenderExe,
                                      {two.string(), "--view", "0", "--width", "320", "--stats", "-o",
                                       (out / "two_small_device.exr").string()});
  ASSERT_EQ(small_device.exit_code, 0) << small_device.err;
  EXPECT_FALSE(contains(small_device.out, "scene parts                         1\n")) << small_device.out;
  EXPECT_EQ(tilesplat::read_exr(out / "two_small_device.exr").rgba,
            tilesplat::read_exr(out / "two_whole.exr").rgba);
}

// --read-in-parts: a binary PLY read from its file part by part (MappedPly) is the same EXR, in parts or,
// where the frame fits, loaded whole; what cannot be read so is a clear error and no file.
TEST(CliRender, APlyReadInPartsIsTheSameImage) {
  const auto out = fresh_output_dir();
  auto render = [&](const fs::path& scene, const std::vector<std::string>& extra, const std::string& name) {
    std::vector<std::string> args = {scene.string(),       "--width", "160", "--height", "90", "-o",
                                     (out / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_exe(kRenderExe, args);
  };
  ASSERT_EQ(render(bundled_playbot(), {}, "whole.exr").exit_code, 0);
  const tilesplat::RenderImage whole = tilesplat::read_exr(out / "whole.exr");
  const auto parts =
      render(bundled_playbot(), {"--read-in-parts", "--memory-budget", "4M", "--stats"}, "parts.exr");
  ASSERT_EQ(parts.exit_code, 0) << parts.err;
  EXPECT_FALSE(contains(parts.out, "scene parts                         1\n")) << parts.out;
  EXPECT_TRUE(contains(parts.err, "31,000 Gaussians (SH2), read in parts from the file")) << parts.err;
  const auto fits = render(bundled_playbot(), {"--read-in-parts"}, "fits.exr");
  ASSERT_EQ(fits.exit_code, 0) << fits.err;
  for (const char* name : {"parts.exr", "fits.exr"}) {
    const tilesplat::RenderImage image = tilesplat::read_exr(out / name);
    EXPECT_EQ(image.rgba, whole.rgba) << name;
    EXPECT_EQ(image.depth, whole.depth) << name;
  }
  // The float64 reference takes the scene whole.
  ASSERT_EQ(render(bundled_playbot(), {"--reference"}, "reference.exr").exit_code, 0);
  const auto reference = render(bundled_playbot(), {"--read-in-parts", "--reference"}, "reference_parts.exr");
  ASSERT_EQ(reference.exit_code, 0) << reference.err;
  EXPECT_EQ(tilesplat::read_exr(out / "reference_parts.exr").rgba,
            tilesplat::read_exr(out / "reference.exr").rgba);

  // An ASCII PLY's rows vary in length: refused, naming the file.
  std::string ascii = "ply\nformat ascii 1.0\nelement vertex 1\n";
  for (const char* name : {"x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1",
                           "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
    ascii += std::string("property float ") + name + "\n";
  ascii += "end_header\n0 0 0 0 0 0 0 -3 -3 -3 1 0 0 0\n";
  const fs::path ascii_path = out / "ascii.ply";
  std::ofstream(ascii_path) << ascii;
  const auto refused = render(ascii_path, {"--read-in-parts"}, "ascii.exr");
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_TRUE(contains(refused.err, ascii_path.string() + ": an ASCII PLY cannot be read part by part"))
      << refused.err;
  EXPECT_FALSE(fs::exists(out / "ascii.exr"));
}

// An SPZ or a SOG read in parts: held in its packed bytes or texels, each part decoded from them; the same
// EXR.
TEST(CliRender, AnSpzOrASogReadInPartsIsTheSameImage) {
  TILESPLAT_REQUIRE_SHARED_SCENES();
  const auto out = fresh_output_dir();
  const fs::path formats = tilesplat::testing::shared_scenes() / "formats";
  const std::vector<std::pair<std::string, std::string>> files = {
      {"playbot_lod6_1873_sh2.v4.spz", "its packed bytes"},
      {"playbot_lod6_1873_sh2.sog", "its images' texels"}};
  for (const auto& [file, held] : files) {
    SCOPED_TRACE(file);
    auto render = [&](const std::vector<std::string>& extra, const std::string& name) {
      std::vector<std::string> args = {(formats / file).string(), "--width", "160", "--height", "90", "-o",
                                       (out / name).string()};
      args.insert(args.end(), extra.begin(), extra.end());
      return run_exe(kRenderExe, args);
    };
    ASSERT_EQ(render({}, "whole.exr").exit_code, 0);
    const auto parts = render({"--read-in-parts", "--memory-budget", "1300K", "--stats"}, "parts.exr");
    ASSERT_EQ(parts.exit_code, 0) << parts.err;
    EXPECT_FALSE(contains(parts.out, "scene parts                         1\n")) << parts.out;
    EXPECT_TRUE(contains(parts.err, "1,873 Gaussians (SH2), read in parts from " + held)) << parts.err;
    const tilesplat::RenderImage whole = tilesplat::read_exr(out / "whole.exr");
    const tilesplat::RenderImage image = tilesplat::read_exr(out / "parts.exr");
    EXPECT_EQ(image.rgba, whole.rgba);
    EXPECT_EQ(image.depth, whole.depth);
  }
}

TEST(CliRender, AntialiasingFlagSetsTheFootprintFilter) {
  const auto out = fresh_output_dir();
  auto render = [&](const std::string& mode, const std::string& name) {
    std::vector<std::string> args = {bundled_sh3().string(), "--width", "64", "--height", "36", "-o",
                                     (out / name).string()};
    if (!mode.empty()) args.insert(args.end(), {"--antialiasing", mode});
    return run_exe(kRenderExe, args);
  };
  ASSERT_EQ(render("", "default.exr").exit_code, 0);
  ASSERT_EQ(render("classic", "classic.exr").exit_code, 0);
  ASSERT_EQ(render("mip", "mip.exr").exit_code, 0);
  EXPECT_EQ(tilesplat::read_exr(out / "default.exr").rgba, tilesplat::read_exr(out / "classic.exr").rgba);
  EXPECT_NE(tilesplat::read_exr(out / "classic.exr").rgba, tilesplat::read_exr(out / "mip.exr").rgba);
  const auto bad = render("gaussian", "bad.exr");
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_TRUE(contains(bad.err, "--antialiasing must be classic, antialiased or mip, got 'gaussian'")) << bad.err;
  EXPECT_FALSE(fs::exists(out / "bad.exr"));
}

TEST(CliRender, MaxAlphaFlagSetsTheCapAndIsRecorded) {
  const auto out = fresh_output_dir();
  auto render = [&](const std::string& cap, const std::string& name) {
    std::vector<std::string> args = {bundled_playbot().string(), "--width", "96", "--height", "54", "-o",
                                     (out / name).string()};
    if (!cap.empty()) args.insert(args.end(), {"--max-alpha", cap});
    return run_exe(kRenderExe, args);
  };
  ASSERT_EQ(render("", "default.exr").exit_code, 0);
  ASSERT_EQ(render("0.99", "cap99.exr").exit_code, 0);
  ASSERT_EQ(render("0.999", "gsplat.exr").exit_code, 0);
  EXPECT_EQ(tilesplat::read_exr(out / "default.exr").rgba, tilesplat::read_exr(out / "cap99.exr").rgba);
  EXPECT_NE(tilesplat::read_exr(out / "default.exr").rgba, tilesplat::read_exr(out / "gsplat.exr").rgba);
  EXPECT_TRUE(contains(tilesplat::read_exr_string_attributes(out / "gsplat.exr").at("renderSettings"),
                       " max_alpha=0.999 "));
  EXPECT_FALSE(
      contains(tilesplat::read_exr_string_attributes(out / "default.exr").at("renderSettings"), "max_alpha"));
  for (const std::string bad : {"1", "0", "-0.5", "nan", "high"}) {
    const auto result = render(bad, "bad.exr");
    EXPECT_EQ(result.exit_code, 2) << bad << ": " << result.err;
    EXPECT_TRUE(contains(result.err, "--max-alpha")) << result.err;
    EXPECT_FALSE(fs::exists(out / "bad.exr"));
  }
}

TEST(CliRender, LensFlagsRenderDepthOfFieldAndAreRecorded) {
  const auto out = fresh_output_dir();
  auto render = [&](std::vector<std::string> extra, const std::string& name) {
    std::vector<std::string> args = {bundled_playbot().string(), "--width", "96", "--height", "54", "-o",
                                     (out / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_exe(kRenderExe, args);
  };
  ASSERT_EQ(render({}, "pinhole.exr").exit_code, 0);
  const auto lens = render({"--aperture", "0.2", "--lens-samples", "8"}, "lens.exr");
  ASSERT_EQ(lens.exit_code, 0) << lens.err;
  const auto pinhole = tilesplat::read_exr(out / "pinhole.exr");
  const auto blurred = tilesplat::read_exr(out / "lens.exr");
  EXPECT_LT(tilesplat::compare_images(blurred, pinhole).psnr_db, 45.0);
  EXPECT_TRUE(contains(tilesplat::read_exr_string_attributes(out / "lens.exr").at("renderSettings"),
                       " lens=aperture:0.200000,focus:scene-centre,samples:8"))
      << tilesplat::read_exr_string_attributes(out / "lens.exr").at("renderSettings");
  // The float64 reference through the same lens.
  const auto reference = render({"--aperture", "0.2", "--lens-samples", "8", "--reference"}, "lens_ref.exr");
  ASSERT_EQ(reference.exit_code, 0) << reference.err;
  EXPECT_GE(tilesplat::compare_images(tilesplat::read_exr(out / "lens_ref.exr"), blurred).psnr_db, 60.0);
  // An f-number, focused on a given depth.
  ASSERT_EQ(
      render({"--f-stop", "0.05", "--focus-distance", "3", "--lens-samples", "4"}, "fstop.exr").exit_code, 0);
  EXPECT_TRUE(contains(tilesplat::read_exr_string_attributes(out / "fstop.exr").at("renderSettings"),
                       " lens=f/0.050:sensor:36.000mm:units-per-metre:1.000000,focus:3.000000,samples:4"));

  const std::vector<std::pair<std::vector<std::string>, std::string>> mistakes = {
      {{"--aperture", "0"}, "--aperture must be a positive number, got '0'"},
      {{"--aperture", "nan"}, "--aperture expects a finite number, got 'nan'"},
      {{"--focus-distance", "2"},
       "--focus-distance shapes the lens, and neither --aperture nor --f-stop gave one"},
      {{"--aperture", "0.1", "--f-stop", "2"}, "--aperture and --f-stop both give the aperture"},
      {{"--aperture", "0.1", "--sensor-width", "24"}, "--sensor-width applies to --f-stop only"},
      {{"--aperture", "0.1", "--lens-samples", "0"}, "--lens-samples"},
  };
  for (const auto& [flags, message] : mistakes) {
    const auto result = render(flags, "bad.exr");
    EXPECT_EQ(result.exit_code, 2) << flags.front() << ": " << result.err;
    EXPECT_TRUE(contains(result.err, message)) << result.err;
    EXPECT_FALSE(fs::exists(out / "bad.exr"));
  }
}

TEST(CliRender, SceneFileLensRendersDepthOfFieldUnlessTheFlagsGiveOne) {
  const auto out = fresh_output_dir();
  const std::string camera =
      R"("width": 96, "height": 54, "look_at": {"eye": [0, -1.2, 3.2], "target": [0, -0.35, 0]})";
  auto scene_file = [&](const std::string& name, const std::string& extra) {
    std::ofstream(out / name) << R"({"models": [{"path": ")" << bundled_playbot().generic_string()
                              << R"("}], "cameras": [{)" << camera << extra << "}]}";
    return (out / name).string();
  };
  const std::string sharp = scene_file("sharp.json", "");
  const std::string lens = scene_file("lens.json", R"(, "lens": {"aperture": 0.6, "samples": 8})");
  ASSERT_EQ(run_exe(kRenderExe, {sharp, "-o", (out / "sharp.exr").string()}).exit_code, 0);
  const auto blurred = run_exe(kRenderExe, {lens, "-o", (out / "lens.exr").string()});
  ASSERT_EQ(blurred.exit_code, 0) << blurred.err;
  EXPECT_LT(
      tilesplat::compare_images(tilesplat::read_exr(out / "lens.exr"), tilesplat::read_exr(out / "sharp.exr"))
          .psnr_db,
      40.0);
  const std::string recorded = tilesplat::read_exr_string_attributes(out / "lens.exr").at("renderSettings");
  EXPECT_TRUE(contains(recorded, " lens=aperture:0.6,focus:")) << recorded;  // the target's distance
  EXPECT_TRUE(contains(recorded, ",samples:8")) << recorded;
  // The same as the library through the scene file's lens.
  const tilesplat::SceneDescription description = tilesplat::load_scene_description(lens);
  tilesplat::RenderSettings settings;
  settings.lens = description.lenses.front();
  tilesplat::Renderer& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(tilesplat::load_described_scene(description));
  EXPECT_GE(tilesplat::compare_images(tilesplat::read_exr(out / "lens.exr"),
                                      renderer.render(description.cameras.front().camera, settings))
                .psnr_db,
            60.0);
  // --aperture replaces the scene file's lens.
  ASSERT_EQ(run_exe(kRenderExe,
                    {lens, "--aperture", "0.05", "--lens-samples", "4", "-o", (out / "flag.exr").string()})
                .exit_code,
            0);
  EXPECT_TRUE(contains(tilesplat::read_exr_string_attributes(out / "flag.exr").at("renderSettings"),
                       " lens=aperture:0.050000,focus:scene-centre,samples:4"));
}

TEST(CliRender, ShutterFlagBlursEachFrameOverTheMotionToTheNext) {
  const auto out = fresh_output_dir();
  auto orbit = [&](std::vector<std::string> extra, const std::string& folder) {
    fs::create_directories(out / folder);
    std::vector<std::string> args = {bundled_playbot().string(),
                                     "--orbit",
                                     "3",
                                     "--width",
                                     "96",
                                     "--height",
                                     "54",
                                     "--quiet",
                                     "-o",
                                     (out / folder / "%04d.exr").string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_exe(kRenderExe, args);
  };
  ASSERT_EQ(orbit({}, "still").exit_code, 0);
  const auto blurred = orbit({"--shutter", "180", "--shutter-samples", "4"}, "blurred");
  ASSERT_EQ(blurred.exit_code, 0) << blurred.err;
  const fs::path frame0 = out / "blurred" / "0000.exr";
  EXPECT_TRUE(contains(tilesplat::read_exr_string_attributes(frame0).at("renderSettings"),
                       " shutter=180deg:samples:4"));
  EXPECT_LT(
      tilesplat::compare_images(tilesplat::read_exr(frame0), tilesplat::read_exr(out / "still" / "0000.exr"))
          .psnr_db,
      40.0);
  // Frame 0 is the library's shutter open half the way to frame 1 (an orbit's last frame blurs toward its
  // first).
  const tilesplat::Camera start = *tilesplat::read_exr_camera(out / "still" / "0000.exr");
  const tilesplat::Camera next = *tilesplat::read_exr_camera(out / "still" / "0001.exr");
  tilesplat::RenderSettings settings;
  settings.shutter = {.open = 0, .close = 0.5, .samples = 4, .end_camera = next};
  tilesplat::Renderer& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(tilesplat::load_scene(bundled_playbot()));
  EXPECT_GE(tilesplat::compare_images(tilesplat::read_exr(frame0), renderer.render(start, settings)).psnr_db,
            60.0);
  EXPECT_LT(tilesplat::compare_images(tilesplat::read_exr(out / "blurred" / "0002.exr"),
                                      tilesplat::read_exr(out / "still" / "0002.exr"))
                .psnr_db,
            40.0);
  // A rolling shutter: the same times, read out top to bottom in 4 bands instead of averaged.
  const auto rolled =
      orbit({"--shutter", "180", "--shutter-samples", "4", "--rolling-shutter", "top-to-bottom"}, "rolled");
  ASSERT_EQ(rolled.exit_code, 0) << rolled.err;
  EXPECT_TRUE(
      contains(tilesplat::read_exr_string_attributes(out / "rolled" / "0000.exr").at("renderSettings"),
               " shutter=180deg:samples:4:rolling:top-to-bottom"));
  settings.shutter.scan = tilesplat::ShutterScan::kTopToBottom;
  EXPECT_GE(tilesplat::compare_images(tilesplat::read_exr(out / "rolled" / "0000.exr"),
                                      renderer.render(start, settings))
                .psnr_db,
            60.0);
  EXPECT_LT(
      tilesplat::compare_images(tilesplat::read_exr(out / "rolled" / "0000.exr"), tilesplat::read_exr(frame0))
          .psnr_db,
      45.0);

  const std::vector<std::pair<std::vector<std::string>, std::string>> mistakes = {
      {{"--shutter", "0"}, "--shutter must be in (0, 360] degrees, got '0'"},
      {{"--shutter", "400"}, "--shutter must be in (0, 360] degrees"},
      {{"--shutter-samples", "4"}, "--shutter-samples shapes the shutter, and no --shutter gave one"},
      {{"--rolling-shutter", "top-to-bottom"},
       "--rolling-shutter shapes the shutter, and no --shutter gave one"},
      {{"--shutter", "180", "--rolling-shutter", "diagonal"}, "--rolling-shutter must be top-to-bottom"},
  };
  for (const auto& [flags, message] : mistakes) {
    const auto result = orbit(flags, "bad");
    EXPECT_EQ(result.exit_code, 2) << flags.front() << ": " << result.err;
    EXPECT_TRUE(contains(result.err, message)) << result.err;
    EXPECT_FALSE(fs::exists(out / "bad" / "0000.exr"));
  }
  const auto single =
      run_exe(kRenderExe, {bundled_playbot().string(), "--shutter", "180", "-o", (out / "one.exr").string()});
  EXPECT_EQ(single.exit_code, 2);
  EXPECT_TRUE(contains(single.err,
                       "--shutter blurs the camera's motion from one frame to the next: it needs --orbit "
                       "or --path"))
      << single.err;
}

TEST(CliRender, StochasticFlagConvergesTowardTheSortedImage) {
  const auto out = fresh_output_dir();
  auto render = [&](std::vector<std::string> extra, const std::string& name) {
    std::vector<std::string> args = {bundled_sh3().string(), "--width", "64", "--height", "36", "-o",
                                     (out / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_exe(kRenderExe, args);
  };
  ASSERT_EQ(render({}, "sorted.exr").exit_code, 0);
  const auto few = render({"--stochastic", "4"}, "few.exr");
  ASSERT_EQ(few.exit_code, 0) << few.err;
  ASSERT_EQ(render({"--stochastic", "256"}, "many.exr").exit_code, 0);
  const auto sorted = tilesplat::read_exr(out / "sorted.exr");
  const double few_db = tilesplat::compare_images(tilesplat::read_exr(out / "few.exr"), sorted).psnr_db;
  const double many_db = tilesplat::compare_images(tilesplat::read_exr(out / "many.exr"), sorted).psnr_db;
  std::printf("[ measure  ] stochastic vs sorted: 4 frames %.2f dB, 256 frames %.2f dB\n", few_db, many_db);
  EXPECT_GT(many_db, few_db + 12);  // 64x the frames: 18 dB expected (error ~ 1/sqrt(N))
  EXPECT_GT(many_db, 35);
  const auto zero = render({"--stochastic", "0"}, "zero.exr");
  EXPECT_EQ(zero.exit_code, 2) << zero.err;
  EXPECT_TRUE(contains(zero.err, "--stochastic")) << zero.err;
  const auto with_reference = render({"--stochastic", "4", "--reference"}, "ref.exr");
  EXPECT_EQ(with_reference.exit_code, 2) << with_reference.err;
  EXPECT_FALSE(fs::exists(out / "zero.exr"));
  EXPECT_FALSE(fs::exists(out / "ref.exr"));
}

TEST(CliBench, PrintsTableAndWritesCsvAndJson) {
  const auto out = fresh_output_dir();
  const fs::path csv = out / "c.csv";
  const fs::path json = out / "j.json";
  const auto result = run_exe(kBenchExe, {bundled_sh3().string(), "--width", "64", "--height", "36", "--warmup",
                                          "1", "--repeat", "2", "--csv", csv.string(), "--json", json.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(contains(result.out, "projection")) << result.out;
  EXPECT_TRUE(contains(result.out, "gpu frame")) << result.out;
  EXPECT_TRUE(contains(result.out, "cpu frame")) << result.out;
  EXPECT_TRUE(contains(result.out, "intersections")) << result.out;
  EXPECT_TRUE(contains(result.out, "64x36")) << result.out;
  ASSERT_TRUE(fs::exists(csv));
  ASSERT_TRUE(fs::exists(json));
  const std::string csv_text = read_file(csv);
  const std::string json_text = read_file(json);
  EXPECT_EQ(csv_text.rfind("device,", 0), 0u) << csv_text;
  EXPECT_TRUE(contains(csv_text, "projection")) << csv_text;
  EXPECT_EQ(json_text.rfind("{", 0), 0u) << json_text;
  EXPECT_TRUE(contains(json_text, "\"projection\"")) << json_text;
  EXPECT_EQ(entries(out), (std::vector<std::string>{"c.csv", "j.json"}));
  EXPECT_FALSE(contains(result.err, "validation messages")) << result.err;
}

// The camera-model flags tilesplat-render has: each case's view through the model, named in the table and
// the CSV; one model at a time, and not for the reports that measure pinhole views.
TEST(CliBench, CameraModelFlagsTimeTheViewsThroughAnotherLens) {
  const auto out = fresh_output_dir();
  const fs::path csv = out / "fisheye.csv";
  const auto fisheye =
      run_exe(kBenchExe, {bundled_sh3().string(), "--width", "64", "--height", "36", "--warmup", "0",
                          "--repeat", "1", "--fisheye", "180", "--csv", csv.string()});
  ASSERT_EQ(fisheye.exit_code, 0) << fisheye.err;
  EXPECT_TRUE(contains(fisheye.out, "fov 50.0, fisheye ==")) << fisheye.out;
  EXPECT_TRUE(contains(read_file(csv), "azimuth 0.0 fisheye")) << read_file(csv);
  const auto two = run_exe(kBenchExe, {bundled_sh3().string(), "--fisheye", "180", "--equirectangular"});
  EXPECT_EQ(two.exit_code, 2);
  EXPECT_TRUE(contains(two.err, "are camera models: one of them")) << two.err;
  const auto effects = run_exe(kBenchExe, {bundled_sh3().string(), "--effects", "--orthographic", "2"});
  EXPECT_EQ(effects.exit_code, 2);
  EXPECT_TRUE(contains(effects.err, "--effects measures pinhole views")) << effects.err;
  const auto sort_bench = run_exe(kBenchExe, {"--sort-bench", "--equirectangular"});
  EXPECT_EQ(sort_bench.exit_code, 2);
}

// Every output says which build and command made it: the CSV in four columns of every record, the
// JSON in "tilesplat" and "command" members, an EXR in string attributes.
TEST(CliBench, CsvAndJsonRecordTheBuildAndTheCommand) {
  const auto out = fresh_output_dir();
  const fs::path csv = out / "c.csv";
  const fs::path json = out / "j.json";
  const std::vector<std::string> arguments = {bundled_sh3().string(),
                                              "--width",
                                              "32",
                                              "--height",
                                              "18",
                                              "--sort",
                                              "radix",
                                              "--warmup",
                                              "0",
                                              "--repeat",
                                              "1",
                                              "--csv",
                                              csv.string(),
                                              "--json",
                                              json.string()};
  const auto result = run_exe(kBenchExe, arguments);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  std::string command = "tilesplat-bench";
  for (const auto& argument : arguments) command += " " + argument;
  const tilesplat::BuildInfo build = tilesplat::build_info();
  const std::string provenance = std::string(",") + build.version + "," + build.git_commit + "," +
                                 build.build_type + "," + cli::csv_field(command);

  std::ifstream lines(csv);
  std::string line;
  ASSERT_TRUE(std::getline(lines, line));
  EXPECT_TRUE(line.ends_with(",samples,tilesplat_version,tilesplat_commit,build_type,command")) << line;
  int records = 0;
  while (std::getline(lines, line)) {
    EXPECT_TRUE(line.ends_with(provenance)) << line << "\nexpected to end with " << provenance;
    ++records;
  }
  EXPECT_GT(records, 3);

  // The same members, read as JSON (the bench writes it through nlohmann; the layout is its own).
  const std::string json_text = read_file(json);
  const auto document = nlohmann::ordered_json::parse(json_text);
  const nlohmann::ordered_json expected_build = {
      {"version", build.version}, {"commit", build.git_commit}, {"build_type", build.build_type}};
  EXPECT_EQ(document.at("tilesplat"), expected_build) << json_text;
  EXPECT_EQ(document.at("command"), command) << json_text;
  // Provenance first, in this order, as every JSON output of the apps begins.
  std::vector<std::string> keys;
  for (const auto& [key, value] : document.items()) keys.push_back(key);
  ASSERT_GE(keys.size(), 3u);
  EXPECT_EQ(std::vector<std::string>(keys.begin(), keys.begin() + 3),
            (std::vector<std::string>{"tool", "tilesplat", "command"}));
}

// A scene whose colours are finite but far outside [0, 1] (SH DC 1e20: the issue-58 file): the EXR stays
// finite in scene-linear float and half, the values past the type's range saturate to its largest finite
// value, and the run says how many in one line on stderr, in --stats and in the header.
TEST(CliRender, HugeColoursSaturateInTheExrAndAreReported) {
  const auto out = fresh_output_dir();
  std::string ply = "ply\nformat ascii 1.0\nelement vertex 3\n";
  for (const char* name : {"x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1",
                           "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"})
    ply += std::string("property float ") + name + "\n";
  ply += "end_header\n"
         "-0.3 0 3 0.5 0.5 0.5 4 -1.5 -1.5 -1.5 1 0 0 0\n"
         "0 0 3.03 1e20 1e20 1e20 4 -1.5 -1.5 -1.5 1 0 0 0\n"
         "0.3 0 3.06 400 400 400 4 -1.5 -1.5 -1.5 1 0 0 0\n";
  const fs::path scene = out / "huge_colours.ply";
  std::ofstream(scene) << ply;
  for (const bool half : {false, true}) {
    SCOPED_TRACE(half ? "half" : "float");
    const fs::path exr = out / (half ? "half.exr" : "float.exr");
    std::vector<std::string> args = {scene.string(), "--width", "64", "--height", "48", "--fov", "60", "--stats",
                                     "-o", exr.string()};
    if (half) args.push_back("--half");
    const auto result = run_exe(kRenderExe, args);
    ASSERT_EQ(result.exit_code, 0) << result.err;
    const tilesplat::StoredExr stored = tilesplat::read_exr_as_stored(exr);
    uint64_t at_largest = 0;
    const float largest = half ? 65504.0f : std::numeric_limits<float>::max();
    for (const float v : stored.image.rgba) {
      ASSERT_TRUE(std::isfinite(v)) << v;
      at_largest += std::abs(v) == largest;
    }
    EXPECT_GT(at_largest, 0u);
    const std::string count = std::to_string(at_largest);
    EXPECT_TRUE(contains(result.err, exr.string() + ": " + count + " values (")) << result.err;
    EXPECT_TRUE(contains(result.err, std::string("past the range of ") + (half ? "half" : "float"))) << result.err;
    EXPECT_TRUE(contains(result.out, "saturated values")) << result.out;
    EXPECT_TRUE(contains(result.out, count)) << result.out;
    const auto attributes = tilesplat::read_exr_string_attributes(exr);
    ASSERT_TRUE(attributes.count(tilesplat::kSaturatedAttribute)) << "the header records it";
    EXPECT_TRUE(contains(attributes.at(tilesplat::kSaturatedAttribute), half ? "(half)" : "(float)"));
  }
  // The display values hold the frame as it is: nothing saturates, nothing is said.
  const fs::path display = out / "display.exr";
  const auto result = run_exe(kRenderExe, {scene.string(), "--width", "64", "--height", "48", "--exr-colour",
                                           "display", "-o", display.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_FALSE(contains(result.err, "saturated")) << result.err;
  EXPECT_FALSE(tilesplat::read_exr_string_attributes(display).count(tilesplat::kSaturatedAttribute));
}

TEST(CliRender, ExrRecordsTheBuildAndTheCommand) {
  const auto out = fresh_output_dir();
  const fs::path exr = out / "with space.exr";
  const auto result =
      run_exe(kRenderExe, {bundled_sh3().string(), "--width", "32", "--height", "18", "-o", exr.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto attributes = tilesplat::read_exr_string_attributes(exr);
  EXPECT_EQ(attributes.at("tilesplatVersion"), tilesplat::version());
  // The argument with a space is quoted, so that a shell can run the command again.
  EXPECT_EQ(attributes.at("commandLine"), "tilesplat-render " + bundled_sh3().string() +
                                              " --width 32 --height 18 -o '" + exr.string() + "'");
}

TEST(CliRender, ExrRecordsTheCameraOfTheView) {
  const auto out = fresh_output_dir();
  const fs::path exr = out / "view2.exr";
  const auto result =
      run_exe(kRenderExe, {bundled_playbot().string(), "--cameras", bundled_playbot_cameras().string(),
                           "--view", "2", "--width", "96", "--height", "54", "-o", exr.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto camera = tilesplat::read_exr_camera(exr);
  ASSERT_TRUE(camera.has_value());
  const auto views = tilesplat::load_cameras_json(bundled_playbot_cameras());
  EXPECT_EQ(*camera, tilesplat::resize_camera(views.at(2).camera, 96, 54));
  const auto attributes = tilesplat::read_exr_string_attributes(exr);
  EXPECT_EQ(attributes.at("scene"), bundled_playbot().string());
  EXPECT_TRUE(contains(attributes.at("view"), "view 2")) << attributes.at("view");
  EXPECT_EQ(attributes.at("viewIndex"), "2");
  EXPECT_EQ(attributes.at("viewName"), views.at(2).name);
  EXPECT_EQ(attributes.at("sceneSha256"), cli::sha256_file_hex(bundled_playbot()));
  EXPECT_EQ(attributes.at("sceneSha256").size(), 64u);
  // The settings as asked for (the default sort is "auto"), and the strategy it chose on this device.
  EXPECT_EQ(attributes.at("renderSettings"),
            "sort=auto accuracy=reference antialiasing=classic compositor=sorted lights=0 background=0,0,0");
  // Rendering the camera read back gives the file's image again (to float rounding: the file holds
  // scene-linear values, which read_exr encodes back).
  const auto renderer = tilesplat::Renderer::create();
  EXPECT_EQ(attributes.at("sortStrategy"), renderer->sort_strategy_for("auto"));
  if (renderer->device_info().cpu) {
    EXPECT_EQ(attributes.at("sortStrategy"), "cpu-radix");
  }
  renderer->set_scene(tilesplat::load_scene(bundled_playbot()));
  EXPECT_LE(tilesplat::compare_images(renderer->render(*camera), tilesplat::read_exr(exr)).max_abs, 1e-6);
}

TEST(CliRender, ExrCompressionFlagChoosesTheMethod) {
  const auto out = fresh_output_dir();
  for (const char* method : {"zip", "piz", "dwaa", "none"}) {
    const fs::path exr = out / (std::string(method) + ".exr");
    const auto result = run_exe(kRenderExe, {bundled_sh3().string(), "--width", "32", "--height", "18",
                                             "--exr-compression", method, "--half", "-o", exr.string()});
    ASSERT_EQ(result.exit_code, 0) << result.err;
    EXPECT_EQ(tilesplat::read_exr(exr).width, 32) << method;
  }
  EXPECT_GT(fs::file_size(out / "none.exr"), fs::file_size(out / "zip.exr"));
  const auto bad = run_exe(
      kRenderExe, {bundled_sh3().string(), "--exr-compression", "lzma", "-o", (out / "bad.exr").string()});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_TRUE(contains(bad.err, "--exr-compression must be zip, piz, dwaa or none, got 'lzma'")) << bad.err;
  EXPECT_FALSE(fs::exists(out / "bad.exr"));
}

TEST(CliProvenance, ColumnsFollowRecordsNotLinesInsideQuotedFields) {
  const tilesplat::BuildInfo build = tilesplat::build_info();
  const std::string values = std::string(",") + build.version + "," + build.git_commit + "," +
                             build.build_type + ",\"run \"\"x\"\", y\"";
  const std::string csv = "a,b\r\n\"two\nlines\",\"q\"\"\"\n1,2";
  EXPECT_EQ(cli::with_provenance_columns(csv, "run \"x\", y"),
            "a,b,tilesplat_version,tilesplat_commit,build_type,command\r\n\"two\nlines\",\"q\"\"\"" + values +
                "\n1,2" + values);
  EXPECT_EQ(cli::with_provenance_columns("", "c"), "");
}

TEST(CliProvenance, CommandLineQuotesWhatAShellWouldSplit) {
  const char* argv[] = {"./build/apps/tilesplat-bench", "a.ply", "my file.csv", "it's", "", "--x=$HOME"};
  EXPECT_EQ(cli::command_line("tilesplat-bench", 6, argv),
            "tilesplat-bench a.ply 'my file.csv' 'it'\\''s' '' '--x=$HOME'");
}

TEST(CliBench, AccuracyReportMeasuresPoppingAndViewConsistencyPerMode) {
  const auto out = fresh_output_dir();
  const fs::path csv = out / "a.csv";
  const fs::path md = out / "a.md";
  const fs::path plot = out / "p.svg";
  const auto result =
      run_exe(kBenchExe, {bundled_sh3().string(), "--accuracy", "--mode", "reference,resort4", "--width", "64",
                          "--height", "36", "--warmup", "0", "--repeat", "1", "--path", "orbit", "--path-frames", "3",
                          "--path-step", "0.01", "--consistency-angle", "0.05", "--csv", csv.string(), "--markdown",
                          md.string(), "--plot", plot.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(contains(result.out, "float64 reference on the orbit")) << result.out;
  EXPECT_TRUE(contains(result.out, "turned 0.050 rad")) << result.out;
  EXPECT_TRUE(contains(result.out, "incons%")) << result.out;
  const std::string csv_text = read_file(csv);
  EXPECT_EQ(csv_text.rfind("device,scene,mode,", 0), 0u) << csv_text;
  EXPECT_TRUE(contains(csv_text, ",pop_fraction,pop_mean,inconsistent_fraction,inconsistency_mean,")) << csv_text;
  EXPECT_EQ(std::count(csv_text.begin(), csv_text.end(), '\n'), 3) << csv_text;  // header, two modes
  const std::string md_text = read_file(md);
  EXPECT_TRUE(contains(md_text, "3-frame orbit (step 0.0100)")) << md_text;
  EXPECT_TRUE(contains(md_text, "turned in place by 0.050 rad")) << md_text;
  EXPECT_TRUE(contains(md_text, "| inconsistent % | inconsistency |")) << md_text;
  // The depth-warped pops and the PSNR against the exact per-pixel order, in every output.
  EXPECT_TRUE(contains(result.out, "warp%") && contains(result.out, "vs ray")) << result.out;
  EXPECT_TRUE(contains(csv_text, ",warp_pop_fraction,warp_pop_mean,psnr_vs_ray_order_db,")) << csv_text;
  EXPECT_TRUE(contains(md_text, "| pops % | warped pops % |")) << md_text;
  EXPECT_TRUE(contains(md_text, "| PSNR vs exact ray order dB |")) << md_text;
  EXPECT_TRUE(contains(read_file(plot), "PSNR against the float64 reference"));
  EXPECT_TRUE(contains(read_file(out / "p_consistency.svg"), "blocks inconsistent under the turn"));
  const std::string popping_chart = read_file(out / "p_popping.svg");
  EXPECT_TRUE(contains(popping_chart, "Popping along the path") && contains(popping_chart, "resort4"))
      << popping_chart;
  EXPECT_EQ(entries(out),
            (std::vector<std::string>{"a.csv", "a.md", "p.svg", "p_consistency.svg", "p_popping.svg"}));
  EXPECT_FALSE(contains(result.err, "validation messages")) << result.err;

  for (const auto& [flag, value, message] :
       {std::tuple<const char*, const char*, const char*>{"--path", "spiral", "--path: 'spiral' is not dolly, pan or orbit"},
        {"--path-step", "0", "--path-step: 0 is not in (0, 0.1]"},
        {"--consistency-angle", "-0.1", "--consistency-angle: -0.1 is not in [0, 0.5]"}}) {
    const auto bad = run_exe(kBenchExe, {bundled_sh3().string(), "--accuracy", flag, value});
    EXPECT_EQ(bad.exit_code, 2) << flag << ": " << bad.err;
    EXPECT_TRUE(contains(bad.err, message)) << bad.err;
    expect_one_error_line(bad, "tilesplat-bench");
  }
}

TEST(CliBench, OutputIntoMissingDirectoryFailsBeforeMeasuring) {
  const auto out = fresh_output_dir();
  for (const char* flag : {"--csv", "--json", "--plot"}) {
    const fs::path file = out / "no_such_dir" / "x.svg";
    // --repeat is large: the run must stop before measuring anything.
    const auto result = run_exe(kBenchExe, {bundled_playbot().string(), "--repeat", "100000", flag, file.string()});
    EXPECT_EQ(result.exit_code, 1) << flag << ": " << result.err;
    EXPECT_TRUE(contains(result.err, "no_such_dir")) << result.err;
    EXPECT_TRUE(contains(result.err, flag)) << result.err;
    expect_one_error_line(result, "tilesplat-bench");
    EXPECT_TRUE(result.out.empty()) << result.out;
  }
  const auto sort_bench = run_exe(kBenchExe, {"--sort-bench", "--plot", (out / "no_such_dir" / "s.svg").string()});
  EXPECT_EQ(sort_bench.exit_code, 1) << sort_bench.err;
  EXPECT_TRUE(contains(sort_bench.err, "no_such_dir")) << sort_bench.err;
  EXPECT_TRUE(entries(out).empty());
}

// Two scenes, each with its cameras.json, two views each at two sizes: a row per camera and sort,
// the statistics over the views, and a bar per scene and size in the plot.
TEST(CliBench, MeasuresSeveralScenesViewsAndSizes) {
  const auto out = fresh_output_dir();
  const fs::path csv = out / "c.csv";
  const fs::path json = out / "j.json";
  const fs::path svg = out / "p.svg";
  const auto result = run_exe(
      kBenchExe, {bundled_sh3().string(), bundled_playbot().string(), "--cameras", bundled_sh3_cameras().string(),
                  "--cameras", bundled_playbot_cameras().string(), "--views", "0,1", "--resolutions", "64x36,32x18",
                  "--sort", "radix", "--warmup", "0", "--repeat", "2", "--csv", csv.string(), "--json",
                  json.string(), "--plot", svg.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(entries(out), (std::vector<std::string>{"c.csv", "j.json", "p.svg"}));
  for (const char* heading : {"playcanvas_test_64_sh3.ply at 64x36: 2 views", "playcanvas_test_64_sh3.ply at 32x18",
                              "playbot_lod3_31000_sh2.ply at 64x36", "playbot_lod3_31000_sh2.ply at 32x18"})
    EXPECT_TRUE(contains(result.out, heading)) << heading << "\n" << result.out;
  EXPECT_TRUE(contains(result.out, "over the 2 views")) << result.out;
  EXPECT_TRUE(contains(result.err, "16 frames")) << result.err;  // 2 scenes x 2 sizes x 2 views x 2 frames

  const std::string csv_text = read_file(csv);
  // 8 cameras measured over frames, 4 (scene, size) summaries over views; projection once in each.
  size_t per_frames = 0, per_views = 0;
  for (size_t pos = csv_text.find(",projection,ms,"); pos != std::string::npos;
       pos = csv_text.find(",projection,ms,", pos + 1)) {
    const std::string rest = csv_text.substr(pos + 15, 6);
    per_frames += rest == "frames";
    per_views += rest.rfind("views", 0) == 0;
  }
  EXPECT_EQ(per_frames, 8u) << csv_text;
  EXPECT_EQ(per_views, 4u) << csv_text;
  EXPECT_EQ(csv_text.rfind("device,scene,width,height,view,camera,sort,", 0), 0u) << csv_text;
  EXPECT_TRUE(contains(csv_text, ",32,18,view 1,")) << csv_text;
  EXPECT_TRUE(contains(csv_text, ",64,36,all,2 views,radix,")) << csv_text;

  const std::string json_text = read_file(json);
  size_t results = 0;
  for (size_t pos = json_text.find("\"camera\": \"view "); pos != std::string::npos;
       pos = json_text.find("\"camera\": \"view ", pos + 1))
    ++results;
  EXPECT_EQ(results, 8u) << json_text;
  EXPECT_TRUE(contains(json_text, "\"summaries\"")) << json_text;

  const std::string svg_text = read_file(svg);
  EXPECT_EQ(svg_text.rfind("<?xml", 0), 0u);
  EXPECT_TRUE(contains(svg_text, "data-bar=\"3\" data-segment=\"composite\"")) << svg_text;
  EXPECT_FALSE(contains(svg_text, "data-bar=\"4\"")) << svg_text;
  EXPECT_TRUE(contains(svg_text, "class=\"legend-label\">projection</text>")) << svg_text;
  EXPECT_TRUE(contains(svg_text, "64x36")) << svg_text;
  EXPECT_FALSE(contains(result.err, "validation messages")) << result.err;
}

TEST(CliBench, OrbitPathIsEvenlySpacedInAzimuth) {
  const auto out = fresh_output_dir();
  const fs::path csv = out / "c.csv";
  const auto result = run_exe(kBenchExe, {bundled_sh3().string(), "--orbit", "4", "--azimuth", "10", "--width", "32",
                                          "--height", "18", "--sort", "radix", "--warmup", "0", "--repeat", "1",
                                          "--csv", csv.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::string csv_text = read_file(csv);
  for (const char* view : {",azimuth 10.0,orbit azimuth 10.0 elevation 20.0", ",azimuth 100.0,", ",azimuth 190.0,",
                           ",azimuth 280.0,", ",all,4 views,"})
    EXPECT_TRUE(contains(csv_text, view)) << view << "\n" << csv_text;
}

TEST(CliBench, SortBenchDrawsThroughputLines) {
  const auto out = fresh_output_dir();
  const fs::path svg = out / "s.svg";
  const auto result = run_exe(kBenchExe, {"--sort-bench", "--sort", "radix", "--sort-sizes", "4,6,8", "--key-bits",
                                          "16", "--warmup", "0", "--repeat", "1", "--plot", svg.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(entries(out), (std::vector<std::string>{"s.svg"}));
  const std::string svg_text = read_file(svg);
  for (const char* series : {"radix, 16-bit keys", "std::sort (cpu), 16-bit keys", "cpu radix (cpu), 16-bit keys"})
    EXPECT_TRUE(contains(svg_text, "<polyline class=\"series\" data-series=\"" + std::string(series) + "\""))
        << series << "\n" << svg_text;
  EXPECT_TRUE(contains(svg_text, "Mkeys/s")) << svg_text;
}

// ---------------------------------------------------------------------------------------------
// Scene files (docs/scene-format.md) in place of a .ply

// Two bundled scenes composed, two cameras of its own, a blue background, colour and depth only.
fs::path write_scene_file(const std::string& effects = "") {
  const fs::path path = temp_dir() / "scene.json";
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      << R"({"models": [{"path": ")" << bundled_playbot().string() << R"("},
                   {"path": ")" << bundled_sh3().string() << R"(", "translation": [0.5, 0, 0], "scale": 0.5,
                    "rotation_deg": [0, 30, 0]}],
        "cameras": [{"name": "front", "width": 64, "height": 36,
                     "look_at": {"eye": [0, -0.5, 2.5], "target": [0, 0, 0], "fov_deg": 45}},
                    {"name": "side", "width": 64, "height": 36, "look_at": {"eye": [2.5, -0.5, 0], "target": [0, 0, 0]}}],
        "background": [0, 0, 1],
        "outputs": ["color", "depth"])"
      << (effects.empty() ? "" : ", \"effects\": " + effects) << "}";
  return path;
}

// The bundled moving_playbots.json: its second model moves while each camera's shutter is open (view 0
// still, view 1 panning, view 2 a rolling shutter).
TEST(CliRender, ASceneFilesMovingModelsBlurUnderItsCamerasShutter) {
  const auto out = fresh_output_dir();
  const fs::path moving = tilesplat::testing::bundled_scene_dir() / "moving_playbots.json";
  // The same scene with nothing moving: the file with its "motion" left out, the model path made absolute.
  std::string text = tilesplat::testing::read_file(moving);
  const std::string motion = R"(, "motion": {"translation": [0.75, 0, 0.55], "rotation_deg": [0, -30, 0]})";
  ASSERT_NE(text.find(motion), std::string::npos);
  text.replace(text.find(motion), motion.size(), "");
  const std::string ply = (tilesplat::testing::bundled_scene_dir() / "playbot_lod3").string() + "/";
  for (size_t at = text.find("playbot_lod3/"); at != std::string::npos;
       at = text.find("playbot_lod3/", at + ply.size()))
    text.replace(at, std::string("playbot_lod3/").size(), ply);
  const fs::path still_file = out / "still_models.json";
  std::ofstream(still_file, std::ios::binary) << text;
  auto render = [&](const fs::path& scene, const std::vector<std::string>& extra, const std::string& name) {
    std::vector<std::string> args = {scene.string(), "--width", "160", "-o", (out / name).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_exe(kRenderExe, args);
  };
  const auto blurred = render(moving, {"--view", "0"}, "blurred.exr");
  ASSERT_EQ(blurred.exit_code, 0) << blurred.err;
  EXPECT_TRUE(contains(blurred.err, "2 placed copies of 1 file")) << blurred.err;
  ASSERT_EQ(render(still_file, {"--view", "0"}, "still.exr").exit_code, 0);
  const std::string recorded =
      tilesplat::read_exr_string_attributes(out / "blurred.exr").at("renderSettings");
  EXPECT_TRUE(contains(recorded, "shutter=open:0,close:1,samples:24,scan:global,camera:still")) << recorded;
  const tilesplat::RenderImage a = tilesplat::read_exr(out / "blurred.exr");
  const tilesplat::RenderImage b = tilesplat::read_exr(out / "still.exr");
  const tilesplat::ImageDifference difference = tilesplat::compare_images(a, b);
  EXPECT_LT(difference.psnr_db, 35.0);  // the moving model is smeared
  EXPECT_GT(difference.psnr_db, 12.0);  // and the other one is where it was

  // A sequence of its views records that each has its own shutter.
  fs::create_directories(out / "views");
  const auto views = run_exe(kRenderExe, {moving.string(), "--views", "1,2", "--width", "96", "-o",
                                          (out / "views" / "frame_%04d.exr").string(), "--quiet"});
  ASSERT_EQ(views.exit_code, 0) << views.err;
  EXPECT_TRUE(
      contains(tilesplat::read_exr_string_attributes(out / "views" / "frame_0002.exr").at("renderSettings"),
               "shutter=the scene file's, per view"));
  // The float64 reference makes the same frame its own way.
  const auto reference = render(moving, {"--view", "0", "--width", "64", "--reference"}, "reference.exr");
  ASSERT_EQ(reference.exit_code, 0) << reference.err;
  ASSERT_EQ(render(moving, {"--view", "0", "--width", "64"}, "gpu.exr").exit_code, 0);
  EXPECT_GE(tilesplat::compare_images(tilesplat::read_exr(out / "reference.exr"),
                                      tilesplat::read_exr(out / "gpu.exr"))
                .psnr_db,
            60.0);
}

TEST(CliRender, RendersSceneFileToExr) {
  const auto out = fresh_output_dir();
  const fs::path scene_file = write_scene_file();
  const fs::path exr = out / "scene.exr";
  const auto result = run_exe(kRenderExe, {scene_file.string(), "-o", exr.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(contains(result.err, "view 0 (front) of scene.json")) << result.err;
  EXPECT_TRUE(contains(result.err, "31,064 Gaussians (SH3)")) << result.err;
  EXPECT_FALSE(contains(result.err, "validation messages")) << result.err;

  // The same scene, camera and settings through the library: the app must have used them all.
  const tilesplat::SceneDescription description = tilesplat::load_scene_description(scene_file);
  tilesplat::RenderSettings settings;
  settings.background = {0, 0, 1};
  settings.splat_count = false;
  tilesplat::Renderer& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(tilesplat::load_described_scene(description));
  const tilesplat::RenderImage expected = renderer.render(description.cameras[0].camera, settings);

  const tilesplat::RenderImage image = tilesplat::read_exr(exr);
  ASSERT_EQ(image.width, 64);
  ASSERT_EQ(image.height, 36);
  EXPECT_EQ(image.depth.size(), image.pixels());  // "depth" is listed
  EXPECT_TRUE(image.splat_count.empty());         // "splat_count" is not
  // Scene-linear in the file, encoded back by read_exr: equal to float rounding.
  EXPECT_LE(tilesplat::compare_images(image, expected).max_abs, 1e-6);
  // "alpha" is not listed: the EXR has no A channel, which reads back as opaque everywhere, even
  // where the render saw only background.
  bool background_seen = false;
  for (size_t i = 0; i < image.pixels(); ++i) {
    EXPECT_EQ(image.rgba[4 * i + 3], 1.0f);
    background_seen = background_seen || expected.rgba[4 * i + 3] == 0.0f;
  }
  EXPECT_TRUE(background_seen);
  EXPECT_EQ(image.rgba[2], 1.0f);  // the top-left corner shows the scene file's blue background

  // --view picks the file's second camera; --background overrides the file's.
  const fs::path side = out / "side.exr";
  const auto side_result =
      run_exe(kRenderExe, {scene_file.string(), "--view", "1", "--background", "0,0,0", "-o", side.string()});
  ASSERT_EQ(side_result.exit_code, 0) << side_result.err;
  EXPECT_TRUE(contains(side_result.err, "view 1 (side) of scene.json")) << side_result.err;
  EXPECT_EQ(tilesplat::read_exr(side).rgba[2], 0.0f);
}

TEST(CliRender, SceneFileLightsRelight) {
  const auto out = fresh_output_dir();
  const fs::path scene_file = write_scene_file(
      R"({"lights": [{"type": "directional", "direction": [0, 1, 0.5], "color": [1, 0.9, 0.8], "intensity": 2},
                     {"type": "point", "position": [0.5, -1, 1.5], "intensity": 3}],
          "ambient": [0.1, 0.1, 0.2]})");
  const fs::path exr = out / "lit.exr";
  const auto result = run_exe(kRenderExe, {scene_file.string(), "-o", exr.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_FALSE(contains(result.err, "validation messages")) << result.err;

  // The library with the file's lights, written out here as tilesplat::Lighting: the app must have
  // mapped every field (directions normalised by the reader, which the renderer does too).
  const tilesplat::SceneDescription description = tilesplat::load_scene_description(scene_file);
  tilesplat::RenderSettings settings;
  settings.background = {0, 0, 1};
  settings.splat_count = false;
  tilesplat::Light sun;
  sun.direction = {0, float(1 / std::sqrt(1.25)), float(0.5 / std::sqrt(1.25))};
  sun.color = {1, 0.9f, 0.8f};
  sun.intensity = 2;
  tilesplat::Light bulb;
  bulb.type = tilesplat::Light::Type::kPoint;
  bulb.position = {0.5f, -1, 1.5f};
  bulb.intensity = 3;
  settings.lighting.lights = {sun, bulb};
  settings.lighting.ambient = {0.1f, 0.1f, 0.2f};
  tilesplat::Renderer& renderer = tilesplat::testing::validated_renderer();
  renderer.set_scene(tilesplat::load_described_scene(description));
  const tilesplat::RenderImage expected = renderer.render(description.cameras[0].camera, settings);
  EXPECT_LE(tilesplat::compare_images(tilesplat::read_exr(exr), expected).max_abs, 1e-6);
  settings.lighting = {};
  const tilesplat::RenderImage unlit = renderer.render(description.cameras[0].camera, settings);
  EXPECT_GT(tilesplat::compare_images(unlit, expected).max_abs, 0.05);  // the lights changed the image
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(CliRender, SceneFileAntialiasingModeApplies) {
  const auto out = fresh_output_dir();
  const fs::path classic = write_scene_file(R"({"antialiasing": "classic"})");
  ASSERT_EQ(run_exe(kRenderExe, {classic.string(), "-o", (out / "classic.exr").string()}).exit_code, 0);
  const fs::path mip = write_scene_file(R"({"antialiasing": "mip"})");
  const auto mip_result = run_exe(kRenderExe, {mip.string(), "-o", (out / "mip.exr").string()});
  ASSERT_EQ(mip_result.exit_code, 0) << mip_result.err;
  // Mip-Splatting's filter changes the image (dilation 0.1 and opacity compensation).
  EXPECT_NE(tilesplat::read_exr(out / "classic.exr").rgba, tilesplat::read_exr(out / "mip.exr").rgba);
}

TEST(CliRender, SceneFileExposureAndToneMapShapeThePngOnly) {
  const auto out = fresh_output_dir();
  const fs::path plain = write_scene_file();
  ASSERT_EQ(run_exe(kRenderExe, {plain.string(), "-o", (out / "plain.exr").string(), "--png",
                                 (out / "plain.png").string()})
                .exit_code,
            0);
  const fs::path graded = write_scene_file(R"({"exposure": 2, "tone_map": "aces"})");
  const auto graded_result = run_exe(
      kRenderExe, {graded.string(), "-o", (out / "graded.exr").string(), "--png", (out / "graded.png").string()});
  ASSERT_EQ(graded_result.exit_code, 0) << graded_result.err;
  // The flags say the same as the scene file, so the preview is byte-identical.
  const auto flags_result =
      run_exe(kRenderExe, {plain.string(), "-o", (out / "flags.exr").string(), "--png", (out / "flags.png").string(),
                           "--exposure", "2", "--tone-map", "aces"});
  ASSERT_EQ(flags_result.exit_code, 0) << flags_result.err;
  // The EXR is never graded; only the preview is.
  EXPECT_EQ(tilesplat::read_exr(out / "plain.exr").rgba, tilesplat::read_exr(out / "graded.exr").rgba);
  EXPECT_NE(read_file(out / "plain.png"), read_file(out / "graded.png"));
  EXPECT_EQ(read_file(out / "graded.png"), read_file(out / "flags.png"));
  // A flag overrides the scene file: back to no grading.
  ASSERT_EQ(run_exe(kRenderExe, {graded.string(), "-o", (out / "undone.exr").string(), "--png",
                                 (out / "undone.png").string(), "--exposure", "0", "--tone-map", "none"})
                .exit_code,
            0);
  EXPECT_EQ(read_file(out / "plain.png"), read_file(out / "undone.png"));

  const auto bad_curve = run_exe(kRenderExe, {plain.string(), "-o", (out / "x.exr").string(), "--png",
                                              (out / "x.png").string(), "--tone-map", "filmic"});
  EXPECT_EQ(bad_curve.exit_code, 2) << bad_curve.err;
  EXPECT_TRUE(contains(bad_curve.err, "--tone-map must be none, aces or reinhard, got 'filmic'")) << bad_curve.err;
  const auto no_png = run_exe(kRenderExe, {plain.string(), "-o", (out / "x.exr").string(), "--tone-map", "aces"});
  EXPECT_EQ(no_png.exit_code, 2) << no_png.err;
  EXPECT_TRUE(contains(no_png.err, "--tone-map applies to the --png preview")) << no_png.err;
  EXPECT_FALSE(fs::exists(out / "x.exr"));
}

TEST(CliRender, SceneFileMistakesAndViews) {
  const auto out = fresh_output_dir();
  const fs::path exr = out / "x.exr";
  const fs::path typo = write_scene_file(R"({"antialias": "classic"})");
  const auto typo_result = run_exe(kRenderExe, {typo.string(), "-o", exr.string()});
  EXPECT_EQ(typo_result.exit_code, 1) << typo_result.err;
  EXPECT_TRUE(contains(typo_result.err, "scene.json: effects.antialias: unknown key; did you mean 'antialiasing'?"))
      << typo_result.err;
  expect_one_error_line(typo_result, "tilesplat-render");

  const fs::path scene_file = write_scene_file();
  const auto out_of_range = run_exe(kRenderExe, {scene_file.string(), "--view", "2", "-o", exr.string()});
  EXPECT_EQ(out_of_range.exit_code, 2) << out_of_range.err;
  EXPECT_TRUE(contains(out_of_range.err, "has 2 views")) << out_of_range.err;

  const auto orbit = run_exe(kRenderExe, {scene_file.string(), "--azimuth", "30", "-o", exr.string()});
  EXPECT_EQ(orbit.exit_code, 2) << orbit.err;
  EXPECT_TRUE(contains(orbit.err, "has cameras of its own")) << orbit.err;

  const fs::path no_cameras = temp_dir() / "no_cameras.json";
  std::ofstream(no_cameras, std::ios::trunc) << R"({"models": [{"path": ")" << bundled_sh3().string() << R"("}]})";
  const auto no_views = run_exe(kRenderExe, {no_cameras.string(), "--view", "0", "-o", exr.string()});
  EXPECT_EQ(no_views.exit_code, 2) << no_views.err;
  EXPECT_TRUE(contains(no_views.err, "--view needs cameras")) << no_views.err;
  EXPECT_TRUE(entries(out).empty());
}

TEST(CliBench, MeasuresSceneFileAtItsOwnCameras) {
  const auto out = fresh_output_dir();
  const fs::path json = out / "j.json";
  const fs::path scene_file = write_scene_file();
  const auto result = run_exe(kBenchExe, {scene_file.string(), "--views", "all", "--sort", "radix", "--warmup", "0",
                                          "--repeat", "1", "--json", json.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(contains(result.err, "2 frames")) << result.err;
  const std::string json_text = read_file(json);
  EXPECT_TRUE(contains(json_text, "\"cameras\": \"" + scene_file.string() + "\"")) << json_text;
  EXPECT_TRUE(contains(json_text, "\"sh_degree\": 3")) << json_text;
}

TEST(CliRender, ListsDevices) {
  const auto result = run_exe(kRenderExe, {"--list-devices"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(contains(result.out, "0: ")) << result.out;
}

}  // namespace
