// Differences between two RenderImages, as used by the tests and the reference comparisons.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "tilesplat/image.h"

namespace tilesplat {
namespace {

std::string size_text(const RenderImage& image) {
  return std::to_string(image.width) + "x" + std::to_string(image.height);
}

void check_comparable(const RenderImage& image, const char* which) {
  if (image.width < 0 || image.height < 0)
    throw std::invalid_argument(std::string("compare_images: image ") + which + " has a negative size " +
                                size_text(image));
  if (image.rgba.size() != 4 * image.pixels())
    throw std::invalid_argument(std::string("compare_images: image ") + which + " (" + size_text(image) +
                                ") holds " + std::to_string(image.rgba.size()) + " rgba values, expected " +
                                std::to_string(4 * image.pixels()));
}

}  // namespace

ImageDifference compare_images(const RenderImage& a, const RenderImage& b) {
  if (a.width != b.width || a.height != b.height)
    throw std::invalid_argument("compare_images: sizes differ: " + size_text(a) + " vs " + size_text(b));
  check_comparable(a, "a");
  check_comparable(b, "b");

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

}  // namespace tilesplat
