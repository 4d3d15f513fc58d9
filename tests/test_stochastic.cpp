// The stochastic (sort-free) compositor: its mean over frames converges to the sorted image at the
// Monte Carlo rate, is deterministic per seed, runs no depth sort, and refuses what it cannot honour.
#include <gtest/gtest.h>
#include <unistd.h>

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
#include "tilesplat/renderer.h"
#include "tilesplat/scene.h"

namespace tilesplat {
namespace {

RenderSettings stochastic(uint32_t frames, uint32_t seed = 1) {
  RenderSettings settings;
  settings.compositor = Compositor::kStochastic;
  settings.stochastic.frames = frames;
  settings.stochastic.seed = seed;
  return settings;
}

// Overlapping splats of every opacity in front of the camera: many layers per pixel, so that the
// nearest-kept choice matters, and some pixels uncovered.
GaussianScene synthetic_scene() {
  GaussianScene scene;
  scene.sh_degree = 0;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  for (int i = 0; i < 3000; ++i) {
    const float x = 2.4f * unit(rng) - 1.2f, y = 1.8f * unit(rng) - 0.9f, z = 2.f + 2.f * unit(rng);
    scene.positions.insert(scene.positions.end(), {x, y, z});
    scene.log_scales.insert(scene.log_scales.end(),
                            {std::log(0.02f + 0.1f * unit(rng)), std::log(0.02f + 0.1f * unit(rng)), -3.f});
    const float angle = 3.14159f * unit(rng);
    scene.rotations.insert(scene.rotations.end(), {std::cos(angle), 0.f, 0.f, std::sin(angle)});
    scene.opacity_logits.push_back(6.f * unit(rng) - 3.f);
    scene.sh.insert(scene.sh.end(), {3.f * unit(rng) - 1.5f, 3.f * unit(rng) - 1.5f, 3.f * unit(rng) - 1.5f});
  }
  return scene;
}

struct Case {
  std::string name;
  GaussianScene scene;
  Camera camera;
  double psnr_bound_256;  // PSNR against the sorted image after 256 frames (measured, with margin)
};

// The bounds: 41.9 and 37.8 dB measured on lavapipe (deterministic hashes), less 3-4 dB.
Case playbot_case() {
  return {"playbot", load_scene(testing::bundled_playbot()),
          resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(0).camera, 160, 90), 38.0};
}
Case synthetic_case() {
  return {"synthetic", synthetic_scene(), look_at_camera({0, 0, 0}, {0, 0, 1}, {0, -1, 0}, 128, 96, 50), 35.0};
}

class StochasticConvergence : public ::testing::TestWithParam<int> {};

// The convergence tests' frames: over a coloured background, so that alpha errors show in the colour.
RenderSettings over_background(RenderSettings settings) {
  settings.background = {0.2f, 0.3f, 0.4f};
  return settings;
}

// The mean over N frames is an unbiased estimate of the sorted blend (up to its T < 1e-4 early-out):
// PSNR rises with N and the RMS error falls as 1/sqrt(N).
TEST_P(StochasticConvergence, ApproachesTheSortedImageAtTheMonteCarloRate) {
  const Case c = GetParam() == 0 ? playbot_case() : synthetic_case();
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(c.scene);
  RenderSettings sorted_settings;
  sorted_settings.background = {0.2f, 0.3f, 0.4f};
  const RenderImage sorted = renderer.render(c.camera, sorted_settings);

  const std::vector<uint32_t> frames = {1, 4, 16, 64, 256};
  std::vector<double> psnr, rmse, alpha_error;
  for (uint32_t n : frames) {
    RenderSettings settings = stochastic(n);
    settings.background = sorted_settings.background;
    const RenderImage image = renderer.render(c.camera, settings);
    const ImageDifference d = compare_images(image, sorted);
    psnr.push_back(d.psnr_db);
    rmse.push_back(d.rmse);
    double alpha_sq = 0;
    for (size_t i = 0; i < image.pixels(); ++i) {
      const double e = double(image.rgba[4 * i + 3]) - double(sorted.rgba[4 * i + 3]);
      alpha_sq += e * e;
    }
    alpha_error.push_back(std::sqrt(alpha_sq / double(image.pixels())));
    std::printf("[ measure  ] %s %dx%d: %4u frames: PSNR %.2f dB, RMSE %.5f, alpha RMSE %.5f, composite %.1f ms\n",
                c.name.c_str(), c.camera.width, c.camera.height, n, d.psnr_db, d.rmse, alpha_error.back(),
                renderer.last_frame_stats().passes.back().gpu_ms);
  }
  for (size_t k = 1; k < frames.size(); ++k) {
    EXPECT_GT(psnr[k], psnr[k - 1] + 3.0) << c.name << ": " << frames[k] << " frames";  // 6 dB per 4x, ideally
    EXPECT_LT(alpha_error[k], alpha_error[k - 1]) << c.name << ": " << frames[k] << " frames";
  }
  EXPECT_GE(psnr.back(), c.psnr_bound_256) << c.name;
  // 1/sqrt(N): 16x the frames, 4x smaller error. Slack for the noise of the estimate itself.
  for (size_t k = 0; k + 2 < frames.size(); ++k) {
    const double ratio = rmse[k] / rmse[k + 2];
    EXPECT_GT(ratio, 3.0) << c.name << ": RMSE " << frames[k] << " / " << frames[k + 2] << " frames";
    EXPECT_LT(ratio, 5.3) << c.name << ": RMSE " << frames[k] << " / " << frames[k + 2] << " frames";
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Scenes, StochasticConvergence, ::testing::Values(0, 1),
                         [](const ::testing::TestParamInfo<int>& scene) {
                           return std::string(scene.param == 0 ? "PlaybotCrop" : "Synthetic");
                         });

// StochasticSampler::kStratified: each splat's thresholds at a pixel take each of the N strata once over
// the N frames. Still unbiased (the mean over seeds converges to the sorted image as the hash's does), but
// each splat's own coverage is exact to 1/N, so the error falls faster than 1/sqrt(N): measured against
// the hash at the same frame counts on both scenes, with the same seed giving the same image.
TEST_P(StochasticConvergence, StratifiedSamplerConvergesFasterThanTheHash) {
  const Case c = GetParam() == 0 ? playbot_case() : synthetic_case();
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(c.scene);
  const RenderImage sorted = renderer.render(c.camera, over_background(RenderSettings{}));
  std::vector<double> gain;
  // Powers of two (every stratum taken), then 24 of 32 strata.
  for (uint32_t n : {1u, 4u, 16u, 64u, 256u, 24u}) {
    const RenderSettings hash = over_background(stochastic(n));
    RenderSettings stratified = hash;
    stratified.stochastic.sampler = StochasticSampler::kStratified;
    const double psnr_hash = compare_images(renderer.render(c.camera, hash), sorted).psnr_db;
    const RenderImage image = renderer.render(c.camera, stratified);
    const double psnr_stratified = compare_images(image, sorted).psnr_db;
    std::printf("[ measure  ] %s %dx%d: %4u frames: hash %.2f dB, stratified %.2f dB (%+.2f)\n",
                c.name.c_str(), c.camera.width, c.camera.height, n, psnr_hash, psnr_stratified,
                psnr_stratified - psnr_hash);
    gain.push_back(psnr_stratified - psnr_hash);
    if (n == 16) {
      EXPECT_EQ(renderer.render(c.camera, stratified).rgba, image.rgba);  // deterministic
      stratified.stochastic.seed = 2;
      EXPECT_NE(renderer.render(c.camera, stratified).rgba, image.rgba);
    }
  }
  // One frame: both are one uniform threshold per splat, equally noisy.
  EXPECT_NEAR(gain[0], 0.0, 1.0) << c.name;
  // Then the stratified frames pull ahead, the more the more frames.
  EXPECT_GT(gain[2], 1.5) << c.name;
  EXPECT_GT(gain[4], gain[2]) << c.name;
  EXPECT_GT(gain[5], 1.0) << c.name;
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// The sobol sampler (the effects' Owen-scrambled sequence, per pixel and splat): stratified like the
// stratified sampler at powers of two, so as far ahead of the hash, and progressive: calls of one frame
// that accumulate are the one call of all of them, to the bit, which the stratified sampler cannot do.
TEST_P(StochasticConvergence, SobolSamplerIsStratifiedAndContinuesAcrossCalls) {
  const Case c = GetParam() == 0 ? playbot_case() : synthetic_case();
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(c.scene);
  const RenderImage sorted = renderer.render(c.camera, over_background(RenderSettings{}));
  std::vector<double> gain;
  for (uint32_t n : {1u, 16u, 256u}) {
    const RenderSettings hash = over_background(stochastic(n));
    RenderSettings sobol = hash, stratified = hash;
    sobol.stochastic.sampler = StochasticSampler::kSobol;
    stratified.stochastic.sampler = StochasticSampler::kStratified;
    const double psnr_hash = compare_images(renderer.render(c.camera, hash), sorted).psnr_db;
    const double psnr_stratified = compare_images(renderer.render(c.camera, stratified), sorted).psnr_db;
    const double psnr_sobol = compare_images(renderer.render(c.camera, sobol), sorted).psnr_db;
    std::printf("[ measure  ] %s %dx%d: %4u frames: hash %.2f dB, stratified %.2f dB, sobol %.2f dB\n",
                c.name.c_str(), c.camera.width, c.camera.height, n, psnr_hash, psnr_stratified, psnr_sobol);
    gain.push_back(psnr_sobol - psnr_hash);
    if (n > 1) {
      EXPECT_NEAR(psnr_sobol, psnr_stratified, 1.0) << c.name << ", " << n << " frames";
    }
  }
  EXPECT_NEAR(gain[0], 0.0, 1.0) << c.name;  // one frame: one uniform threshold per splat either way
  EXPECT_GT(gain[1], 1.5) << c.name;
  EXPECT_GT(gain[2], gain[1]) << c.name;

  RenderSettings one = over_background(stochastic(1));
  one.stochastic.sampler = StochasticSampler::kSobol;
  one.stochastic.accumulate = true;
  RenderImage image;
  for (uint32_t k = 1; k <= 5; ++k) image = renderer.render(c.camera, one);
  EXPECT_EQ(renderer.last_frame_stats().accumulated_frames, 5u);
  RenderSettings five = one;
  five.stochastic.frames = 5;
  five.stochastic.accumulate = false;
  EXPECT_EQ(image.rgba, renderer.render(c.camera, five).rgba);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// tilesplat-render --stochastic N --stochastic-sampler stratified renders what RenderSettings does and
// records the sampler; a bad name, or the flag without the stochastic compositor, is a usage error.
TEST(Stochastic, RenderCommandLineChoosesTheSampler) {
  const std::filesystem::path out = testing::fresh_output_dir();
  const std::string scene = testing::bundled_playbot().string();
  auto render = [&](std::vector<std::string> args, const std::string& file) {
    args.insert(args.begin(), {scene, "--width", "96", "--height", "54"});
    args.insert(args.end(), {"-o", (out / file).string()});
    return testing::run_process("", TILESPLAT_RENDER_EXE, args);
  };
  const testing::ProcessResult stratified =
      render({"--stochastic", "8", "--stochastic-sampler", "stratified"}, "stratified.exr");
  ASSERT_EQ(stratified.exit_code, 0) << stratified.err;
  EXPECT_NE(
      read_exr_string_attributes(out / "stratified.exr").at("renderSettings").find("sampler=stratified"),
      std::string::npos);
  ASSERT_EQ(render({"--stochastic", "8"}, "hash.exr").exit_code, 0);
  EXPECT_EQ(read_exr_string_attributes(out / "hash.exr").at("renderSettings").find("sampler="),
            std::string::npos);
  EXPECT_NE(read_exr(out / "stratified.exr").rgba, read_exr(out / "hash.exr").rgba);

  const testing::ProcessResult bad = render({"--stochastic", "8", "--stochastic-sampler", "blue"}, "bad.exr");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--stochastic-sampler must be hash, stratified or sobol, got 'blue'"),
            std::string::npos)
      << bad.err;
  const testing::ProcessResult alone = render({"--stochastic-sampler", "stratified"}, "alone.exr");
  EXPECT_EQ(alone.exit_code, 2);
  EXPECT_NE(alone.err.find("--stochastic-sampler is the stochastic compositor's"), std::string::npos)
      << alone.err;
  EXPECT_FALSE(std::filesystem::exists(out / "bad.exr"));
  EXPECT_FALSE(std::filesystem::exists(out / "alone.exr"));
  EXPECT_EQ(to_string(StochasticSampler::kStratified), "stratified");
  EXPECT_EQ(parse_stochastic_sampler("hash"), StochasticSampler::kHash);
  EXPECT_THROW(parse_stochastic_sampler("blue"), std::invalid_argument);
}

// StochasticSettings::accumulate: repeated calls on a view at rest add their frames to one mean (the
// composite state keeps the sums), so N calls of 1 frame are one call of N frames, to the bit; a new
// camera, background or an other frame in between starts the mean anew.
TEST(Stochastic, AccumulatedCallsAreOneLongerCall) {
  const Case c = playbot_case();
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(c.scene);
  RenderSettings one = stochastic(1);
  one.stochastic.accumulate = true;
  RenderImage image;
  for (uint32_t k = 1; k <= 6; ++k) {
    image = renderer.render(c.camera, one);
    EXPECT_EQ(renderer.last_frame_stats().accumulated_frames, k);
  }
  const RenderImage six = renderer.render(c.camera, stochastic(6));
  EXPECT_EQ(renderer.last_frame_stats().accumulated_frames, 6u);
  EXPECT_EQ(image.rgba, six.rgba);
  EXPECT_EQ(image.depth, six.depth);
  EXPECT_EQ(image.splat_count, six.splat_count);

  // Calls of several frames continue the same sequence: 3 + 5 frames are 8.
  RenderSettings three = stochastic(3);
  three.stochastic.accumulate = true;
  renderer.render(c.camera, three);  // after a frame that did not accumulate: anew
  EXPECT_EQ(renderer.last_frame_stats().accumulated_frames, 3u);
  RenderSettings five = three;
  five.stochastic.frames = 5;
  const RenderImage eight = renderer.render(c.camera, five);
  EXPECT_EQ(renderer.last_frame_stats().accumulated_frames, 8u);
  EXPECT_EQ(eight.rgba, renderer.render(c.camera, stochastic(8)).rgba);

  // What starts it anew: another camera, another background, a sorted frame in between.
  renderer.render(c.camera, one);
  EXPECT_EQ(renderer.last_frame_stats().accumulated_frames, 1u);
  renderer.render(c.camera, one);
  EXPECT_EQ(renderer.last_frame_stats().accumulated_frames, 2u);
  const Camera moved =
      resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(1).camera, 160, 90);
  const RenderImage first_moved = renderer.render(moved, one);
  EXPECT_EQ(renderer.last_frame_stats().accumulated_frames, 1u);
  EXPECT_EQ(first_moved.rgba, renderer.render(moved, stochastic(1)).rgba);
  renderer.render(moved, one);
  RenderSettings white = one;
  white.background = {1, 1, 1};
  renderer.render(moved, white);
  EXPECT_EQ(renderer.last_frame_stats().accumulated_frames, 1u);
  renderer.render(moved, white);
  renderer.render(moved);  // sorted
  renderer.render(moved, white);
  EXPECT_EQ(renderer.last_frame_stats().accumulated_frames, 1u);

  RenderSettings stratified = one;
  stratified.stochastic.sampler = StochasticSampler::kStratified;
  EXPECT_NE(testing::error_of<std::invalid_argument>([&] {
              renderer.render(moved, stratified);
            }).find("accumulate with the hash sampler"),
            std::string::npos);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(Stochastic, SameSeedIsBitIdenticalAndOtherSeedsAreEquallyClose) {
  const Case c = playbot_case();
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(c.scene);
  const RenderImage sorted = renderer.render(c.camera);
  const RenderImage a = renderer.render(c.camera, stochastic(16, 7));
  renderer.set_scene(c.scene);  // the lists built anew: the same again
  const RenderImage b = renderer.render(c.camera, stochastic(16, 7));
  EXPECT_EQ(a.rgba, b.rgba);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_EQ(a.splat_count, b.splat_count);

  const RenderImage other = renderer.render(c.camera, stochastic(16, 8));
  EXPECT_NE(a.rgba, other.rgba);
  const double psnr_a = compare_images(a, sorted).psnr_db;
  const double psnr_other = compare_images(other, sorted).psnr_db;
  const double psnr_between = compare_images(a, other).psnr_db;
  std::printf("[ measure  ] 16 frames, seed 7: %.2f dB, seed 8: %.2f dB, seed 7 vs 8: %.2f dB\n", psnr_a, psnr_other,
              psnr_between);
  EXPECT_NEAR(psnr_a, psnr_other, 1.0);
  // Independent estimates: their difference has twice the variance of either's error (-3 dB).
  EXPECT_NEAR(psnr_between, psnr_a - 3.0, 1.5);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

TEST(Stochastic, FrameRunsNoDepthSortAndReportsItsPasses) {
  const Case c = synthetic_case();
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(c.scene);
  RenderImage first;
  for (const std::string& sort : sort_strategies()) {
    if (!sort_strategy_is_exact(sort)) continue;
    RenderSettings settings = stochastic(2);
    settings.sort = sort;
    const RenderImage image = renderer.render(c.camera, settings);
    const FrameStats& stats = renderer.last_frame_stats();
    std::vector<std::string> names;
    for (const PassTiming& pass : stats.passes) {
      names.push_back(pass.name);
      EXPECT_GE(pass.gpu_ms, 0.0);
    }
    EXPECT_EQ(names, (std::vector<std::string>{"projection", "prefix_sum", "key_emission", "tile_binning",
                                               "tile_ranges", "stochastic_composite"}))
        << sort;
    EXPECT_FALSE(stats.reused_sorted_lists);
    EXPECT_GT(stats.intersections, 3000u);
    // Tile bits alone: the 8x6 tiles' ids need 6 bits.
    EXPECT_EQ(stats.sort_bits, 6u) << sort;
    // Every strategy bins the same pairs into the same lists, so the images agree bit for bit.
    if (first.rgba.empty()) first = image;
    EXPECT_EQ(image.rgba, first.rgba) << sort;
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// The outputs besides colour: alpha is the fraction of frames that kept a splat, depth the mean of
// the winners' depths, the count the list length each pixel tested (at least the sorted blend's).
TEST(Stochastic, AlphaDepthAndCountOutputs) {
  const Case c = synthetic_case();
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(c.scene);
  const RenderImage sorted = renderer.render(c.camera);
  const uint32_t frames = 64;
  const RenderImage image = renderer.render(c.camera, stochastic(frames));
  double depth_error = 0;
  size_t covered = 0, empty = 0;
  for (size_t i = 0; i < image.pixels(); ++i) {
    const float alpha = image.rgba[4 * i + 3];
    // A fraction of the frames: a multiple of 1/64, exactly.
    EXPECT_EQ(alpha * float(frames), std::round(alpha * float(frames))) << i;
    EXPECT_GE(image.splat_count[i], sorted.splat_count[i]) << i;
    if (image.splat_count[i] == 0) {
      ++empty;
      EXPECT_EQ(alpha, 0.f);
      EXPECT_EQ(image.depth[i], 0.f);
    }
    if (alpha > 0.9f && sorted.rgba[4 * i + 3] > 0.9f) {
      depth_error += std::abs(double(image.depth[i]) - double(sorted.depth[i]));
      ++covered;
    }
  }
  ASSERT_GT(covered, image.pixels() / 4);
  depth_error /= double(covered);
  std::printf("[ measure  ] 64 frames: mean |depth - sorted depth| %.4f over %zu covered pixels (%zu empty)\n",
              depth_error, covered, empty);
  EXPECT_LT(depth_error, 0.1);  // depths 2 to 4
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// The stratified sampler's strata, checked directly rather than through a dB gain: one splat covering the
// image with the same alpha at every pixel (a Gaussian 1000 times the view's width: alpha varies by 1e-7),
// rendered with N frames. Its thresholds at a pixel over the N frames fall one in each stratum [k/N,
// (k+1)/N), so an alpha in the middle of stratum k is passed by exactly k or k + 1 of them: the pixel's
// coverage (its alpha, the fraction of frames the splat was kept) is within 1/(2N) of alpha at every pixel,
// and the image's mean coverage within 1/N of it. The hash sampler's coverage, binomial, strays past the
// half stratum at many pixels: the check can tell the two apart.
TEST(Stochastic, StratifiedThresholdsFallOneInEachStratumOfTheFrames) {
  Renderer& renderer = testing::validated_renderer();
  const Camera camera = testing::axis_camera(64, 48, 50);
  for (const uint32_t frames : {16u, 64u}) {
    for (const uint32_t stratum : {0u, frames / 3, frames - 2}) {  // below the alpha cap of 0.99
      const double alpha = (stratum + 0.5) / frames;
      GaussianScene scene;
      scene.positions = {0, 0, 5};
      scene.log_scales = {8, 8, 8};  // a sigma of 3000 units at depth 5
      scene.rotations = {1, 0, 0, 0};
      scene.opacity_logits = {float(std::log(alpha / (1 - alpha)))};
      scene.sh = {1.77f, 1.77f, 1.77f};  // white: 0.5 + C0 * 1.77 = 1.0
      renderer.set_scene(scene);
      for (const StochasticSampler sampler : {StochasticSampler::kStratified, StochasticSampler::kHash}) {
        RenderSettings settings = stochastic(frames, 7);
        settings.stochastic.sampler = sampler;
        const RenderImage image = renderer.render(camera, settings);
        size_t past_half_stratum = 0;
        double mean = 0;
        for (size_t p = 0; p < image.pixels(); ++p) {
          const double coverage = image.rgba[4 * p + 3];
          mean += coverage;
          past_half_stratum += std::abs(coverage - alpha) > 0.5 / frames + 1e-6;
        }
        mean /= double(image.pixels());
        std::printf("[ measure  ] %-10s %2u frames, alpha %.4f: mean coverage %.5f, %zu of %zu pixels past half a "
                    "stratum\n",
                    to_string(sampler).c_str(), frames, alpha, mean, past_half_stratum, image.pixels());
        if (sampler == StochasticSampler::kStratified) {
          EXPECT_EQ(past_half_stratum, 0u) << frames << " frames, alpha " << alpha;
          EXPECT_NEAR(mean, alpha, 1.0 / frames);
        } else if (stratum > 0 && stratum + 1 < frames) {
          EXPECT_GT(past_half_stratum, image.pixels() / 10) << "the hash sampler is not stratified";
        }
      }
    }
  }
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// llvmpipe cuts a shader invocation after 65535 loop iterations: a tile list of 70k splats is tested
// in chunks, each sample carrying its nearest kept splat between them. The nearest, opaque splats
// are the last 10k of the list (binned lists keep index order), so a truncated list would show the
// far red ones instead of the near green ones.
TEST(Stochastic, TileListsLongerThanTheCpuLoopLimitAreTestedWhole) {
  GaussianScene scene;
  scene.sh_degree = 0;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  Camera camera;
  camera.width = camera.height = 16;  // one tile
  camera.fx = camera.fy = 16;
  camera.cx = camera.cy = 8;
  for (int i = 0; i < 70000; ++i) {
    const bool near = i >= 60000;
    const float z = near ? 1.f + 0.1f * unit(rng) : 2.f + unit(rng);
    const float px = 0.5f + 15.f * unit(rng), py = 0.5f + 15.f * unit(rng);
    scene.positions.insert(scene.positions.end(), {(px - 8.f) * z / 16.f, (py - 8.f) * z / 16.f, z});
    const float log_scale = std::log((near ? 0.5f : 0.05f) * z / 16.f);
    scene.log_scales.insert(scene.log_scales.end(), {log_scale, log_scale, log_scale});
    scene.rotations.insert(scene.rotations.end(), {1, 0, 0, 0});
    scene.opacity_logits.push_back(near ? 0.f : -4.f);
    scene.sh.insert(scene.sh.end(), {near ? -1.f : 1.f, near ? 1.f : -1.f, -1.f});
  }
  RendererOptions options;
  options.validation = true;
  const auto owned = Renderer::create(options);  // its own: the chunk count starts at one
  Renderer& renderer = *owned;
  renderer.set_scene(scene);
  const RenderImage sorted = renderer.render(camera);
  const RenderImage image = renderer.render(camera, stochastic(64));
  const FrameStats& stats = renderer.last_frame_stats();
  for (size_t i = 0; i < image.pixels(); ++i) EXPECT_EQ(image.splat_count[i], 70000u) << i;
  const ImageDifference d = compare_images(image, sorted);
  double green = 0;
  for (size_t i = 0; i < image.pixels(); ++i) green += image.rgba[4 * i + 1] / double(image.pixels());
  std::printf("[ measure  ] 70000 splats in one tile, 64 frames: PSNR %.2f dB against sorted, mean green %.3f, "
              "%d re-render(s)\n",
              d.psnr_db, green, stats.retries);
  EXPECT_GE(stats.retries, 1);  // found the list too long for one chunk, and re-rendered with more
  EXPECT_GT(green, 0.4);
  EXPECT_GE(d.psnr_db, 25.0);
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

// As CompositeLayoutsGiveIdenticalImages: the GPU layouts (one pixel per invocation, or a few with
// one list each) run on lavapipe and give the CPU layout's image bit for bit.
TEST(Stochastic, CompositeLayoutsGiveIdenticalImages) {
  const Case c = playbot_case();
  testing::expect_composite_layouts_identical(c.scene, c.camera, stochastic(3));
}

TEST(Stochastic, RejectsSettingsItCannotHonour) {
  Renderer& renderer = testing::validated_renderer();
  renderer.set_scene(synthetic_scene());
  const Camera camera = look_at_camera({0, 0, 0}, {0, 0, 1}, {0, -1, 0}, 32, 32, 50);
  auto message = [&](const RenderSettings& settings) -> std::string {
    try {
      renderer.render(camera, settings);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "(no exception)";
  };
  RenderSettings settings = stochastic(4);
  settings.accuracy.resort_window = 8;
  EXPECT_NE(message(settings).find("resort8"), std::string::npos) << message(settings);
  settings = stochastic(4);
  settings.accuracy.depth_key_bits = 16;
  EXPECT_NE(message(settings).find("16-bit depth keys"), std::string::npos) << message(settings);
  settings.accuracy.depth_key_bits = 24;
  EXPECT_NE(message(settings).find("24-bit depth keys"), std::string::npos) << message(settings);
  for (uint32_t frames : {0u, 4097u}) {
    settings = stochastic(frames);
    EXPECT_NE(message(settings).find("frames must be 1 to 4096"), std::string::npos) << message(settings);
  }
  // The limits themselves are fine, and the sorted compositor ignores the stochastic settings.
  EXPECT_NO_THROW(renderer.render(camera, stochastic(1)));
  settings = stochastic(0);
  settings.compositor = Compositor::kSorted;
  settings.accuracy.resort_window = 8;
  EXPECT_NO_THROW(renderer.render(camera, settings));
  EXPECT_EQ(to_string(Compositor::kStochastic), "stochastic");
  EXPECT_EQ(to_string(Compositor::kSorted), "sorted");
  EXPECT_EQ(renderer.validation_messages(), 0u);
}

#ifdef TILESPLAT_VIEWER_EXE
// The viewer's screenshot after six redraws of the stochastic compositor with `sampler_flags`, and
// tilesplat-render's image of the same view with --stochastic N (N the frames the viewer reports) and the
// same flags, for the tests below to compare.
void expect_viewer_screenshot_is_the_render(const std::vector<std::string>& sampler_flags) {
  const std::filesystem::path out = testing::fresh_output_dir();
  std::vector<std::string> view = {testing::bundled_playbot().string(), "--width", "160", "--height", "90"};
  view.insert(view.end(), sampler_flags.begin(), sampler_flags.end());
  std::vector<std::string> viewer_args = view;
  viewer_args.insert(viewer_args.end(), {"--compositor", "stochastic", "--frames", "6", "--validation",
                                         "--screenshot", (out / "viewer.exr").string()});
  const std::optional<std::string> display = tilesplat::testing::display_prefix();
  if (!display) TILESPLAT_SKIP_OR_FAIL(tilesplat::testing::kNoDisplay);
  const testing::ProcessResult viewer = testing::run_process(*display, TILESPLAT_VIEWER_EXE, viewer_args);
  ASSERT_EQ(viewer.exit_code, 0) << viewer.err;
  EXPECT_NE(viewer.err.find("validation: 0 messages"), std::string::npos) << viewer.err;
  const std::string said = "the screenshot is the mean of ";
  const size_t at = viewer.err.find(said);
  ASSERT_NE(at, std::string::npos) << viewer.err;
  const int frames = std::atoi(viewer.err.c_str() + at + said.size());
  // Six redraws of a view that never moved: each added its frame (a resize at the start may restart).
  EXPECT_GE(frames, 4) << viewer.err;
  EXPECT_LE(frames, 6) << viewer.err;
  std::vector<std::string> render_args = view;
  render_args.insert(render_args.end(),
                     {"--stochastic", std::to_string(frames), "-o", (out / "render.exr").string()});
  const testing::ProcessResult render = testing::run_process("", TILESPLAT_RENDER_EXE, render_args);
  ASSERT_EQ(render.exit_code, 0) << render.err;
  EXPECT_EQ(read_exr(out / "viewer.exr").rgba, read_exr(out / "render.exr").rgba);
}

// The viewer shows the stochastic compositor too (--compositor stochastic, key C): a view at rest adds a
// frame a redraw to the mean, and its screenshot is that mean rendered in one call: the image of
// tilesplat-render --stochastic N with the N it reports, to the bit.
TEST(Stochastic, ViewerAccumulatesFramesWhileTheViewRests) {
  expect_viewer_screenshot_is_the_render({});
}

// With --stochastic-sampler sobol the frames a still view adds up are the progressive sequence's: the
// screenshot is tilesplat-render --stochastic N --stochastic-sampler sobol, to the bit.
TEST(Stochastic, ViewerAddsUpTheSobolSequence) {
  expect_viewer_screenshot_is_the_render({"--stochastic-sampler", "sobol"});
}
#endif

}  // namespace
}  // namespace tilesplat
