// The raster compositor (Compositor::kRaster): the depth-sorted splats drawn as quads through the
// graphics pipeline and blended by the hardware. It is held to its own definition in the float64
// reference (the raster rule: no tiles, no transmittance early-out), to the tile compositor within
// the early-out's difference, and to the same image whatever exact sort orders it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "process_support.h"
#include "test_support.h"
#include "tilesplat/camera.h"
#include "tilesplat/image.h"
#include "tilesplat/reference.h"
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

RenderSettings raster_settings() {
  RenderSettings settings;
  settings.compositor = Compositor::kRaster;
  return settings;
}

// Overlapping splats of every opacity in layers: many per pixel, and some pixels uncovered.
GaussianScene layered_scene() {
  GaussianScene scene;
  scene.sh_degree = 0;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  for (int i = 0; i < 4000; ++i) {
    const float x = 2.4f * unit(rng) - 1.2f, y = 1.8f * unit(rng) - 0.9f, z = 2.f + 2.f * unit(rng);
    scene.positions.insert(scene.positions.end(), {x, y, z});
    scene.log_scales.insert(scene.log_scales.end(),
                            {std::log(0.01f + 0.1f * unit(rng)), std::log(0.01f + 0.1f * unit(rng)), -3.f});
    const float angle = 3.14159f * unit(rng);
    scene.rotations.insert(scene.rotations.end(), {std::cos(angle), 0.f, 0.f, std::sin(angle)});
    scene.opacity_logits.push_back(8.f * unit(rng) - 3.f);
    scene.sh.insert(scene.sh.end(), {3.f * unit(rng) - 1.5f, 3.f * unit(rng) - 1.5f, 3.f * unit(rng) - 1.5f});
  }
  return scene;
}

Camera playbot_camera(int width, int height) {
  return resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(0).camera, width, height);
}

// The median of the image's depth output over the pixels the splats reach; 0 where they reach none.
double median_splat_depth(const RenderImage& image) {
  std::vector<float> depths;
  for (float z : image.depth)
    if (z > 0) depths.push_back(z);
  if (depths.empty()) return 0.0;
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  return depths[depths.size() / 2];
}

double depth_max_abs(const RenderImage& a, const RenderImage& b) {
  double worst = 0;
  for (size_t i = 0; i < a.depth.size(); ++i)
    worst = std::max(worst, double(std::abs(a.depth[i] - b.depth[i])));
  return worst;
}

struct CountDifference {
  size_t pixels = 0;     // whose counts differ
  uint32_t largest = 0;  // by at most this
};
CountDifference count_difference(const RenderImage& a, const RenderImage& b) {
  CountDifference d;
  for (size_t i = 0; i < a.splat_count.size(); ++i) {
    const uint32_t x = a.splat_count[i], y = b.splat_count[i];
    if (x == y) continue;
    ++d.pixels;
    d.largest = std::max(d.largest, x > y ? x - y : y - x);
  }
  return d;
}

TEST(Raster, MatchesTheReferenceRasterRule) {
  Renderer& renderer = testing::validated_renderer();
  struct Case {
    std::string name;
    GaussianScene scene;
    Camera camera;
  };
  std::vector<Case> cases;
  cases.push_back({"playbot", load_scene(testing::bundled_playbot()), playbot_camera(320, 180)});
  cases.push_back({"layered", layered_scene(), testing::axis_camera(256, 192, 220.0)});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    renderer.set_scene(c.scene);
    const RenderImage gpu = renderer.render(c.camera, raster_settings());
    const RenderImage reference = render_reference(c.scene, c.camera, raster_settings());
    const ImageDifference d = compare_images(gpu, reference);
    const CountDifference counts = count_difference(gpu, reference);
    std::printf(
        "%s: raster vs reference raster rule: %.2f dB, max abs %.3g (alpha %.3g), depth max abs %.3g, "
        "counts differ at %zu pixels (by <= %u)\n",
        c.name.c_str(), d.psnr_db, d.max_abs, d.max_abs_alpha, depth_max_abs(gpu, reference), counts.pixels,
        counts.largest);
    // Measured on Mesa 22's lavapipe: 139-141 dB, depth within 6e-6, counts off by one at 1-2 pixels
    // (a splat within float rounding of the alpha cut-off).
    EXPECT_GE(d.psnr_db, 60.0);
    EXPECT_LE(depth_max_abs(gpu, reference), 1e-3);
    EXPECT_LE(counts.pixels, gpu.pixels() / 1000);
    EXPECT_LE(counts.largest, 1u);
    // Against the tile compositor the difference is its early-out at T < 1e-4 and its tile rectangles
    // (3 sigma, where the raster reaches the alpha cut-off): 76-82 dB measured.
    const RenderImage tiles = renderer.render(c.camera, RenderSettings{});
    const ImageDifference t = compare_images(gpu, tiles);
    std::printf("%s: raster vs tile compositor: %.2f dB, max abs %.3g\n", c.name.c_str(), t.psnr_db,
                t.max_abs);
    EXPECT_GE(t.psnr_db, 65.0);
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// The wide cameras draw through the same quads: the fisheye's local Jacobians and the panorama's seam
// copies (two records per Gaussian) come from the projection, which the raster frame shares.
TEST(Raster, WideCamerasMatchTheReferenceRasterRule) {
  Renderer& renderer = testing::validated_renderer();
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  renderer.set_scene(scene);
  const Camera pinhole = playbot_camera(256, 144);
  Camera panorama = equirectangular_camera(pinhole);
  panorama.width = 256;
  panorama.height = 128;
  for (const Camera& camera : {fisheye_camera(pinhole, 200.0), panorama}) {
    SCOPED_TRACE(camera_model_name(camera.model));
    const RenderImage gpu = renderer.render(camera, raster_settings());
    const RenderImage reference = render_reference(scene, camera, raster_settings());
    const ImageDifference d = compare_images(gpu, reference);
    EXPECT_GE(d.psnr_db, 60.0);
    EXPECT_LE(count_difference(gpu, reference).pixels, gpu.pixels() / 1000);
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// Every exact strategy gives the one depth order, and the blend runs in draw order: the same image
// to the bit, whichever sorts (a strategy that sorts (tile, depth) pairs itself sorts depths here).
TEST(Raster, EveryExactSortDrawsTheSameImage) {
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(load_scene(testing::bundled_playbot()));
  const Camera camera = playbot_camera(240, 136);
  RenderSettings settings = raster_settings();
  settings.sort = "radix";
  const RenderImage expected = renderer.render(camera, settings);
  int strategies = 0;
  for (const std::string& sort : sort_strategies()) {
    if (!sort_strategy_is_exact(sort)) continue;
    settings.sort = sort;
    const RenderImage image = renderer.render(camera, settings);
    EXPECT_EQ(image.rgba, expected.rgba) << sort;
    EXPECT_EQ(image.depth, expected.depth) << sort;
    EXPECT_EQ(image.splat_count, expected.splat_count) << sort;
    EXPECT_EQ(renderer.last_frame_stats().passes.back().name, "raster_composite") << sort;
    ++strategies;
  }
  EXPECT_GE(strategies, 5);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// The training caps and the outputs: max_alpha as the reference draws it, depth and counts off leave
// the colour as it was, and a frame on reused lists re-draws the sorted splats under a new background.
TEST(Raster, SettingsOutputsAndReusedLists) {
  Renderer& renderer = testing::validated_renderer();
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  renderer.set_scene(scene);
  const Camera camera = playbot_camera(200, 112);
  RenderSettings gsplat = raster_settings();
  gsplat.max_alpha = 0.999;
  EXPECT_GE(compare_images(renderer.render(camera, gsplat), render_reference(scene, camera, gsplat)).psnr_db,
            60.0);

  RenderSettings settings = raster_settings();
  const RenderImage full = renderer.render(camera, settings);
  settings.depth = false;
  settings.splat_count = false;
  const RenderImage colour_only = renderer.render(camera, settings);
  EXPECT_EQ(colour_only.rgba, full.rgba);
  EXPECT_TRUE(colour_only.depth.empty());
  EXPECT_TRUE(colour_only.splat_count.empty());

  settings = raster_settings();
  settings.reuse_lists = true;
  renderer.render(camera, settings);
  settings.background = {0.2f, 0.4f, 0.6f};
  const RenderImage reused = renderer.render(camera, settings);
  EXPECT_TRUE(renderer.last_frame_stats().reused_sorted_lists);
  ASSERT_EQ(renderer.last_frame_stats().passes.size(), 1u);
  EXPECT_EQ(renderer.last_frame_stats().passes[0].name, "raster_composite");
  settings.reuse_lists = false;
  const RenderImage fresh = renderer.render(camera, settings);
  EXPECT_EQ(reused.rgba, fresh.rgba);
  // The background shows through by the transmittance left, as in the tile compositor.
  const size_t corner = 0;
  EXPECT_NEAR(fresh.rgba[corner * 4 + 2] - full.rgba[corner * 4 + 2],
              0.6f * (1.0f - full.rgba[corner * 4 + 3]), 1e-5f);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// Accuracy modes that only change the splats (their SH, depth keys, cut-off) apply as they do to the tile
// compositor; re-sorting and a host's depth are refused with the reason.
TEST(Raster, AccuracyModesAndRefusals) {
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(load_scene(testing::bundled_playbot()));
  const Camera camera = playbot_camera(200, 112);
  for (const std::string mode : {"depth16", "sh1+fp16-cov", "alpha-cutoff=1/64", "opacity-extent"}) {
    RenderSettings tiles;
    tiles.accuracy = parse_accuracy_modes(mode);
    RenderSettings raster = raster_settings();
    raster.accuracy = tiles.accuracy;
    const ImageDifference d = compare_images(renderer.render(camera, raster), renderer.render(camera, tiles));
    EXPECT_GE(d.psnr_db, 55.0) << mode;
  }
  RenderSettings resort = raster_settings();
  resort.accuracy = parse_accuracy_modes("resort4");
  EXPECT_NE(testing::error_of<std::invalid_argument>([&] {
              renderer.render(camera, resort);
            }).find("raster compositor"),
            std::string::npos);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// A host's surfaces in the draw's depth attachment (test LESS, no writes) hide the splats behind them:
// the same cut as the reference's raster rule and the tile compositor's, whose test is
// `splat depth < host depth` on the same floats.
TEST(Raster, HostDepthIsTheDepthAttachment) {
  Renderer& renderer = testing::validated_renderer();
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  renderer.set_scene(scene);
  const Camera camera = playbot_camera(240, 136);
  // A slanted surface through the scene: from 0.8 to 1.2 times the splats' median depth, left to right,
  // in the default convention d = 1 - 1 / z; the right quarter of the image is left empty (far).
  const RenderImage unhidden = renderer.render(camera, raster_settings());
  const double median = median_splat_depth(unhidden);
  ASSERT_GT(median, 0.0);
  std::vector<float> host_depth(size_t(camera.width) * camera.height);
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const double z = median * (0.8 + 0.4 * x / camera.width);
      host_depth[size_t(y) * camera.width + x] = x >= camera.width * 3 / 4 ? 1.0f : float(1.0 - 1.0 / z);
    }
  RenderSettings settings = raster_settings();
  settings.host = HostDepth{};
  settings.host->depth = host_depth;
  const RenderImage gpu = renderer.render(camera, settings);
  const RenderImage reference = render_reference(scene, camera, settings);
  const ImageDifference d = compare_images(gpu, reference);
  std::printf(
      "raster with a host's depth vs the reference raster rule: %.2f dB, counts differ at %zu pixels\n",
      d.psnr_db, count_difference(gpu, reference).pixels);
  EXPECT_GE(d.psnr_db, 60.0);
  EXPECT_LE(count_difference(gpu, reference).pixels, gpu.pixels() / 1000);
  // The surface hides something: fewer splats blend than without it, and none where it is far.
  size_t hidden = 0;
  for (size_t i = 0; i < gpu.pixels(); ++i) {
    EXPECT_LE(gpu.splat_count[i], unhidden.splat_count[i]);
    hidden += gpu.splat_count[i] < unhidden.splat_count[i] ? 1 : 0;
    if (i % camera.width >= size_t(camera.width * 3 / 4)) {
      EXPECT_EQ(gpu.splat_count[i], unhidden.splat_count[i]);
    }
  }
  EXPECT_GT(hidden, gpu.pixels() / 10);
  RenderSettings tiles = settings;
  tiles.compositor = Compositor::kSorted;
  EXPECT_GE(compare_images(gpu, renderer.render(camera, tiles)).psnr_db, 60.0);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// A host's depth out (HostDepth::write_depth) through the raster compositor: each fragment reads the
// alpha its pixel blended so far (rasterization-order attachment access) and the one that lifts it to the
// threshold gives the depth, as in the reference's raster rule and the tile compositor. Host surfaces cut
// the scene; where the splats never reach the threshold the host's own depth comes back.
TEST(Raster, HostDepthOutIsTheThresholdRule) {
  Renderer& renderer = testing::validated_renderer();
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  renderer.set_scene(scene);
  const Camera camera = playbot_camera(240, 136);
  // A plane at 1.1 times the splats' median depth over the left half, nothing (far) on the right.
  const double median = median_splat_depth(renderer.render(camera, raster_settings()));
  ASSERT_GT(median, 0.0);
  const double plane = 1.1 * median;
  std::vector<float> host_depth(size_t(camera.width) * camera.height, 1.0f);
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width / 2; ++x)
      host_depth[size_t(y) * camera.width + x] = float(1.0 - 1.0 / plane);
  size_t host_own_before = 0;
  for (const float threshold : {0.5f, 0.9f}) {
    RenderSettings settings = raster_settings();
    settings.host = HostDepth{};
    settings.host->depth = host_depth;
    settings.host->write_depth = true;
    settings.host->alpha_threshold = threshold;
    const RenderImage gpu = renderer.render(camera, settings);
    const RenderImage reference = render_reference(scene, camera, settings);
    RenderSettings tiles = settings;
    tiles.compositor = Compositor::kSorted;
    const RenderImage sorted = renderer.render(camera, tiles);
    ASSERT_EQ(gpu.host_depth.size(), gpu.pixels());
    size_t differ_reference = 0, differ_sorted = 0, splats_out = 0, host_own = 0;
    for (size_t i = 0; i < gpu.pixels(); ++i) {
      // The reference's splat depths are float64, the device's float32 (test_host_depth.cpp's tolerance).
      differ_reference += std::abs(gpu.host_depth[i] - reference.host_depth[i]) > 1e-6f ? 1 : 0;
      differ_sorted += gpu.host_depth[i] != sorted.host_depth[i] ? 1 : 0;
      if (gpu.host_depth[i] == host_depth[i])
        ++host_own;
      else
        ++splats_out;
      // Never behind the host's surface: the splats behind it are not drawn.
      EXPECT_LE(gpu.host_depth[i], host_depth[i]) << i;
    }
    std::printf(
        "raster depth out at alpha %.1f: %zu of %zu pixels the splats', %zu the host's; differs from the "
        "reference's raster rule at %zu, from the sorted compositor at %zu\n",
        threshold, splats_out, gpu.pixels(), host_own, differ_reference, differ_sorted);
    // Both kinds occur, and a higher threshold leaves more pixels the host's.
    EXPECT_GT(splats_out, gpu.pixels() / 10);
    EXPECT_GT(host_own, gpu.pixels() / 10);
    EXPECT_GT(host_own, host_own_before);
    host_own_before = host_own;
    // The running alpha is 1 - T in float32 here, T in float64 there: a crossing within rounding of the
    // threshold may fall one splat apart. The sorted compositor (the same float32 depths) also differs
    // where its tile rectangles cut a splat that the raster's quad still blends.
    EXPECT_LE(differ_reference, gpu.pixels() / 1000);
    EXPECT_LE(differ_sorted, gpu.pixels() / 100);
    EXPECT_GE(compare_images(gpu, reference).psnr_db, 60.0);
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// fp16-blend (AccuracyModes::fp16_blend): the raster compositor's colour and 1 - T blended in an RGBA16F
// attachment. It changes the colour by half precision's rounding, not the depth, the counts or (beyond
// rounding at the threshold) a host's depth out; the other compositors refuse it by name.
TEST(Raster, Fp16BlendIsAnAccuracyMode) {
  EXPECT_EQ(to_string(parse_accuracy_modes("fp16-blend")), "fp16-blend");
  EXPECT_TRUE(parse_accuracy_modes("depth16+fp16-blend").fp16_blend);
  EXPECT_FALSE(compositor_draws(Compositor::kSorted, parse_accuracy_modes("fp16-blend")));
  EXPECT_FALSE(compositor_draws(Compositor::kStochastic, parse_accuracy_modes("fp16-blend")));
  EXPECT_TRUE(compositor_draws(Compositor::kRaster, parse_accuracy_modes("fp16-blend")));

  Renderer& renderer = testing::validated_renderer();
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  renderer.set_scene(scene);
  const Camera camera = playbot_camera(240, 136);
  const std::vector<float> host_depth(size_t(camera.width) * camera.height, float(1.0 - 1.0 / 4.0));
  RenderSettings full = raster_settings();
  full.host = HostDepth{};
  full.host->depth = host_depth;
  full.host->write_depth = true;
  RenderSettings half = full;
  half.accuracy = parse_accuracy_modes("fp16-blend");
  const RenderImage f32 = renderer.render(camera, full);
  const RenderImage f16 = renderer.render(camera, half);
  const RenderImage reference = render_reference(scene, camera, full);
  const ImageDifference to_f32 = compare_images(f16, f32), to_reference = compare_images(f16, reference);
  size_t depth_out_differs = 0;
  for (size_t i = 0; i < f16.pixels(); ++i)
    depth_out_differs += f16.host_depth[i] != f32.host_depth[i] ? 1 : 0;
  std::printf(
      "fp16-blend: %.2f dB (max abs %.2g) from the float32 blend, %.2f dB from the reference's raster rule; "
      "depth out differs at %zu of %zu pixels\n",
      to_f32.psnr_db, to_f32.max_abs, to_reference.psnr_db, depth_out_differs, f16.pixels());
  EXPECT_NE(f16.rgba, f32.rgba);  // half precision shows
  EXPECT_GE(to_f32.psnr_db, 55.0);
  EXPECT_GE(to_reference.psnr_db, 55.0);
  EXPECT_EQ(f16.depth, f32.depth);  // the depth sums and counts keep their float32 attachments
  EXPECT_EQ(f16.splat_count, f32.splat_count);
  EXPECT_LE(depth_out_differs, f16.pixels() / 100);

  for (Compositor other : {Compositor::kSorted, Compositor::kStochastic}) {
    RenderSettings refused = raster_settings();
    refused.compositor = other;
    refused.accuracy = half.accuracy;
    EXPECT_NE(testing::error_of<std::invalid_argument>([&] {
                renderer.render(camera, refused);
              }).find("fp16-blend is the raster compositor's"),
              std::string::npos);
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// tilesplat-render --compositor raster on the GPU and with --reference; a name it does not know is a
// usage error naming the choices.
TEST(Raster, RenderCommandLine) {
  const std::filesystem::path out = testing::fresh_output_dir();
  const std::string scene = testing::bundled_playbot().string();
  const std::vector<std::string> common = {scene, "--width",      "96",    "--height",
                                           "54",  "--compositor", "raster"};
  std::vector<std::string> gpu_args = common;
  gpu_args.insert(gpu_args.end(), {"-o", (out / "gpu.exr").string()});
  const testing::ProcessResult gpu = testing::run_process("", TILESPLAT_RENDER_EXE, gpu_args);
  ASSERT_EQ(gpu.exit_code, 0) << gpu.err;
  EXPECT_NE(read_exr_string_attributes(out / "gpu.exr").at("renderSettings").find("compositor=raster"),
            std::string::npos);
  std::vector<std::string> reference_args = common;
  reference_args.insert(reference_args.end(), {"--reference", "-o", (out / "reference.exr").string()});
  const testing::ProcessResult reference = testing::run_process("", TILESPLAT_RENDER_EXE, reference_args);
  ASSERT_EQ(reference.exit_code, 0) << reference.err;
  EXPECT_GE(compare_images(read_exr(out / "gpu.exr"), read_exr(out / "reference.exr")).psnr_db, 60.0);

  const testing::ProcessResult bad = testing::run_process(
      "", TILESPLAT_RENDER_EXE, {scene, "--compositor", "billboard", "-o", (out / "bad.exr").string()});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--compositor must be sorted, stochastic or raster, got 'billboard'"),
            std::string::npos)
      << bad.err;
  EXPECT_FALSE(std::filesystem::exists(out / "bad.exr"));
  const testing::ProcessResult mixed = testing::run_process(
      "", TILESPLAT_RENDER_EXE,
      {scene, "--compositor", "raster", "--stochastic", "4", "-o", (out / "bad.exr").string()});
  EXPECT_EQ(mixed.exit_code, 2);
  testing::expect_one_error_line(mixed, "tilesplat-render");
}

// The mesh stage (where the device has VK_EXT_mesh_shader, as Mesa 25's lavapipe does) and the vertex
// stage draw the same image to the bit, with a host's depth too; asking for the mesh stage on a device
// without it (Mesa 22's lavapipe) is an error that says so.
TEST(RasterStages, MeshAndVertexStagesDrawTheSameImage) {
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const Camera camera = playbot_camera(240, 136);
  const std::vector<float> host_depth(size_t(camera.width) * camera.height, float(1.0 - 1.0 / 4.0));
  std::vector<RenderSettings> frames(2, raster_settings());
  frames[1].host = HostDepth{};
  frames[1].host->depth = host_depth;
  frames[1].splat_count = false;
  frames.push_back(frames[1]);  // and the splats' depth out
  frames[2].host->write_depth = true;
  // One renderer per stage; the stage is chosen on its first raster frame.
  auto render_with = [&](const char* stage, std::string& driver) {
    ::setenv("TILESPLAT_RASTER_STAGE", stage, 1);
    RendererOptions options;
    options.validation = true;
    auto renderer = Renderer::create(options);
    driver = renderer->device_info().driver;
    renderer->set_scene(scene);
    std::vector<RenderImage> images;
    try {
      for (const RenderSettings& settings : frames) images.push_back(renderer->render(camera, settings));
    } catch (...) {
      ::unsetenv("TILESPLAT_RASTER_STAGE");
      throw;
    }
    ::unsetenv("TILESPLAT_RASTER_STAGE");
    EXPECT_EQ(renderer->validation_messages(), 0u) << stage;
    return images;
  };
  std::string driver;
  const std::vector<RenderImage> vertex = render_with("vertex", driver);
  // Mesa's lavapipe has had VK_EXT_mesh_shader since its 24.1; Mesa 25 is what CI runs besides 22.
  const size_t mesa = driver.find("Mesa ");
  const bool mesa25_or_later = mesa != std::string::npos && std::atoi(driver.c_str() + mesa + 5) >= 25;
  try {
    const std::vector<RenderImage> mesh = render_with("mesh", driver);
    for (size_t k = 0; k < frames.size(); ++k) {
      EXPECT_EQ(mesh[k].rgba, vertex[k].rgba) << "frame " << k;
      EXPECT_EQ(mesh[k].depth, vertex[k].depth) << "frame " << k;
      EXPECT_EQ(mesh[k].splat_count, vertex[k].splat_count) << "frame " << k;
      EXPECT_EQ(mesh[k].host_depth, vertex[k].host_depth) << "frame " << k;
    }
    std::printf("mesh and vertex stages: the same images on %s\n", driver.c_str());
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("has no VK_EXT_mesh_shader"), std::string::npos) << e.what();
    EXPECT_FALSE(mesa25_or_later) << driver << " has VK_EXT_mesh_shader: " << e.what();
    std::printf("no mesh stage on %s: %s\n", driver.c_str(), e.what());
  }
}

// The reports: a row in the effects table (with a host's depth too) and the accuracy report's raster row,
// whose PSNR against the sorted compositor is a column of its own.
TEST(Raster, EffectsAndAccuracyReportsHaveTheRasterRows) {
  const std::filesystem::path out = testing::fresh_output_dir();
  const std::string scene = testing::bundled_sh3().string();
  const testing::ProcessResult effects =
      testing::run_process("", TILESPLAT_BENCH_EXE,
                           {scene, "--effects", "--width", "64", "--height", "36", "--warmup", "0",
                            "--repeat", "1", "--sort", "radix"});
  ASSERT_EQ(effects.exit_code, 0) << effects.err;
  for (const char* row :
       {"raster compositor", "raster, host depth in (a plane through the scene)", "raster_composite"})
    EXPECT_NE(effects.out.find(row), std::string::npos) << row << "\n" << effects.out;

  // The default report ends with the raster row of the reference modes; --compositor raster draws the
  // modes given with it, leaving out those it cannot draw.
  const std::filesystem::path md = out / "accuracy.md";
  const std::vector<std::string> quick = {"--width",
                                          "64",
                                          "--height",
                                          "36",
                                          "--warmup",
                                          "0",
                                          "--repeat",
                                          "1",
                                          "--sort",
                                          "radix",
                                          "--path-frames",
                                          "0",
                                          "--consistency-angle",
                                          "0"};
  std::vector<std::string> default_args = {scene, "--accuracy", "--markdown", md.string()};
  default_args.insert(default_args.end(), quick.begin(), quick.end());
  const testing::ProcessResult defaults = testing::run_process("", TILESPLAT_BENCH_EXE, default_args);
  ASSERT_EQ(defaults.exit_code, 0) << defaults.err;
  const std::string markdown = testing::read_file(md);
  EXPECT_NE(markdown.find("PSNR vs sorted compositor dB |"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("\n| raster | "), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("\n| resort4 | "), std::string::npos) << markdown;

  std::vector<std::string> raster_args = {scene,    "--accuracy", "--compositor",
                                          "raster", "--mode",     "reference,resort4"};
  raster_args.insert(raster_args.end(), quick.begin(), quick.end());
  const testing::ProcessResult raster = testing::run_process("", TILESPLAT_BENCH_EXE, raster_args);
  ASSERT_EQ(raster.exit_code, 0) << raster.err;
  EXPECT_NE(raster.out.find("\n  raster "), std::string::npos) << raster.out;
  EXPECT_EQ(raster.out.find("resort4"), std::string::npos) << raster.out;
}

#ifdef TILESPLAT_VIEWER_EXE
// The viewer draws the raster compositor too (--compositor raster, the key C): its screenshot is
// tilesplat-render's image of the same view with the same compositor.
TEST(Raster, ViewerScreenshotIsTheRasterRender) {
  const std::filesystem::path out = testing::fresh_output_dir();
  const std::vector<std::string> view = {
      testing::bundled_playbot().string(), "--width", "160", "--height", "90", "--compositor", "raster"};
  std::vector<std::string> viewer_args = view;
  viewer_args.insert(viewer_args.end(), {"--frames", "2", "--screenshot", (out / "viewer.exr").string()});
  const std::optional<std::string> display = tilesplat::testing::display_prefix();
  if (!display) TILESPLAT_SKIP_OR_FAIL(tilesplat::testing::kNoDisplay);
  const std::string prefix = *display;
  const testing::ProcessResult viewer = testing::run_process(prefix, TILESPLAT_VIEWER_EXE, viewer_args);
  ASSERT_EQ(viewer.exit_code, 0) << viewer.err;
  std::vector<std::string> render_args = view;
  render_args.insert(render_args.end(), {"-o", (out / "render.exr").string()});
  const testing::ProcessResult render = testing::run_process("", TILESPLAT_RENDER_EXE, render_args);
  ASSERT_EQ(render.exit_code, 0) << render.err;
  const RenderImage shown = read_exr(out / "viewer.exr");
  const RenderImage rendered = read_exr(out / "render.exr");
  EXPECT_GE(compare_images(shown, rendered).psnr_db, 100.0);
  EXPECT_EQ(shown.splat_count, rendered.splat_count);

  // Refused before a window opens: no display needed.
  const testing::ProcessResult resort = testing::run_process(
      "env -u DISPLAY -u WAYLAND_DISPLAY ", TILESPLAT_VIEWER_EXE,
      {testing::bundled_playbot().string(), "--compositor", "raster", "--mode", "resort8"});
  EXPECT_EQ(resort.exit_code, 2);
  EXPECT_NE(resort.err.find("does not re-sort per pixel"), std::string::npos) << resort.err;
}
#endif

}  // namespace
}  // namespace tilesplat
