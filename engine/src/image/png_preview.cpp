// 8-bit sRGB PNG previews of RenderImages (the trained display values, graded on request), written with
// libpng's simplified API.
#include <png.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "image/atomic_file.h"
#include "tilesplat/image.h"

namespace tilesplat {
namespace {

// The trained colour as it is, unless graded: grading happens in linear light (decode, exposure, tone
// curve, encode), so that a stop of exposure doubles the light as a camera's would. NaN, which fails
// every comparison, maps to black.
std::uint8_t preview_byte(float colour, double scale, ToneMap tone_map) {
  double display = colour;
  if (scale != 1.0 || tone_map != ToneMap::kNone)
    display = linear_to_srgb(std::min(1.0, apply_tone_map(tone_map, srgb_to_linear(colour) * scale)));
  if (!(display > 0.0)) return 0;
  return static_cast<std::uint8_t>(std::lround(std::min(display, 1.0) * 255.0));
}

// What makes an image or the options unfit for a preview; empty when nothing does.
std::string preview_problem(const RenderImage& image, const PreviewOptions& options) {
  const size_t pixels = image.pixels();
  if (image.rgba.size() != 4 * pixels)
    return "rgba holds " + std::to_string(image.rgba.size()) + " values, a " + std::to_string(image.width) +
           "x" + std::to_string(image.height) + " image needs " + std::to_string(4 * pixels);
  if (!(std::abs(options.exposure_stops) <= 20.0))
    return "exposure " + std::to_string(options.exposure_stops) + " stops is not a number from -20 to 20";
  return {};
}

}  // namespace

std::string to_string(ToneMap tone_map) {
  switch (tone_map) {
    case ToneMap::kNone: return "none";
    case ToneMap::kAces: return "aces";
    case ToneMap::kReinhard: return "reinhard";
  }
  return "unknown";
}

double apply_tone_map(ToneMap tone_map, double x) {
  if (!(x > 0.0)) return 0.0;  // negatives and NaN
  if (std::isinf(x)) return 1.0;
  switch (tone_map) {
    case ToneMap::kNone: return x;
    // Both curves are monotonic, map 0 to 0 and approach 1 (ACES reaches it at x ~ 11.2, then clamps).
    case ToneMap::kAces: return std::min(1.0, x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14));
    case ToneMap::kReinhard: return x / (1.0 + x);
  }
  return x;
}

std::vector<std::uint8_t> preview_pixels(const RenderImage& image, const PreviewOptions& options) {
  if (const std::string problem = preview_problem(image, options); !problem.empty())
    throw std::invalid_argument("preview_pixels: " + problem);
  const size_t pixels = image.pixels();
  const double scale = std::exp2(options.exposure_stops);
  std::vector<std::uint8_t> rgb(3 * pixels);
  for (size_t pixel = 0; pixel < pixels; ++pixel)
    for (size_t c = 0; c < 3; ++c)
      rgb[3 * pixel + c] = preview_byte(image.rgba[4 * pixel + c], scale, options.tone_map);
  return rgb;
}

void write_png_preview(const std::filesystem::path& path, const RenderImage& image, const PreviewOptions& options) {
  const std::string prefix = "cannot write " + path.string() + ": ";
  if (image.width <= 0 || image.height <= 0)
    throw std::runtime_error(prefix + "image size " + std::to_string(image.width) + "x" +
                             std::to_string(image.height) + " is empty");
  // libpng takes the row stride (3 bytes a pixel) as a 32-bit int.
  if (image.width > INT_MAX / 3)
    throw std::runtime_error(prefix + "image width " + std::to_string(image.width) + " is too large for PNG");
  if (const std::string problem = preview_problem(image, options); !problem.empty())
    throw std::runtime_error(prefix + problem);
  const std::vector<std::uint8_t> rgb = preview_pixels(image, options);

  detail::write_file_atomically(path, [&](const std::filesystem::path& temp) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(image.width);
    png.height = static_cast<png_uint_32>(image.height);
    png.format = PNG_FORMAT_RGB;  // 8-bit non-linear: libpng tags the file with an sRGB chunk
    const bool written = png_image_write_to_file(&png, temp.c_str(), /*convert_to_8_bit=*/0, rgb.data(),
                                                 /*row_stride=*/3 * image.width, /*colormap=*/nullptr) != 0;
    // The simplified API reports failures through png.message rather than longjmp, so no C++
    // exception ever has to unwind through libpng.
    const std::string message = png.message;
    png_image_free(&png);
    if (!written) throw std::runtime_error("libpng: " + message);
  });
}

}  // namespace tilesplat
