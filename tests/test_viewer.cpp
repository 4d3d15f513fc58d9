// Runs tilesplat-viewer as a process, in a window on the session's display or, without one, on a
// private Xvfb server (xvfb-run): its screenshot is tilesplat-render's image of the same view, the
// validation layer stays silent, and bad input fails with one line and writes nothing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "process_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/lod_set.h"
#include "tilesplat/renderer.h"

namespace {

namespace fs = std::filesystem;
using tilesplat::testing::bundled_playbot;
using tilesplat::testing::bundled_playbot_cameras;
using tilesplat::testing::bundled_sh3;
using tilesplat::testing::bundled_sh3_cameras;
using tilesplat::testing::DecodedPng;
using tilesplat::testing::display_prefix;
using tilesplat::testing::fresh_output_dir;
using tilesplat::testing::kNoDisplay;
using tilesplat::testing::line_count;
using tilesplat::testing::ProcessResult;
using tilesplat::testing::run_process;
using tilesplat::testing::temp_dir;

#ifdef TILESPLAT_VIEWER_EXE
constexpr const char* kViewerExe = TILESPLAT_VIEWER_EXE;
#define REQUIRE_VIEWER() (void)0
#else
constexpr const char* kViewerExe = "";
#define REQUIRE_VIEWER() \
  TILESPLAT_SKIP_OR_FAIL("tilesplat-viewer is not built (configure with -DTILESPLAT_BUILD_VIEWER=ON)")
#endif
constexpr const char* kRenderExe = TILESPLAT_RENDER_EXE;

std::vector<std::string> view_args(const fs::path& scene, const fs::path& cameras, int view) {
  return {scene.string(), "--cameras", cameras.string(), "--view", std::to_string(view), "--width", "320",
          "--height", "180"};
}

// The bundled playbot as a LOD set of 3 levels (tests/data/playbot_lod_set).
fs::path playbot_lod_set() {
  return fs::path(TILESPLAT_SOURCE_DIR) / "tests" / "data" / "playbot_lod_set" / "lod-meta.json";
}

void expect_one_error_line(const ProcessResult& result) {
  tilesplat::testing::expect_one_error_line(result, "tilesplat-viewer");
}

TEST(Viewer, ScreenshotIsTheRenderOfTheSameView) {
  REQUIRE_VIEWER();
  const std::optional<std::string> prefix = display_prefix();
  if (!prefix) TILESPLAT_SKIP_OR_FAIL(kNoDisplay);
  const fs::path out = fresh_output_dir();
  std::vector<std::string> viewer_args = view_args(bundled_playbot(), bundled_playbot_cameras(), 2);
  std::vector<std::string> render_args = viewer_args;
  viewer_args.insert(viewer_args.end(), {"--frames", "3", "--screenshot", (out / "viewer.exr").string()});
  render_args.insert(render_args.end(), {"-o", (out / "render.exr").string()});

  const ProcessResult viewer = run_process(*prefix, kViewerExe, viewer_args);
  ASSERT_EQ(viewer.exit_code, 0) << viewer.err;
  EXPECT_NE(viewer.err.find("3 frames"), std::string::npos) << viewer.err;
  const ProcessResult render = run_process("", kRenderExe, render_args);
  ASSERT_EQ(render.exit_code, 0) << render.err;

  const tilesplat::RenderImage shown = tilesplat::read_exr(out / "viewer.exr");
  const tilesplat::RenderImage rendered = tilesplat::read_exr(out / "render.exr");
  ASSERT_EQ(shown.width, 320);
  ASSERT_EQ(shown.height, 180);
  const tilesplat::ImageDifference difference = tilesplat::compare_images(shown, rendered);
  EXPECT_GE(difference.psnr_db, 100.0) << "max abs " << difference.max_abs;
  EXPECT_LE(difference.max_abs_alpha, 1e-6);
  EXPECT_EQ(shown.depth.size(), rendered.depth.size());
  EXPECT_EQ(shown.splat_count, rendered.splat_count);
}

// The viewer's screenshot of `scene` under a splat budget against tilesplat-render's frame of the same view:
// the same choice for the same camera, the same image. `said` are phrases the viewer's summary must hold.
void expect_budgeted_view_as_rendered(const fs::path& scene, const fs::path& cameras, int view, const char* budget,
                                      std::initializer_list<const char*> said) {
  const std::optional<std::string> prefix = display_prefix();
  if (!prefix) TILESPLAT_SKIP_OR_FAIL(kNoDisplay);
  const fs::path out = fresh_output_dir();
  std::vector<std::string> viewer_args = view_args(scene, cameras, view);
  viewer_args.insert(viewer_args.end(), {"--splat-budget", budget});
  std::vector<std::string> render_args = viewer_args;
  viewer_args.insert(viewer_args.end(),
                     {"--validation", "--frames", "2", "--screenshot", (out / "viewer.exr").string()});
  render_args.insert(render_args.end(), {"-o", (out / "render.exr").string()});

  const ProcessResult viewer = run_process(*prefix, kViewerExe, viewer_args);
  ASSERT_EQ(viewer.exit_code, 0) << viewer.err;
  for (const char* phrase : said) EXPECT_NE(viewer.err.find(phrase), std::string::npos) << phrase << "\n" << viewer.err;
  EXPECT_NE(viewer.err.find("validation: 0 messages"), std::string::npos) << viewer.err;
  const ProcessResult render = run_process("", kRenderExe, render_args);
  ASSERT_EQ(render.exit_code, 0) << render.err;
  const tilesplat::ImageDifference difference = tilesplat::compare_images(
      tilesplat::read_exr(out / "viewer.exr"), tilesplat::read_exr(out / "render.exr"));
  EXPECT_GE(difference.psnr_db, 100.0) << "max abs " << difference.max_abs;
}

// A LOD set under a splat budget: the viewer chooses the levels for its camera as tilesplat-render does
// for the same view, and says how many Gaussians it draws.
TEST(Viewer, ASplatBudgetDrawsWhatTheRendererDraws) {
  REQUIRE_VIEWER();
  expect_budgeted_view_as_rendered(playbot_lod_set(), bundled_playbot_cameras(), 2, "6000", {"at most 6,000 a frame"});
}

// A .rad LOD tree under a splat budget: the viewer draws the cut tilesplat-render draws for the same view.
TEST(Viewer, ARadTreeUnderABudgetDrawsWhatTheRendererDraws) {
  REQUIRE_VIEWER();
  expect_budgeted_view_as_rendered(
      fs::path(TILESPLAT_SOURCE_DIR) / "tests" / "data" / "rad" / "playcanvas_test_64_sh3-lod.rad",
      tilesplat::testing::bundled_sh3_cameras(), 0, "20", {"LOD tree of 90 splats", "tree cuts decoded"});
}

// --turn moves the camera every frame: under a splat budget the levels each camera calls for are read on
// the streamer's thread while frames go on, and the EXR screenshot (its camera recorded in the file) is the
// renderer's frame of the last camera's levels.
TEST(Viewer, ATurningCameraStreamsTheLevelsItCallsFor) {
  REQUIRE_VIEWER();
  const std::optional<std::string> prefix = display_prefix();
  if (!prefix) TILESPLAT_SKIP_OR_FAIL(kNoDisplay);
  const fs::path out = fresh_output_dir();
  const fs::path lod_set = playbot_lod_set();
  std::vector<std::string> viewer_args = view_args(lod_set, bundled_playbot_cameras(), 2);
  viewer_args.insert(viewer_args.end(), {"--splat-budget", "6000", "--turn", "20", "--frames", "10",
                                         "--validation", "--screenshot", (out / "viewer.exr").string()});
  const ProcessResult viewer = run_process(*prefix, kViewerExe, viewer_args);
  ASSERT_EQ(viewer.exit_code, 0) << viewer.err;
  EXPECT_NE(viewer.err.find("validation: 0 messages"), std::string::npos) << viewer.err;
  const size_t reads_at = viewer.err.find("levels read ");
  ASSERT_NE(reads_at, std::string::npos) << viewer.err;
  EXPECT_GE(std::stoi(viewer.err.substr(reads_at + 12)), 3) << "half a turn should change the levels";

  const std::optional<tilesplat::Camera> camera = tilesplat::read_exr_camera(out / "viewer.exr");
  ASSERT_TRUE(camera);
  const tilesplat::Camera start = tilesplat::load_cameras_json(bundled_playbot_cameras()).at(2).camera;
  EXPECT_GT(
      std::abs(camera->position[0] - start.position[0]) + std::abs(camera->position[2] - start.position[2]),
      0.5)
      << "the camera did not turn";
  const tilesplat::LodSet set = tilesplat::LodSet::open(lod_set);
  tilesplat::RenderSettings settings;
  settings.splat_budget = 6000;
  const tilesplat::RenderImage rendered = tilesplat::Renderer::create()->render(set, *camera, settings);
  const tilesplat::ImageDifference difference =
      tilesplat::compare_images(tilesplat::read_exr(out / "viewer.exr"), rendered);
  EXPECT_GE(difference.psnr_db, 100.0) << "max abs " << difference.max_abs;
}

// Radial sorting measures from the camera's centre: through --orthographic (no centre) it is a usage error
// before any window, naming both flags.
TEST(Viewer, RadialSortingRefusesTheOrthographicLens) {
  REQUIRE_VIEWER();
  std::vector<std::string> args = view_args(bundled_playbot(), bundled_playbot_cameras(), 2);
  args.insert(args.end(), {"--orthographic", "3", "--no-mesh", "--mode", "radial"});
  const ProcessResult radial = run_process("env -u DISPLAY ", kViewerExe, args);
  EXPECT_EQ(radial.exit_code, 2) << radial.err;
  EXPECT_NE(radial.err.find("radial sorting (--mode radial) measures from the camera's centre, which "
                            "--orthographic does not have"),
            std::string::npos)
      << radial.err;
}

// --fisheye, --equirectangular (and key L's cycle) show the splats through another lens: the screenshot
// is tilesplat-render's frame through the same lens. They need --no-mesh (the box and the grid are drawn
// through a pinhole), and per-pixel re-sorting needs the pinhole: usage errors before any window.
TEST(Viewer, AnotherLensShowsWhatTheRendererDrawsThroughIt) {
  REQUIRE_VIEWER();
  const fs::path out = fresh_output_dir();
  std::vector<std::string> mesh_args = view_args(bundled_playbot(), bundled_playbot_cameras(), 2);
  mesh_args.insert(mesh_args.end(), {"--fisheye", "200"});
  const ProcessResult with_mesh = run_process("env -u DISPLAY ", kViewerExe, mesh_args);
  EXPECT_EQ(with_mesh.exit_code, 2) << with_mesh.err;
  EXPECT_NE(with_mesh.err.find("add --no-mesh"), std::string::npos) << with_mesh.err;
  mesh_args.insert(mesh_args.end(), {"--no-mesh", "--mode", "resort4"});
  const ProcessResult resort = run_process("env -u DISPLAY ", kViewerExe, mesh_args);
  EXPECT_EQ(resort.exit_code, 2) << resort.err;
  EXPECT_NE(resort.err.find("needs the pinhole camera"), std::string::npos) << resort.err;

  const std::optional<std::string> prefix = display_prefix();
  if (!prefix) TILESPLAT_SKIP_OR_FAIL(kNoDisplay);
  for (const std::vector<std::string>& lens :
       {std::vector<std::string>{"--fisheye", "200"}, std::vector<std::string>{"--equirectangular"}}) {
    std::vector<std::string> viewer_args = view_args(bundled_playbot(), bundled_playbot_cameras(), 2);
    viewer_args.insert(viewer_args.end(), lens.begin(), lens.end());
    std::vector<std::string> render_args = viewer_args;
    viewer_args.insert(viewer_args.end(), {"--no-mesh", "--validation", "--frames", "2", "--screenshot",
                                           (out / "viewer.exr").string()});
    render_args.insert(render_args.end(), {"-o", (out / "render.exr").string()});
    const ProcessResult viewer = run_process(*prefix, kViewerExe, viewer_args);
    ASSERT_EQ(viewer.exit_code, 0) << viewer.err;
    EXPECT_NE(viewer.err.find("validation: 0 messages"), std::string::npos) << viewer.err;
    const ProcessResult render = run_process("", kRenderExe, render_args);
    ASSERT_EQ(render.exit_code, 0) << render.err;
    const tilesplat::ImageDifference difference = tilesplat::compare_images(
        tilesplat::read_exr(out / "viewer.exr"), tilesplat::read_exr(out / "render.exr"));
    EXPECT_GE(difference.psnr_db, 100.0) << lens.front() << ": max abs " << difference.max_abs;
  }
}

// The window shows the trained colours as a PNG preview holds them (docs/colour.md): the bytes of the
// window's image equal tilesplat-render's --png of the same view within one level (the blit's float to
// 8-bit rounding against the preview's). Both kinds of window format: a _UNORM one, which the viewer
// prefers, and an _SRGB one (TILESPLAT_VIEWER_SWAPCHAIN=srgb), which would encode the colours a second
// time if the viewer blitted into it directly.
TEST(Viewer, WindowPixelsAreThePngPreviewOfTheSameView) {
  REQUIRE_VIEWER();
  const std::optional<std::string> prefix = display_prefix();
  if (!prefix) TILESPLAT_SKIP_OR_FAIL(kNoDisplay);
  const fs::path out = fresh_output_dir();
  std::vector<std::string> render_args = view_args(bundled_playbot(), bundled_playbot_cameras(), 2);
  render_args.insert(render_args.end(),
                     {"-o", (out / "render.exr").string(), "--png", (out / "render.png").string()});
  const ProcessResult render = run_process("", kRenderExe, render_args);
  ASSERT_EQ(render.exit_code, 0) << render.err;
  const DecodedPng preview = tilesplat::testing::read_png_rgb(out / "render.png");

  for (const std::string kind : {"unorm", "srgb"}) {
    std::vector<std::string> viewer_args = view_args(bundled_playbot(), bundled_playbot_cameras(), 2);
    const fs::path shot = out / ("window_" + kind + ".png");
    viewer_args.insert(viewer_args.end(),
                       {"--no-mesh", "--validation", "--frames", "2", "--screenshot", shot.string()});
    const ProcessResult viewer =
        run_process("env TILESPLAT_VIEWER_SWAPCHAIN=" + kind + " " + *prefix, kViewerExe, viewer_args);
    ASSERT_EQ(viewer.exit_code, 0) << viewer.err;
    EXPECT_NE(viewer.err.find("validation: 0 messages"), std::string::npos) << viewer.err;
    EXPECT_NE(viewer.err.find(kind == "srgb" ? "_SRGB window" : "_UNORM window"), std::string::npos)
        << viewer.err;
    const DecodedPng window = tilesplat::testing::read_png_rgb(shot);
    ASSERT_EQ(window.width, preview.width);
    ASSERT_EQ(window.height, preview.height);
    ASSERT_EQ(window.rgb.size(), preview.rgb.size());
    size_t differ = 0, lit = 0;
    int worst = 0;
    for (size_t i = 0; i < window.rgb.size(); ++i) {
      const int difference = std::abs(int(window.rgb[i]) - int(preview.rgb[i]));
      worst = std::max(worst, difference);
      differ += difference > 0;
      lit += preview.rgb[i] > 32;
    }
    std::printf("[ measure  ] %s window: %zu of %zu values differ from the preview, by at most %d\n",
                kind.c_str(), differ, window.rgb.size(), worst);
    EXPECT_LE(worst, 1) << kind;
    EXPECT_GT(lit, window.rgb.size() / 10) << "the view should show the scene";
  }
}

// Every mode and sort path the keys reach goes through the same frame code; this one takes a
// non-default one of each and a PNG screenshot.
TEST(Viewer, ValidationLayerStaysSilent) {
  REQUIRE_VIEWER();
  const std::optional<std::string> prefix = display_prefix();
  if (!prefix) TILESPLAT_SKIP_OR_FAIL(kNoDisplay);
  const fs::path out = fresh_output_dir();
  std::vector<std::string> args = view_args(bundled_sh3(), bundled_sh3_cameras(), 1);
  args.insert(args.end(), {"--validation", "--mode", "depth16", "--sort", "onesweep", "--frames", "2", "--screenshot",
                           (out / "shot.png").string()});
  const ProcessResult result = run_process(*prefix, kViewerExe, args);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.err.find("validation: 0 messages"), std::string::npos) << result.err;
  EXPECT_EQ(result.err.find("vulkan validation"), std::string::npos) << result.err;
  EXPECT_EQ(line_count(result.err), 1u) << result.err;
  std::ifstream png(out / "shot.png", std::ios::binary);
  std::string signature(8, '\0');
  png.read(signature.data(), 8);
  EXPECT_EQ(signature, "\x89PNG\r\n\x1a\n");
}

// The viewer's own mesh, drawn as a host application's would be: the box drawn before the splats hides
// what lies behind it, and the ground grid drawn after is hidden behind the splats' depth where they are
// dense (drawn over them with --no-depth-out); in a mode that cannot depth-test, the splats show alone.
// Counted on the pixels of PNG screenshots of the window,
// where the box's faces and the grid have colours of their own.
TEST(Viewer, BoxHidesSplatsAndSplatsHideTheGrid) {
  REQUIRE_VIEWER();
  const std::optional<std::string> prefix = display_prefix();
  if (!prefix) TILESPLAT_SKIP_OR_FAIL(kNoDisplay);
  const fs::path out = fresh_output_dir();
  auto screenshot = [&](const std::string& name, const std::vector<std::string>& flags) {
    std::vector<std::string> args = view_args(bundled_playbot(), bundled_playbot_cameras(), 2);
    args.insert(args.end(), flags.begin(), flags.end());
    args.insert(args.end(), {"--validation", "--frames", "2", "--screenshot", (out / name).string()});
    const ProcessResult result = run_process(*prefix, kViewerExe, args);
    EXPECT_EQ(result.exit_code, 0) << result.err;
    EXPECT_NE(result.err.find("validation: 0 messages"), std::string::npos) << result.err;
    return tilesplat::testing::read_png_rgb(out / name);
  };
  const DecodedPng mesh = screenshot("mesh.png", {});
  const DecodedPng no_depth_out = screenshot("no_depth_out.png", {"--no-depth-out"});
  const DecodedPng splats_only = screenshot("splats_only.png", {"--no-mesh"});
  // Per-pixel re-sorting cannot depth-test against a host's surfaces: the viewer shows the splats alone.
  const DecodedPng resorted = screenshot("resorted.png", {"--mode", "resort8"});
  ASSERT_EQ(mesh.width, 320u);
  ASSERT_EQ(mesh.height, 180u);

  // The colours viewer/mesh_layer.cpp draws with (linear light), sRGB-encoded by its fragment shader, as
  // the window and so the PNG hold them (+-1 for the half-float picture's rounding).
  auto srgb_byte = [](double c) {
    const double encoded = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055;
    return int(std::lround(255 * encoded));
  };
  const double box_faces[6][3] = {{0.80, 0.30, 0.08}, {0.70, 0.25, 0.06}, {0.90, 0.45, 0.10},
                                  {0.55, 0.20, 0.05}, {0.85, 0.38, 0.09}, {0.62, 0.22, 0.05}};
  std::vector<std::array<int, 3>> box_colours;
  for (const auto& face : box_faces)
    box_colours.push_back({srgb_byte(face[0]), srgb_byte(face[1]), srgb_byte(face[2])});
  auto is = [](const uint8_t* pixel, const std::array<int, 3>& colour) {
    for (int c = 0; c < 3; ++c)
      if (std::abs(int(pixel[c]) - colour[size_t(c)]) > 1) return false;
    return true;
  };
  auto count = [&](const DecodedPng& png, auto&& matches) {
    size_t n = 0;
    for (size_t i = 0; i + 2 < png.rgb.size(); i += 3) n += matches(&png.rgb[i]) ? 1u : 0u;
    return n;
  };
  auto box = [&](const uint8_t* p) {
    return std::any_of(box_colours.begin(), box_colours.end(), [&](const auto& c) { return is(p, c); });
  };
  auto grid = [&](const uint8_t* p) { return is(p, {0, 255, 255}); };

  const size_t pixels = size_t(mesh.width) * mesh.height;
  const size_t box_pixels = count(mesh, box), grid_pixels = count(mesh, grid);
  const size_t grid_over_splats = count(no_depth_out, grid);
  std::printf(
      "box %zu of %zu pixels (splats alone: %zu); grid %zu, drawn over the splats %zu (splats alone: %zu)\n",
      box_pixels, pixels, count(splats_only, box), grid_pixels, grid_over_splats, count(splats_only, grid));
  EXPECT_GT(box_pixels, pixels / 20) << "the box should cover a good part of the view";
  EXPECT_LT(count(splats_only, box), box_pixels / 50) << "the splats alone have the box's colours";
  EXPECT_GT(grid_pixels, pixels / 200) << "the grid should show where no splat covers it";
  EXPECT_GT(grid_over_splats, grid_pixels + grid_pixels / 10)
      << "the splats' depth should hide part of the grid";
  EXPECT_EQ(count(splats_only, grid), 0u);
  EXPECT_LT(count(resorted, box), box_pixels / 50);
  EXPECT_EQ(count(resorted, grid), 0u);
  // Where the box is drawn, the splats behind it left nothing: the same pixels show the box with and
  // without the splats' depth out.
  size_t box_differs = 0;
  for (size_t i = 0; i < mesh.rgb.size(); i += 3)
    if (box(&mesh.rgb[i]) && !box(&no_depth_out.rgb[i]) && !grid(&no_depth_out.rgb[i])) ++box_differs;
  EXPECT_EQ(box_differs, 0u);
}

// These fail before a window opens, so they need no display.
TEST(Viewer, BadInputFailsWithOneLineAndWritesNothing) {
  REQUIRE_VIEWER();
  const fs::path out = fresh_output_dir();
  const std::string shot = (out / "shot.exr").string();
  const fs::path missing = temp_dir() / "no_such_scene.ply";
  fs::remove(missing);

  const ProcessResult no_scene = run_process("", kViewerExe, {missing.string(), "--frames", "1", "--screenshot", shot});
  EXPECT_EQ(no_scene.exit_code, 1) << no_scene.err;  // a runtime error, as tilesplat-render's
  EXPECT_NE(no_scene.err.find("no_such_scene.ply"), std::string::npos) << no_scene.err;
  expect_one_error_line(no_scene);

  const ProcessResult bad_flag = run_process("", kViewerExe, {bundled_sh3().string(), "--frobnicate", "--screenshot", shot});
  EXPECT_EQ(bad_flag.exit_code, 2) << bad_flag.err;
  EXPECT_NE(bad_flag.err.find("--frobnicate"), std::string::npos) << bad_flag.err;
  expect_one_error_line(bad_flag);

  const ProcessResult no_frames = run_process("", kViewerExe, {bundled_sh3().string(), "--frames", "0"});
  EXPECT_EQ(no_frames.exit_code, 2) << no_frames.err;
  expect_one_error_line(no_frames);

  for (const char* turn : {"181", "nan", "ten"}) {
    const ProcessResult bad_turn =
        run_process("", kViewerExe, {bundled_sh3().string(), "--turn", turn, "--screenshot", shot});
    EXPECT_EQ(bad_turn.exit_code, 2) << bad_turn.err;
    EXPECT_NE(bad_turn.err.find("--turn"), std::string::npos) << bad_turn.err;
    expect_one_error_line(bad_turn);
  }

  const std::string jpg = (out / "x.jpg").string();
  const ProcessResult bad_shot = run_process("", kViewerExe, {bundled_sh3().string(), "--screenshot", jpg});
  EXPECT_EQ(bad_shot.exit_code, 2) << bad_shot.err;
  expect_one_error_line(bad_shot);

  EXPECT_TRUE(fs::is_empty(out));
}

TEST(Viewer, NoDisplayFailsWithOneLine) {
  REQUIRE_VIEWER();
  const fs::path out = fresh_output_dir();
  const ProcessResult result = run_process("env -u DISPLAY -u WAYLAND_DISPLAY ", kViewerExe,
                                   {bundled_sh3().string(), "--frames", "1", "--screenshot",
                                    (out / "shot.exr").string()});
  EXPECT_EQ(result.exit_code, 1) << result.err;
  EXPECT_NE(result.err.find("display"), std::string::npos) << result.err;
  expect_one_error_line(result);
  EXPECT_TRUE(fs::is_empty(out));
}

}  // namespace
