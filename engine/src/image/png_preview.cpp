// 8-bit sRGB PNG previews of RenderImages, written with libpng's simplified API.
#include <png.h>

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

// The exact piecewise sRGB encoding (IEC 61966-2-1), not a 2.2 gamma approximation, so previews
// match what image viewers expect for 8-bit sRGB data.
double linear_to_srgb(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

std::uint8_t preview_byte(float colour, float exposure) {
  double exposed = double{colour} * double{exposure};
  // Written so that NaN, which fails every comparison, maps to black instead of reaching the cast.
  if (!(exposed > 0.0)) exposed = 0.0;
  if (exposed > 1.0) exposed = 1.0;
  return static_cast<std::uint8_t>(std::lround(linear_to_srgb(exposed) * 255.0));
}

}  // namespace

void write_png_preview(const std::filesystem::path& path, const RenderImage& image, float exposure) {
  const std::string prefix = "cannot write " + path.string() + ": ";
  if (image.width <= 0 || image.height <= 0)
    throw std::runtime_error(prefix + "image size " + std::to_string(image.width) + "x" +
                             std::to_string(image.height) + " is empty");
  // libpng takes the row stride (3 bytes a pixel) as a 32-bit int.
  if (image.width > INT_MAX / 3)
    throw std::runtime_error(prefix + "image width " + std::to_string(image.width) + " is too large for PNG");
  const size_t pixels = image.pixels();
  if (image.rgba.size() != 4 * pixels)
    throw std::runtime_error(prefix + "rgba holds " + std::to_string(image.rgba.size()) + " values, a " +
                             std::to_string(image.width) + "x" + std::to_string(image.height) +
                             " image needs " + std::to_string(4 * pixels));
  if (!std::isfinite(exposure) || exposure <= 0.0f)
    throw std::runtime_error(prefix + "exposure " + std::to_string(exposure) +
                             " is not a positive finite number");

  std::vector<std::uint8_t> rgb(3 * pixels);
  for (size_t pixel = 0; pixel < pixels; ++pixel)
    for (size_t c = 0; c < 3; ++c) rgb[3 * pixel + c] = preview_byte(image.rgba[4 * pixel + c], exposure);

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
