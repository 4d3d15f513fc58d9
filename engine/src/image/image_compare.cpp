// Differences between two RenderImages, as used by the tests and the reference comparisons.
#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "tilesplat/image.h"

namespace tilesplat {
namespace {

std::string size_text(const RenderImage& image) {
  return std::to_string(image.width) + "x" + std::to_string(image.height);
}

void check_comparable(const RenderImage& image, const char* function, const char* which) {
  if (image.width < 0 || image.height < 0)
    throw std::invalid_argument(std::string(function) + ": image " + which + " has a negative size " +
                                size_text(image));
  if (image.rgba.size() != 4 * image.pixels())
    throw std::invalid_argument(std::string(function) + ": image " + which + " (" + size_text(image) +
                                ") holds " + std::to_string(image.rgba.size()) + " rgba values, expected " +
                                std::to_string(4 * image.pixels()));
}

// Checks a sequence of images for a function that compares them value by value: one size, the rgba
// layout. names[i] names images[i] in the messages.
void check_same_size(const char* function, std::initializer_list<const RenderImage*> images,
                     std::initializer_list<const char*> names) {
  const RenderImage& first = **images.begin();
  auto name = names.begin();
  for (const RenderImage* image : images) {
    if (image->width != first.width || image->height != first.height)
      throw std::invalid_argument(std::string(function) + ": sizes differ: " + *names.begin() + " is " +
                                  size_text(first) + ", " + *name + " is " + size_text(*image));
    ++name;
  }
  name = names.begin();
  for (const RenderImage* image : images) check_comparable(*image, function, *name++);
}

bool all_finite(const RenderImage& image) {
  for (const float value : image.rgba)
    if (!std::isfinite(value)) return false;
  return true;
}

// The SSIM window along one dimension of n pixels: the Gaussian of sigma 1.5 sampled at 11 taps
// around the centre one, normalised to sum 1. Where n < 11 the window is clipped to the image: n taps
// placed symmetrically around the image's centre (a half-pixel offset when n is even), renormalised,
// so that the whole dimension is one window position rather than no SSIM at all.
std::vector<double> ssim_window(int n) {
  constexpr int kTaps = 11;
  constexpr double kSigma = 1.5;
  const int taps = std::min(n, kTaps);
  std::vector<double> weights(static_cast<size_t>(taps));
  const double centre = 0.5 * (taps - 1);
  double sum = 0;
  for (int i = 0; i < taps; ++i) {
    const double offset = i - centre;
    weights[static_cast<size_t>(i)] = std::exp(-offset * offset / (2 * kSigma * kSigma));
    sum += weights[static_cast<size_t>(i)];
  }
  for (double& weight : weights) weight /= sum;
  return weights;
}

}  // namespace

ImageDifference compare_images(const RenderImage& a, const RenderImage& b) {
  if (a.width != b.width || a.height != b.height)
    throw std::invalid_argument("compare_images: sizes differ: " + size_text(a) + " vs " + size_text(b));
  check_comparable(a, "compare_images", "a");
  check_comparable(b, "compare_images", "b");

  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  ImageDifference difference;
  const size_t pixels = a.pixels();
  double squared_error_sum = 0;
  bool found_non_finite = false;
  for (size_t pixel = 0; pixel < pixels && !found_non_finite; ++pixel) {
    for (int c = 0; c < 4; ++c) {
      const size_t index = 4 * pixel + static_cast<size_t>(c);
      const double value_a = a.rgba[index];
      const double value_b = b.rgba[index];
      const int x = static_cast<int>(pixel % static_cast<size_t>(a.width));
      const int y = static_cast<int>(pixel / static_cast<size_t>(a.width));
      // A NaN or infinity means the renderer is broken; left alone it would vanish into max() or
      // turn the PSNR into NaN that some callers might not check for, so it poisons every metric.
      if (!std::isfinite(value_a) || !std::isfinite(value_b)) {
        found_non_finite = true;
        difference.worst_x = x;
        difference.worst_y = y;
        difference.worst_channel = c;
        break;
      }
      const double abs_error = std::fabs(value_a - value_b);
      if (c == 3) {
        if (abs_error > difference.max_abs_alpha) difference.max_abs_alpha = abs_error;
        continue;
      }
      squared_error_sum += abs_error * abs_error;
      if (abs_error > difference.max_abs) {
        difference.max_abs = abs_error;
        difference.worst_x = x;
        difference.worst_y = y;
        difference.worst_channel = c;
      }
    }
  }

  if (found_non_finite) {
    difference.psnr_db = -kInfinity;
    difference.max_abs = kInfinity;
    difference.max_abs_alpha = kInfinity;
    difference.rmse = kInfinity;
    return difference;
  }
  const double mean_squared_error =
      pixels == 0 ? 0.0 : squared_error_sum / (3.0 * static_cast<double>(pixels));
  difference.rmse = std::sqrt(mean_squared_error);
  difference.psnr_db = mean_squared_error == 0.0 ? kInfinity : 10.0 * std::log10(1.0 / mean_squared_error);
  return difference;
}

double ssim(const RenderImage& a, const RenderImage& b) {
  check_same_size("ssim", {&a, &b}, {"a", "b"});
  if (!all_finite(a) || !all_finite(b)) return std::numeric_limits<double>::quiet_NaN();
  if (a.pixels() == 0) return 1.0;

  constexpr double kC1 = 0.01 * 0.01;  // (K1 L)^2 with L = 1
  constexpr double kC2 = 0.03 * 0.03;  // (K2 L)^2
  // The window's weighted means of five quantities: x, y, x^2, y^2 and (x - y)^2. The last one
  // instead of xy, because SSIM's two factors are 1 minus a difference term,
  //   (2 mx my + C1) / (mx^2 + my^2 + C1) = 1 - (mx - my)^2 / (mx^2 + my^2 + C1),
  //   (2 sxy + C2) / (sx^2 + sy^2 + C2)   = 1 - var(x - y) / (sx^2 + sy^2 + C2),
  // and computing those differences from x - y directly keeps them exact where the images agree:
  // identical images score exactly 1, and nearly identical ones (the accurate modes that matter
  // most) do not lose their small differences to the cancellation of 2 sxy against sx^2 + sy^2.
  constexpr size_t kQuantities = 5;
  const size_t width = static_cast<size_t>(a.width);
  const size_t height = static_cast<size_t>(a.height);
  const std::vector<double> window_x = ssim_window(a.width);
  const std::vector<double> window_y = ssim_window(a.height);
  const size_t taps_x = window_x.size();
  const size_t taps_y = window_y.size();
  const size_t out_width = width - taps_x + 1;  // the 'valid' region: where the whole window fits
  const size_t out_height = height - taps_y + 1;

  // Separable: each row is filtered horizontally once into a ring of the last taps_y rows, and
  // each output row filters that ring vertically. Loops run along rows so that they vectorise.
  std::vector<double> row(kQuantities * width);
  std::vector<double> ring(taps_y * kQuantities * out_width);
  std::vector<double> filtered(kQuantities * out_width);
  double sum = 0;
  for (size_t channel = 0; channel < 3; ++channel) {
    for (size_t y = 0; y < height; ++y) {
      for (size_t x = 0; x < width; ++x) {
        const double value_a = a.rgba[4 * (y * width + x) + channel];
        const double value_b = b.rgba[4 * (y * width + x) + channel];
        const double difference = value_a - value_b;
        row[x] = value_a;
        row[width + x] = value_b;
        row[2 * width + x] = value_a * value_a;
        row[3 * width + x] = value_b * value_b;
        row[4 * width + x] = difference * difference;
      }
      double* const slot = &ring[(y % taps_y) * kQuantities * out_width];
      for (size_t q = 0; q < kQuantities; ++q) {
        double* const out = slot + q * out_width;
        const double* const in = &row[q * width];
        // The window is symmetric: pairs of taps share a multiply.
        const double centre_weight = window_x[taps_x / 2];
        if (taps_x % 2 == 1)
          for (size_t x = 0; x < out_width; ++x) out[x] = centre_weight * in[x + taps_x / 2];
        else
          std::fill(out, out + out_width, 0.0);
        for (size_t t = 0; t < taps_x / 2; ++t) {
          const double weight = window_x[t];
          const double* const mirrored = in + (taps_x - 1 - t);
          for (size_t x = 0; x < out_width; ++x) out[x] += weight * (in[x + t] + mirrored[x]);
        }
      }
      if (y + 1 < taps_y) continue;

      const size_t out_y = y + 1 - taps_y;
      const size_t row_size = kQuantities * out_width;
      auto ring_row = [&](size_t t) { return &ring[((out_y + t) % taps_y) * row_size]; };
      if (taps_y % 2 == 1) {
        const double centre_weight = window_y[taps_y / 2];
        const double* const in = ring_row(taps_y / 2);
        for (size_t i = 0; i < row_size; ++i) filtered[i] = centre_weight * in[i];
      } else {
        std::fill(filtered.begin(), filtered.end(), 0.0);
      }
      for (size_t t = 0; t < taps_y / 2; ++t) {
        const double weight = window_y[t];
        const double* const in = ring_row(t);
        const double* const mirrored = ring_row(taps_y - 1 - t);
        for (size_t i = 0; i < row_size; ++i) filtered[i] += weight * (in[i] + mirrored[i]);
      }
      double row_sum = 0;
      for (size_t x = 0; x < out_width; ++x) {
        const double mean_a = filtered[x];
        const double mean_b = filtered[out_width + x];
        const double variance_sum =
            (filtered[2 * out_width + x] - mean_a * mean_a) + (filtered[3 * out_width + x] - mean_b * mean_b);
        const double mean_difference = mean_a - mean_b;
        const double squared_mean_difference = mean_difference * mean_difference;
        // var(x - y) >= 0; only rounding takes it below, and then SSIM would exceed 1.
        const double difference_variance = std::max(0.0, filtered[4 * out_width + x] - squared_mean_difference);
        const double luminance = 1.0 - squared_mean_difference / (mean_a * mean_a + mean_b * mean_b + kC1);
        const double contrast_structure = 1.0 - difference_variance / (variance_sum + kC2);
        row_sum += luminance * contrast_structure;
      }
      sum += row_sum;
    }
  }
  return sum / (3.0 * static_cast<double>(out_width) * static_cast<double>(out_height));
}

namespace {

// e = |(a1 - a0) - (r1 - r0)| over RGB, or |a1 - a0| without a reference; NaN results for a
// non-finite value, as the header promises.
TemporalDifference temporal_difference(const RenderImage& a0, const RenderImage& a1, const RenderImage* r0,
                                       const RenderImage* r1, double threshold) {
  TemporalDifference result;
  if (!all_finite(a0) || !all_finite(a1) || (r0 && (!all_finite(*r0) || !all_finite(*r1)))) {
    result.mean_abs = std::numeric_limits<double>::quiet_NaN();
    result.flicker_fraction = std::numeric_limits<double>::quiet_NaN();
    return result;
  }
  const size_t pixels = a0.pixels();
  if (pixels == 0) return result;
  double sum = 0;
  size_t flickering = 0;
  for (size_t pixel = 0; pixel < pixels; ++pixel) {
    double largest = 0;
    for (size_t c = 0; c < 3; ++c) {
      const size_t index = 4 * pixel + c;
      double change = double{a1.rgba[index]} - double{a0.rgba[index]};
      if (r0) change -= double{r1->rgba[index]} - double{r0->rgba[index]};
      const double excess = std::fabs(change);
      sum += excess;
      largest = std::max(largest, excess);
    }
    if (largest > threshold) ++flickering;
  }
  result.mean_abs = sum / (3.0 * static_cast<double>(pixels));
  result.flicker_fraction = static_cast<double>(flickering) / static_cast<double>(pixels);
  return result;
}

}  // namespace

TemporalDifference temporal_excess(const RenderImage& a0, const RenderImage& a1, const RenderImage& r0,
                                   const RenderImage& r1, double threshold) {
  check_same_size("temporal_excess", {&a0, &a1, &r0, &r1}, {"a0", "a1", "r0", "r1"});
  if (!std::isfinite(threshold) || threshold < 0)
    throw std::invalid_argument("temporal_excess: the threshold must be finite and >= 0, got " +
                                std::to_string(threshold));
  return temporal_difference(a0, a1, &r0, &r1, threshold);
}

TemporalDifference popping(const RenderImage& a0, const RenderImage& a1, const RenderImage& a2, double threshold) {
  check_same_size("popping", {&a0, &a1, &a2}, {"a0", "a1", "a2"});
  return temporal_excess(a1, a2, a0, a1, threshold);
}

double frame_change(const RenderImage& a0, const RenderImage& a1) {
  check_same_size("frame_change", {&a0, &a1}, {"a0", "a1"});
  return temporal_difference(a0, a1, nullptr, nullptr, 0).mean_abs;
}

namespace {

// The camera-space direction of pixel (x, y)'s centre turned into world space: R^T K^-1 (x + 0.5, y + 0.5, 1).
std::array<double, 3> pixel_ray(const Camera& camera, double x, double y) {
  const double d[3] = {(x + 0.5 - camera.cx) / camera.fx, (y + 0.5 - camera.cy) / camera.fy, 1.0};
  std::array<double, 3> world{};
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) world[r] += camera.rotation[3 * k + r] * d[k];
  return world;
}

// Two images and the cameras that framed them: valid cameras of the images' (equal) size.
void check_framed_pair(const char* function, const RenderImage& a, const Camera& camera_a,
                       const RenderImage& b, const Camera& camera_b) {
  check_same_size(function, {&a, &b}, {"a", "b"});
  validate(camera_a);
  validate(camera_b);
  if (camera_a.width != a.width || camera_a.height != a.height || camera_b.width != a.width ||
      camera_b.height != a.height)
    throw std::invalid_argument(std::string(function) + ": the images are " + size_text(a) +
                                ", the cameras " + std::to_string(camera_a.width) + "x" +
                                std::to_string(camera_a.height) + " and " + std::to_string(camera_b.width) +
                                "x" + std::to_string(camera_b.height));
}

// The per-pixel differences (RGB) averaged over blocks of block x block pixels, the blocks with a pixel
// not `inside` left out: mean_abs over the blocks kept and RGB, flicker_fraction the fraction of them
// whose largest channel exceeds the threshold.
TemporalDifference block_statistics(const std::vector<std::array<double, 3>>& difference,
                                    const std::vector<char>& inside, int width, int height, int block,
                                    double threshold) {
  TemporalDifference result;
  double sum = 0;
  size_t kept = 0, over = 0;
  for (int by = 0; by + block <= height; by += block) {
    for (int bx = 0; bx + block <= width; bx += block) {
      std::array<double, 3> mean{};
      bool complete = true;
      for (int y = by; y < by + block && complete; ++y)
        for (int x = bx; x < bx + block; ++x) {
          const size_t pixel = size_t(y) * size_t(width) + size_t(x);
          if (!inside[pixel]) {
            complete = false;
            break;
          }
          for (int c = 0; c < 3; ++c) mean[c] += difference[pixel][c];
        }
      if (!complete) continue;
      double largest = 0;
      for (double& channel : mean) {
        channel = std::fabs(channel) / double(block * block);
        sum += channel;
        largest = std::max(largest, channel);
      }
      ++kept;
      if (largest > threshold) ++over;
    }
  }
  if (kept == 0) return result;
  result.mean_abs = sum / (3.0 * double(kept));
  result.flicker_fraction = double(over) / double(kept);
  return result;
}

TemporalDifference not_a_number() {
  TemporalDifference result;
  result.mean_abs = std::numeric_limits<double>::quiet_NaN();
  result.flicker_fraction = std::numeric_limits<double>::quiet_NaN();
  return result;
}

// The blocks and threshold of block_statistics: a block of at least one pixel, a finite threshold >= 0.
void check_blocks(const char* function, int block, double threshold) {
  if (block < 1)
    throw std::invalid_argument(std::string(function) + ": block must be >= 1, got " + std::to_string(block));
  if (!std::isfinite(threshold) || threshold < 0)
    throw std::invalid_argument(std::string(function) + ": the threshold must be finite and >= 0, got " +
                                std::to_string(threshold));
}

// Where a point in camera space lands in the camera's image of width x height pixels, in continuous
// coordinates with pixel centres on the integers; nothing when it is not in front of the camera or
// lies outside the outer pixel centres (so that all four neighbours exist).
std::optional<std::array<double, 2>> image_point(const Camera& camera, const std::array<double, 3>& in_camera,
                                                 int width, int height) {
  if (!(in_camera[2] > 0)) return std::nullopt;
  const double u = camera.fx * in_camera[0] / in_camera[2] + camera.cx - 0.5;
  const double v = camera.fy * in_camera[1] / in_camera[2] + camera.cy - 0.5;
  if (!(u >= 0 && v >= 0 && u <= width - 1 && v <= height - 1)) return std::nullopt;
  return std::array<double, 2>{u, v};
}

// The 2x2 pixels around an image point (image_point) and its bilinear weights.
struct Neighbourhood {
  int x0, y0, x1, y1;
  double fx, fy;
};
Neighbourhood neighbourhood(const std::array<double, 2>& point, int width, int height) {
  const int x0 = std::min(int(point[0]), std::max(width - 2, 0));
  const int y0 = std::min(int(point[1]), std::max(height - 2, 0));
  return {x0, y0, std::min(x0 + 1, width - 1), std::min(y0 + 1, height - 1), point[0] - x0, point[1] - y0};
}

// b - a resampled bilinearly at the neighbourhood, per RGB channel, for pixel `pixel` of b.
std::array<double, 3> difference_to(const RenderImage& a, const Neighbourhood& n, const RenderImage& b,
                                    size_t pixel) {
  auto at = [&](int px, int py, int c) {
    return double{a.rgba[4 * (size_t(py) * size_t(a.width) + size_t(px)) + size_t(c)]};
  };
  std::array<double, 3> difference{};
  for (int c = 0; c < 3; ++c) {
    const double warped = (1 - n.fy) * ((1 - n.fx) * at(n.x0, n.y0, c) + n.fx * at(n.x1, n.y0, c)) +
                          n.fy * ((1 - n.fx) * at(n.x0, n.y1, c) + n.fx * at(n.x1, n.y1, c));
    difference[size_t(c)] = double{b.rgba[4 * pixel + size_t(c)]} - warped;
  }
  return difference;
}

}  // namespace

TemporalDifference rotation_inconsistency(const RenderImage& a, const Camera& camera_a, const RenderImage& b,
                                          const Camera& camera_b, int block, double threshold) {
  constexpr const char* kFunction = "rotation_inconsistency";
  check_framed_pair(kFunction, a, camera_a, b, camera_b);
  if (camera_a.fx != camera_b.fx || camera_a.fy != camera_b.fy || camera_a.cx != camera_b.cx ||
      camera_a.cy != camera_b.cy || camera_a.position != camera_b.position)
    throw std::invalid_argument(std::string(kFunction) +
                                ": the cameras must differ by a rotation alone (same intrinsics and position)");
  check_blocks(kFunction, block, threshold);
  if (!all_finite(a) || !all_finite(b)) return not_a_number();
  const int width = a.width, height = a.height;
  // Per pixel of b: b - warp(a) over RGB, and whether the ray landed inside a (with its 2x2 neighbourhood).
  std::vector<std::array<double, 3>> difference(b.pixels());
  std::vector<char> inside(b.pixels(), 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::array<double, 3> world = pixel_ray(camera_b, x, y);
      std::array<double, 3> in_a{};
      for (size_t r = 0; r < 3; ++r)
        for (size_t k = 0; k < 3; ++k) in_a[r] += camera_a.rotation[3 * r + k] * world[k];
      const auto point = image_point(camera_a, in_a, width, height);
      if (!point) continue;
      const size_t pixel = size_t(y) * size_t(width) + size_t(x);
      difference[pixel] = difference_to(a, neighbourhood(*point, width, height), b, pixel);
      inside[pixel] = 1;
    }
  }
  return block_statistics(difference, inside, width, height, block, threshold);
}

TemporalDifference depth_warp_difference(const RenderImage& a, const Camera& camera_a, const RenderImage& b,
                                         const Camera& camera_b, int block, double threshold,
                                         double depth_tolerance) {
  constexpr const char* kFunction = "depth_warp_difference";
  check_framed_pair(kFunction, a, camera_a, b, camera_b);
  if (camera_a.model != CameraModel::kPinhole || camera_b.model != CameraModel::kPinhole)
    throw std::invalid_argument(std::string(kFunction) + ": the cameras must be pinhole cameras");
  if (a.depth.size() != a.pixels() || b.depth.size() != b.pixels())
    throw std::invalid_argument(std::string(kFunction) +
                                ": both images need their depth (RenderSettings::depth)");
  check_blocks(kFunction, block, threshold);
  if (!std::isfinite(depth_tolerance) || depth_tolerance < 0)
    throw std::invalid_argument(std::string(kFunction) +
                                ": the depth tolerance must be finite and >= 0, got " +
                                std::to_string(depth_tolerance));
  if (!all_finite(a) || !all_finite(b)) return not_a_number();
  const int width = a.width, height = a.height;
  auto depth_at = [&](const RenderImage& image, int x, int y) {
    return double{image.depth[size_t(y) * size_t(width) + size_t(x)]};
  };
  std::vector<std::array<double, 3>> difference(b.pixels());
  std::vector<char> inside(b.pixels(), 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t pixel = size_t(y) * size_t(width) + size_t(x);
      const double z_b = depth_at(b, x, y);
      if (!(b.rgba[4 * pixel + 3] >= 0.5f) || !(z_b > 0) || !std::isfinite(z_b)) continue;
      // The world point at depth z_b on the ray through the pixel's centre, in a's camera space.
      const std::array<double, 3> ray = pixel_ray(camera_b, x, y);  // camera z = 1
      std::array<double, 3> in_a{};
      for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 3; ++k)
          in_a[size_t(r)] +=
              camera_a.rotation[size_t(3 * r + k)] *
              (camera_b.position[size_t(k)] + z_b * ray[size_t(k)] - camera_a.position[size_t(k)]);
      }
      const auto point = image_point(camera_a, in_a, width, height);
      if (!point) continue;
      // a sees the point where its depth at all four neighbours agrees with the point's.
      const Neighbourhood n = neighbourhood(*point, width, height);
      bool seen = true;
      for (int neighbour_y : {n.y0, n.y1})
        for (int neighbour_x : {n.x0, n.x1})
          seen =
              seen && std::fabs(depth_at(a, neighbour_x, neighbour_y) - in_a[2]) <= depth_tolerance * in_a[2];
      if (!seen) continue;
      difference[pixel] = difference_to(a, n, b, pixel);
      inside[pixel] = 1;
    }
  }
  return block_statistics(difference, inside, width, height, block, threshold);
}

}  // namespace tilesplat
