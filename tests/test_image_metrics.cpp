// SSIM and the temporal-stability metrics of image.h, checked against direct implementations of their
// definitions written here without the engine's tricks (separable filtering, the difference form).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "tilesplat/image.h"

namespace {

using tilesplat::compare_images;
using tilesplat::frame_change;
using tilesplat::RenderImage;
using tilesplat::ssim;
using tilesplat::popping;
using tilesplat::temporal_excess;
using tilesplat::TemporalDifference;

// Values uniform in [lo, hi), alpha 1.
RenderImage random_image(int width, int height, unsigned seed, float lo = 0.0f, float hi = 1.0f) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<float> distribution(lo, hi);
  RenderImage image;
  image.width = width;
  image.height = height;
  image.rgba.resize(4 * image.pixels());
  for (size_t i = 0; i < image.rgba.size(); ++i) image.rgba[i] = i % 4 == 3 ? 1.0f : distribution(generator);
  return image;
}

// A smooth pattern with structure at several scales, in [0.2, 0.8]: what SSIM is meant for, unlike
// white noise whose windows have no structure to lose.
RenderImage textured_image(int width, int height) {
  RenderImage image;
  image.width = width;
  image.height = height;
  image.rgba.resize(4 * image.pixels());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 4; ++c) {
        const double value =
            0.5 + 0.15 * std::sin(0.3 * x + c) * std::cos(0.2 * y) + 0.15 * std::sin(0.05 * (x + 2 * y));
        image.rgba[4 * static_cast<size_t>(y * width + x) + static_cast<size_t>(c)] =
            c == 3 ? 1.0f : static_cast<float>(value);
      }
  return image;
}

float at(const RenderImage& image, int x, int y, int channel) {
  return image.rgba[4 * static_cast<size_t>(y * image.width + x) + static_cast<size_t>(channel)];
}

// SSIM straight from Wang et al.: for every position of the window inside the image, the 2D Gaussian
// weights (sigma 1.5, normalised over the window), weighted means, population variances and covariance,
// and the textbook product formula. An image dimension under 11 gets the window clipped to it, centred,
// as image.h documents.
double direct_ssim(const RenderImage& a, const RenderImage& b) {
  const int window_w = std::min(a.width, 11);
  const int window_h = std::min(a.height, 11);
  const double centre_x = 0.5 * (window_w - 1);
  const double centre_y = 0.5 * (window_h - 1);
  std::vector<double> weights(static_cast<size_t>(window_w * window_h));
  double weight_sum = 0;
  for (int j = 0; j < window_h; ++j)
    for (int i = 0; i < window_w; ++i) {
      const double r2 = (i - centre_x) * (i - centre_x) + (j - centre_y) * (j - centre_y);
      weights[static_cast<size_t>(j * window_w + i)] = std::exp(-r2 / (2 * 1.5 * 1.5));
      weight_sum += weights[static_cast<size_t>(j * window_w + i)];
    }
  for (double& weight : weights) weight /= weight_sum;

  const double c1 = 0.01 * 0.01;
  const double c2 = 0.03 * 0.03;
  double sum = 0;
  int count = 0;
  for (int c = 0; c < 3; ++c)
    for (int oy = 0; oy + window_h <= a.height; ++oy)
      for (int ox = 0; ox + window_w <= a.width; ++ox) {
        double mean_a = 0, mean_b = 0;
        for (int j = 0; j < window_h; ++j)
          for (int i = 0; i < window_w; ++i) {
            const double w = weights[static_cast<size_t>(j * window_w + i)];
            mean_a += w * at(a, ox + i, oy + j, c);
            mean_b += w * at(b, ox + i, oy + j, c);
          }
        double var_a = 0, var_b = 0, covariance = 0;
        for (int j = 0; j < window_h; ++j)
          for (int i = 0; i < window_w; ++i) {
            const double w = weights[static_cast<size_t>(j * window_w + i)];
            const double da = at(a, ox + i, oy + j, c) - mean_a;
            const double db = at(b, ox + i, oy + j, c) - mean_b;
            var_a += w * da * da;
            var_b += w * db * db;
            covariance += w * da * db;
          }
        sum += (2 * mean_a * mean_b + c1) * (2 * covariance + c2) /
               ((mean_a * mean_a + mean_b * mean_b + c1) * (var_a + var_b + c2));
        ++count;
      }
  return sum / count;
}

// ---------------------------------------------------------------------------------------------
// SSIM

TEST(Ssim, IdenticalImagesScoreExactlyOne) {
  for (const auto& [width, height] : {std::pair{40, 30}, std::pair{64, 11}, std::pair{7, 5}, std::pair{1, 1}}) {
    const RenderImage image = random_image(width, height, 1u);
    EXPECT_EQ(ssim(image, image), 1.0) << width << "x" << height;
    RenderImage copy = image;
    EXPECT_EQ(ssim(image, copy), 1.0) << width << "x" << height;
  }
  RenderImage flat = random_image(16, 16, 2u);
  std::fill(flat.rgba.begin(), flat.rgba.end(), 0.25f);
  EXPECT_EQ(ssim(flat, flat), 1.0);  // no variance at all: the constants keep it defined
}

TEST(Ssim, IsSymmetric) {
  const RenderImage a = random_image(40, 30, 3u);
  const RenderImage b = random_image(40, 30, 4u);
  EXPECT_DOUBLE_EQ(ssim(a, b), ssim(b, a));
  const RenderImage c = textured_image(40, 30);
  EXPECT_DOUBLE_EQ(ssim(a, c), ssim(c, a));
}

TEST(Ssim, MatchesADirectImplementationOfTheDefinition) {
  const RenderImage a = random_image(40, 30, 5u);
  // b: a plus noise, so the score is far from both 0 and 1 and every term of the formula matters.
  RenderImage b = a;
  std::mt19937 generator(6u);
  std::normal_distribution<float> noise(0.0f, 0.1f);
  for (size_t i = 0; i < b.rgba.size(); ++i)
    if (i % 4 != 3) b.rgba[i] += noise(generator);
  const double expected = direct_ssim(a, b);
  EXPECT_GT(expected, 0.2);
  EXPECT_LT(expected, 0.95);
  EXPECT_NEAR(ssim(a, b), expected, 1e-9);

  // Unrelated images, structured ones, and the clipped window of images under 11 pixels on a side.
  const RenderImage unrelated = random_image(40, 30, 7u);
  EXPECT_NEAR(ssim(a, unrelated), direct_ssim(a, unrelated), 1e-9);
  const RenderImage textured = textured_image(40, 30);
  EXPECT_NEAR(ssim(textured, b), direct_ssim(textured, b), 1e-9);
  for (const auto& [width, height] : {std::pair{8, 20}, std::pair{25, 5}, std::pair{6, 3}, std::pair{11, 11}}) {
    const RenderImage small_a = random_image(width, height, 8u);
    const RenderImage small_b = random_image(width, height, 9u);
    EXPECT_NEAR(ssim(small_a, small_b), direct_ssim(small_a, small_b), 1e-9) << width << "x" << height;
  }
}

// The convention, against an outside implementation: scikit-image 0.26.0 (numpy 2.4.6),
//   structural_similarity(a, b, channel_axis=2, gaussian_weights=True, sigma=1.5,
//                         use_sample_covariance=False, data_range=1.0)
// on these two images (built in float64, stored as float32, as here) gives 0.110367157175.
TEST(Ssim, MatchesScikitImage) {
  auto pattern = [](int width, int height, int k) {
    RenderImage image;
    image.width = width;
    image.height = height;
    image.rgba.resize(4 * image.pixels());
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        for (int c = 0; c < 4; ++c) {
          const double value = 0.5 + 0.3 * std::sin(0.37 * x * (k + 1) + c) * std::cos(0.23 * y + k) +
                               0.1 * std::sin(1.7 * x * y + k * c);
          image.rgba[4 * static_cast<size_t>(y * width + x) + static_cast<size_t>(c)] =
              c == 3 ? 1.0f : static_cast<float>(value);
        }
    return image;
  };
  // A last-bit difference between libms may move a pixel by one float ulp: far under this tolerance.
  EXPECT_NEAR(ssim(pattern(64, 48, 0), pattern(64, 48, 1)), 0.110367157175, 1e-8);
}

TEST(Ssim, StructuralNoiseCostsMoreThanABrightnessShiftOfTheSameMse) {
  const RenderImage reference = textured_image(64, 48);
  RenderImage shifted = reference;
  RenderImage noisy = reference;
  std::mt19937 generator(10u);
  std::bernoulli_distribution sign(0.5);
  for (size_t i = 0; i < reference.rgba.size(); ++i) {
    if (i % 4 == 3) continue;
    shifted.rgba[i] += 0.05f;
    noisy.rgba[i] += sign(generator) ? 0.05f : -0.05f;  // |error| 0.05 everywhere: the shift's MSE
  }
  const double shifted_rmse = compare_images(reference, shifted).rmse;
  const double noisy_rmse = compare_images(reference, noisy).rmse;
  ASSERT_NEAR(shifted_rmse, noisy_rmse, 1e-6);

  const double shifted_ssim = ssim(reference, shifted);
  const double noisy_ssim = ssim(reference, noisy);
  EXPECT_LT(shifted_ssim, 1.0);
  EXPECT_LT(noisy_ssim, 1.0);
  EXPECT_GT(shifted_ssim, 0.98);                 // luminance alone: 1 - 0.05^2 / (2 mean^2 + C1)
  EXPECT_LT(noisy_ssim, shifted_ssim - 0.05);    // the same error as structure costs far more

  // More noise, less similarity.
  RenderImage noisier = reference;
  std::mt19937 generator2(10u);
  for (size_t i = 0; i < reference.rgba.size(); ++i)
    if (i % 4 != 3) noisier.rgba[i] += sign(generator2) ? 0.1f : -0.1f;
  EXPECT_LT(ssim(reference, noisier), noisy_ssim);
}

TEST(Ssim, IgnoresAlpha) {
  const RenderImage a = random_image(20, 20, 11u);
  RenderImage b = a;
  for (size_t i = 3; i < b.rgba.size(); i += 4) b.rgba[i] = 0.0f;
  EXPECT_EQ(ssim(a, b), 1.0);
}

TEST(Ssim, RejectsMismatchedOrMalformedImages) {
  const RenderImage a = random_image(12, 12, 12u);
  const RenderImage b = random_image(12, 13, 12u);
  EXPECT_THROW(ssim(a, b), std::invalid_argument);
  try {
    ssim(a, b);
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("12x12"), std::string::npos) << message;
    EXPECT_NE(message.find("12x13"), std::string::npos) << message;
  }
  RenderImage short_rgba = a;
  short_rgba.rgba.resize(7);
  EXPECT_THROW(ssim(a, short_rgba), std::invalid_argument);
  EXPECT_THROW(ssim(short_rgba, a), std::invalid_argument);
  RenderImage negative;
  negative.width = -1;
  negative.height = -1;
  EXPECT_THROW(ssim(negative, negative), std::invalid_argument);

  const RenderImage empty;
  EXPECT_EQ(ssim(empty, empty), 1.0);
}

TEST(Ssim, NonFiniteValuesGiveNaN) {
  const RenderImage a = random_image(16, 16, 13u);
  for (const float poison : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    for (const size_t index : {size_t{0}, size_t{4 * 100 + 2}, size_t{4 * 255 + 3}}) {
      RenderImage poisoned = a;
      poisoned.rgba[index] = poison;
      EXPECT_TRUE(std::isnan(ssim(poisoned, a))) << index;
      EXPECT_TRUE(std::isnan(ssim(a, poisoned))) << index;
    }
  }
}

TEST(Ssim, FullHdTakesWellUnderASecond) {
  const RenderImage a = random_image(1920, 1080, 14u);
  const RenderImage b = random_image(1920, 1080, 15u);
  const auto start = std::chrono::steady_clock::now();
  const double value = ssim(a, b);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(std::isfinite(value));
  EXPECT_LT(std::fabs(value), 0.05);  // independent noise images: next to no similarity
  // Generous against a loaded test machine or a sanitizer build (optimised, it takes about 0.2 s);
  // an unoptimised build is not held to it.
#ifdef NDEBUG
  EXPECT_LT(seconds, 3.0) << "ssim took " << seconds << " s";
#endif
  std::printf("ssim of 1920x1080: %.3f s\n", seconds);
}

// ---------------------------------------------------------------------------------------------
// Temporal stability

RenderImage tiny(std::vector<float> rgb) {  // 2x1, alpha 1
  RenderImage image;
  image.width = 2;
  image.height = 1;
  image.rgba = {rgb[0], rgb[1], rgb[2], 1.0f, rgb[3], rgb[4], rgb[5], 1.0f};
  return image;
}

TEST(TemporalExcess, IsZeroWhenTheSequenceIsTheReference) {
  const RenderImage frame0 = random_image(17, 9, 20u);
  const RenderImage frame1 = random_image(17, 9, 21u);
  const TemporalDifference difference = temporal_excess(frame0, frame1, frame0, frame1);
  EXPECT_EQ(difference.mean_abs, 0.0);
  EXPECT_EQ(difference.flicker_fraction, 0.0);
  EXPECT_GT(frame_change(frame0, frame1), 0.2);  // the frames did change: that change is not excess

  // An error present in both frames alike (a static bias) does not pop either.
  RenderImage biased0 = frame0, biased1 = frame1;
  for (size_t i = 0; i < biased0.rgba.size(); ++i) {
    biased0.rgba[i] += 0.25f;
    biased1.rgba[i] += 0.25f;
  }
  EXPECT_NEAR(temporal_excess(biased0, biased1, frame0, frame1).mean_abs, 0.0, 1e-7);
}

TEST(Popping, SmoothMotionCancelsAndAJumpDoesNot) {
  // Pixel 0 brightens by 0.2 every frame (smooth: a sliding edge, changing shading); pixel 1 holds,
  // then jumps by 0.5 in one step (an order flip).
  const RenderImage f0 = tiny({0.1f, 0.1f, 0.1f, 0.2f, 0.2f, 0.2f});
  const RenderImage f1 = tiny({0.3f, 0.3f, 0.3f, 0.2f, 0.2f, 0.2f});
  const RenderImage f2 = tiny({0.5f, 0.5f, 0.5f, 0.7f, 0.7f, 0.7f});
  const TemporalDifference pops = popping(f0, f1, f2, 0.05);
  EXPECT_EQ(pops.flicker_fraction, 0.5);  // pixel 1 alone
  EXPECT_NEAR(pops.mean_abs, 0.25, 1e-6);  // (0 * 3 + 0.5 * 3) / 6
  // The plain frame change counts both pixels: it cannot tell motion from a pop.
  EXPECT_EQ(temporal_excess(f1, f2, f1, f1, 0.05).flicker_fraction, 1.0);
  const TemporalDifference steady = popping(f0, f1, tiny({0.5f, 0.5f, 0.5f, 0.2f, 0.2f, 0.2f}), 0.05);
  EXPECT_NEAR(steady.mean_abs, 0.0, 1e-6);
  EXPECT_EQ(steady.flicker_fraction, 0.0);
  EXPECT_THROW(popping(f0, f1, random_image(3, 1, 5u)), std::invalid_argument);
}

TEST(TemporalExcess, MatchesHandComputedValues) {
  // Pixel 0: tested changes (+0.5, 0, -0.25), reference (+0.5, +0.125, 0): e = (0, 0.125, 0.25).
  // Pixel 1: tested changes (0, 0, 0), reference (-0.0625, 0, +0.03125):   e = (0.0625, 0, 0.03125).
  const RenderImage a0 = tiny({0.25f, 0.5f, 0.75f, 0.5f, 0.5f, 0.5f});
  const RenderImage a1 = tiny({0.75f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f});
  const RenderImage r0 = tiny({0.0f, 0.0f, 0.0f, 0.5f, 0.25f, 0.0f});
  const RenderImage r1 = tiny({0.5f, 0.125f, 0.0f, 0.4375f, 0.25f, 0.03125f});
  const double mean = (0.125 + 0.25 + 0.0625 + 0.03125) / 6;
  TemporalDifference difference = temporal_excess(a0, a1, r0, r1);
  EXPECT_DOUBLE_EQ(difference.mean_abs, mean);
  // Largest e per pixel: 0.25 and 0.0625, both over 0.05.
  EXPECT_EQ(difference.flicker_fraction, 1.0);
  EXPECT_EQ(temporal_excess(a0, a1, r0, r1, 0.1).flicker_fraction, 0.5);
  EXPECT_EQ(temporal_excess(a0, a1, r0, r1, 0.0625).flicker_fraction, 0.5);  // exceeds: equal is not enough
  EXPECT_EQ(temporal_excess(a0, a1, r0, r1, 0.25).flicker_fraction, 0.0);
  EXPECT_EQ(temporal_excess(a0, a1, r0, r1, 0.0).flicker_fraction, 1.0);
  // Swapping roles (reference <-> tested) flips the sign inside |.|: the same numbers.
  difference = temporal_excess(r0, r1, a0, a1);
  EXPECT_DOUBLE_EQ(difference.mean_abs, mean);

  // Raw change: tested |(0.5, 0, 0.25), (0, 0, 0)|, reference |(0.5, 0.125, 0), (0.0625, 0, 0.03125)|.
  EXPECT_DOUBLE_EQ(frame_change(a0, a1), 0.75 / 6);
  EXPECT_DOUBLE_EQ(frame_change(r0, r1), (0.5 + 0.125 + 0.0625 + 0.03125) / 6);
  // Against a still reference, the excess is the raw change.
  EXPECT_DOUBLE_EQ(temporal_excess(a0, a1, r0, r0).mean_abs, frame_change(a0, a1));
}

TEST(TemporalExcess, FlickerFractionCountsPixelsNotChannels) {
  // 10x10, a still reference; the tested sequence pops 7 pixels: 3 in all channels, 4 in one.
  const RenderImage still = random_image(10, 10, 22u);
  RenderImage popped = still;
  for (const int pixel : {3, 14, 15}) {
    for (int c = 0; c < 3; ++c) popped.rgba[4 * static_cast<size_t>(pixel) + static_cast<size_t>(c)] += 0.3f;
  }
  for (const int pixel : {40, 41, 77, 99}) popped.rgba[4 * static_cast<size_t>(pixel) + 2] -= 0.2f;
  popped.rgba[4 * 50 + 3] += 0.9f;  // alpha is not colour: no popping
  popped.rgba[4 * 60 + 1] += 0.01f; // under the threshold
  const TemporalDifference difference = temporal_excess(still, popped, still, still);
  EXPECT_DOUBLE_EQ(difference.flicker_fraction, 0.07);
  EXPECT_NEAR(difference.mean_abs, (3 * 3 * 0.3 + 4 * 0.2 + 0.01) / 300, 1e-7);
}

TEST(TemporalExcess, RejectsMismatchedImagesAndBadThresholdsAndPoisonsOnNonFinite) {
  const RenderImage a = random_image(6, 4, 23u);
  const RenderImage b = random_image(6, 4, 24u);
  const RenderImage other = random_image(4, 6, 25u);
  EXPECT_THROW(temporal_excess(a, b, a, other), std::invalid_argument);
  EXPECT_THROW(temporal_excess(other, b, a, b), std::invalid_argument);
  EXPECT_THROW(frame_change(a, other), std::invalid_argument);
  RenderImage short_rgba = a;
  short_rgba.rgba.pop_back();
  EXPECT_THROW(temporal_excess(a, b, short_rgba, b), std::invalid_argument);
  EXPECT_THROW(frame_change(short_rgba, a), std::invalid_argument);
  EXPECT_THROW(temporal_excess(a, b, a, b, -0.1), std::invalid_argument);
  EXPECT_THROW(temporal_excess(a, b, a, b, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);

  RenderImage poisoned = b;
  poisoned.rgba[5] = std::numeric_limits<float>::quiet_NaN();
  const TemporalDifference difference = temporal_excess(a, b, a, poisoned);
  EXPECT_TRUE(std::isnan(difference.mean_abs));
  EXPECT_TRUE(std::isnan(difference.flicker_fraction));
  EXPECT_TRUE(std::isnan(frame_change(poisoned, a)));

  const RenderImage empty;
  EXPECT_EQ(temporal_excess(empty, empty, empty, empty).mean_abs, 0.0);
  EXPECT_EQ(frame_change(empty, empty), 0.0);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// rotation_inconsistency: a renderer whose colour is a function of the world ray alone is consistent.

namespace rotation {

using tilesplat::Camera;
using tilesplat::rotation_inconsistency;

Camera camera(double yaw) {
  Camera c;
  c.width = 160;
  c.height = 96;
  c.fx = c.fy = 140;
  c.cx = 80;
  c.cy = 48;
  c.position = {0.5, -0.25, 2};
  // x_cam = R_y(yaw) x_world: turning in place about the camera's y axis.
  c.rotation = {std::cos(yaw), 0, std::sin(yaw), 0, 1, 0, -std::sin(yaw), 0, std::cos(yaw)};
  return c;
}

// Renders colour(world direction) at each pixel centre, as a view-consistent renderer would.
template <typename Colour>
RenderImage render_rays(const Camera& c, Colour colour) {
  RenderImage image;
  image.width = c.width;
  image.height = c.height;
  image.rgba.resize(4 * image.pixels());
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      const double d[3] = {(x + 0.5 - c.cx) / c.fx, (y + 0.5 - c.cy) / c.fy, 1};
      double w[3] = {0, 0, 0};
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) w[r] += c.rotation[3 * k + r] * d[k];
      const double n = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
      const std::array<double, 3> rgb = colour(w[0] / n, w[1] / n, w[2] / n);
      for (int ch = 0; ch < 3; ++ch) image.rgba[4 * (size_t(y) * c.width + x) + ch] = float(rgb[ch]);
      image.rgba[4 * (size_t(y) * c.width + x) + 3] = 1.0f;
    }
  return image;
}

std::array<double, 3> smooth(double x, double y, double z) {
  return {0.5 + 0.4 * std::sin(6 * x), 0.5 + 0.4 * std::cos(5 * y + z), 0.5 + 0.3 * std::sin(4 * x + 3 * y)};
}

// A hard edge fixed in the world: what per-pixel re-sorting draws where two splats' ray depths cross.
std::array<double, 3> edge(double x, double y, double) {
  const double v = x + 0.3 * y > 0.05 ? 0.8 : 0.2;
  return {v, v, v};
}

// The blocks of b whose pixel centres all look along rays that a sees between its outer pixel centres.
int blocks_inside(const Camera& a, const Camera& b, int block) {
  int kept = 0;
  for (int by = 0; by + block <= b.height; by += block)
    for (int bx = 0; bx + block <= b.width; bx += block) {
      bool inside = true;
      for (int y = by; y < by + block; ++y)
        for (int x = bx; x < bx + block; ++x) {
          const double d[3] = {(x + 0.5 - b.cx) / b.fx, (y + 0.5 - b.cy) / b.fy, 1};
          double w[3] = {0, 0, 0}, in_a[3] = {0, 0, 0};
          for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k) w[r] += b.rotation[3 * k + r] * d[k];
          for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k) in_a[r] += a.rotation[3 * r + k] * w[k];
          const double u = a.fx * in_a[0] / in_a[2] + a.cx - 0.5, v = a.fy * in_a[1] / in_a[2] + a.cy - 0.5;
          inside = inside && u >= 0 && v >= 0 && u <= a.width - 1 && v <= a.height - 1;
        }
      kept += inside ? 1 : 0;
    }
  return kept;
}

}  // namespace rotation

TEST(RotationInconsistency, AConsistentRendererScoresZeroWhateverTheTurn) {
  using namespace rotation;
  const Camera a = camera(0), b = camera(0.08);
  const RenderImage image_a = render_rays(a, smooth), image_b = render_rays(b, smooth);
  // The turn moved the image by about 11 pixels: the plain difference is large.
  EXPECT_GT(frame_change(image_a, image_b), 0.02);
  const TemporalDifference consistent = rotation_inconsistency(image_a, a, image_b, b, 4);
  EXPECT_EQ(consistent.flicker_fraction, 0.0);
  EXPECT_LT(consistent.mean_abs, 2e-4);  // bilinear resampling of a smooth function
  // The same camera twice: exactly nothing.
  const TemporalDifference same = rotation_inconsistency(image_a, a, image_a, a, 1);
  EXPECT_LT(same.mean_abs, 1e-12);  // the pixel's ray there and back, in doubles
  EXPECT_EQ(same.flicker_fraction, 0.0);
}

TEST(RotationInconsistency, BlocksAverageAwayTheResamplingOfAHardEdgeButNotAChangedRegion) {
  using namespace rotation;
  const Camera a = camera(0), b = camera(0.05);
  const RenderImage edge_a = render_rays(a, edge), edge_b = render_rays(b, edge);
  // Per pixel, resampling the edge misses along it; over 8x8 blocks those misses average out.
  EXPECT_GT(rotation_inconsistency(edge_a, a, edge_b, b, 1, 0.05).flicker_fraction, 0.003);
  EXPECT_EQ(rotation_inconsistency(edge_a, a, edge_b, b, 8, 0.05).flicker_fraction, 0.0);

  // A region of b that changed where nothing moved (an order flip in centre-depth blending): the
  // blocks wholly inside it count, at full size.
  RenderImage flipped = render_rays(b, smooth);
  for (int y = 32; y < 64; ++y)
    for (int x = 40; x < 88; ++x)
      for (int c = 0; c < 3; ++c) flipped.rgba[4 * (size_t(y) * b.width + x) + c] += 0.1f;
  const RenderImage smooth_a = render_rays(a, smooth);
  const TemporalDifference popped = rotation_inconsistency(smooth_a, a, flipped, b, 8, 0.05);
  // b's blocks whose samples all land inside a: the turned camera sees new columns at one side.
  const int kept_blocks = blocks_inside(a, b, 8);
  EXPECT_LT(kept_blocks, (b.width / 8) * (b.height / 8));
  EXPECT_NEAR(popped.flicker_fraction, (4.0 * 6.0) / kept_blocks, 1e-12);
  EXPECT_NEAR(popped.mean_abs, 0.1 * (4.0 * 6.0) / kept_blocks, 2e-4);
}

TEST(RotationInconsistency, RefusesCamerasThatDoNotDifferByARotationAndPropagatesNaN) {
  using namespace rotation;
  const Camera a = camera(0), b = camera(0.05);
  const RenderImage image_a = render_rays(a, smooth), image_b = render_rays(b, smooth);
  Camera moved = b;
  moved.position[0] += 0.1;
  EXPECT_THROW(rotation_inconsistency(image_a, a, image_b, moved, 4), std::invalid_argument);
  Camera zoomed = b;
  zoomed.fx *= 1.1;
  EXPECT_THROW(rotation_inconsistency(image_a, a, image_b, zoomed, 4), std::invalid_argument);
  EXPECT_THROW(rotation_inconsistency(image_a, a, image_b, b, 0), std::invalid_argument);
  EXPECT_THROW(rotation_inconsistency(image_a, a, image_b, b, 4, -1), std::invalid_argument);
  EXPECT_THROW(rotation_inconsistency(image_a, a, random_image(8, 8, 3u), b, 4), std::invalid_argument);
  Camera small = b;
  small.width = 80;
  EXPECT_THROW(rotation_inconsistency(image_a, a, image_b, small, 4), std::invalid_argument);
  RenderImage broken = image_b;
  broken.rgba[4 * 500 + 1] = std::numeric_limits<float>::quiet_NaN();
  const TemporalDifference nan = rotation_inconsistency(image_a, a, broken, b, 4);
  EXPECT_TRUE(std::isnan(nan.mean_abs));
  EXPECT_TRUE(std::isnan(nan.flicker_fraction));
}

// depth_warp_difference: a plane at depth 5 seen by two cameras 0.1 apart sideways (fx 50), so that
// pixel x of b sees what pixel x + 1 of a sees.
namespace warp {

using tilesplat::Camera;
using tilesplat::depth_warp_difference;

Camera camera(double x) {
  Camera c;
  c.width = 64;
  c.height = 32;
  c.fx = c.fy = 50;
  c.cx = 32;
  c.cy = 16;
  c.position = {x, 0, 0};
  return c;
}

// Red = 0.01 (column + shift), opaque, at depth 5: the plane's colour is a function of the world point.
RenderImage plane(int shift) {
  RenderImage image;
  image.width = 64;
  image.height = 32;
  image.rgba.assign(4 * image.pixels(), 0.0f);
  image.depth.assign(image.pixels(), 5.0f);
  for (size_t i = 0; i < image.pixels(); ++i) {
    image.rgba[4 * i] = 0.01f * float(int(i % 64) + shift);
    image.rgba[4 * i + 1] = 0.5f;
    image.rgba[4 * i + 3] = 1.0f;
  }
  return image;
}

}  // namespace warp

TEST(DepthWarpDifference, AStillSceneWarpsOntoItselfAndAChangedBlockStays) {
  using namespace warp;
  const Camera a = camera(0), b = camera(0.1);
  const RenderImage image_a = plane(0);
  RenderImage image_b = plane(1);
  // Columns 0..62 of b land inside a (u = x + 1); the last block of each row reaches u = 64 and is left out.
  const TemporalDifference still = depth_warp_difference(image_a, a, image_b, b, 8);
  EXPECT_NEAR(still.mean_abs, 0.0, 1e-6);
  EXPECT_EQ(still.flicker_fraction, 0.0);
  // One block of b changes colour where the scene did not move: one of the 7 x 4 blocks kept.
  for (int y = 8; y < 16; ++y)
    for (int x = 8; x < 16; ++x) image_b.rgba[4 * size_t(y * 64 + x) + 2] += 0.5f;
  const TemporalDifference popped = depth_warp_difference(image_a, a, image_b, b, 8);
  EXPECT_NEAR(popped.flicker_fraction, 1.0 / 28.0, 1e-12);
  EXPECT_NEAR(popped.mean_abs, 0.5 / 3.0 / 28.0, 1e-6);
}

TEST(DepthWarpDifference, WhatTheMotionRevealsOrHidesIsLeftOut) {
  using namespace warp;
  const Camera a = camera(0), b = camera(0.1);
  RenderImage image_a = plane(0);
  RenderImage image_b = plane(1);
  // In a, something nearer covers columns 20..23: b's points there are hidden from a. Their pixels (x + 1
  // or x + 2 in 20..23: x 18..22) leave blocks 16..23 of every row out, changed colour and all.
  for (int y = 0; y < 32; ++y)
    for (int x = 20; x < 24; ++x) {
      image_a.depth[size_t(y * 64 + x)] = 2.0f;
      image_a.rgba[4 * size_t(y * 64 + x)] = 1.0f;
    }
  const TemporalDifference hidden = depth_warp_difference(image_a, a, image_b, b, 8, 0.01);
  EXPECT_EQ(hidden.flicker_fraction, 0.0);
  // A half-covered pixel of b (alpha < 0.5) has no trusted depth: its block is left out too, so one
  // changed block among the 24 kept counts 1/23 once another block is dropped that way.
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) image_b.rgba[4 * size_t(y * 64 + x) + 2] += 0.5f;
  image_b.rgba[4 * size_t(9 * 64 + 9) + 3] = 0.25f;
  const TemporalDifference one = depth_warp_difference(image_a, a, image_b, b, 8, 0.01);
  EXPECT_NEAR(one.flicker_fraction, 1.0 / 23.0, 1e-12);
}

TEST(DepthWarpDifference, RefusesImagesWithoutDepthAndOtherCameraModels) {
  using namespace warp;
  const Camera a = camera(0), b = camera(0.1);
  const RenderImage image_a = plane(0), image_b = plane(1);
  RenderImage flat = image_b;
  flat.depth.clear();
  EXPECT_THROW(depth_warp_difference(image_a, a, flat, b, 8), std::invalid_argument);
  Camera fisheye = b;
  fisheye.model = tilesplat::CameraModel::kFisheye;
  EXPECT_THROW(depth_warp_difference(image_a, a, image_b, fisheye, 8), std::invalid_argument);
  EXPECT_THROW(depth_warp_difference(image_a, a, image_b, b, 0), std::invalid_argument);
  EXPECT_THROW(depth_warp_difference(image_a, a, image_b, b, 8, 0.01, -1), std::invalid_argument);
  RenderImage broken = image_b;
  broken.rgba[1] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_TRUE(std::isnan(depth_warp_difference(image_a, a, broken, b, 8).mean_abs));
}
