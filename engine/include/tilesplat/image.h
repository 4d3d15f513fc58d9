// Rendered images, their files (EXR, PNG preview) and comparisons between them.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace tilesplat {

// What a render produces, row-major with row 0 at the top.
struct RenderImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgba;  // 4 per pixel: premultiplied colour over the background, A = 1 - T
  std::vector<float> depth; // 1 per pixel: expected view depth of the blended splats
                            // (sum w z / sum w), 0 where nothing was blended; may be empty
  std::vector<uint32_t> splat_count;  // 1 per pixel: splats blended; may be empty

  size_t pixels() const { return size_t(width) * size_t(height); }
};

struct ExrWriteOptions {
  bool half = false;  // store HALF instead of FLOAT channels
};

// Writes channels R G B A (and Z when depth is present, and "splats" when counts are present).
// Atomic: the image goes to a temporary file beside `path` that is renamed over it only once
// complete, so a failure never leaves a partial file. Throws std::runtime_error naming the file.
void write_exr(const std::filesystem::path& path, const RenderImage& image, const ExrWriteOptions& options = {});

// Reads an EXR's R G B A (A = 1 when absent), Z and "splats" (each when present), any pixel type
// converted, any data window origin. Throws std::runtime_error naming the file.
RenderImage read_exr(const std::filesystem::path& path);

// An 8-bit sRGB PNG preview of the colour channels (clamped to [0, 1], alpha dropped).
// Atomic like write_exr.
void write_png_preview(const std::filesystem::path& path, const RenderImage& image, float exposure = 1.0f);

struct ImageDifference {
  double psnr_db = 0;       // over RGB, peak 1.0; +inf when identical
  double max_abs = 0;       // largest |a - b| over RGB
  double max_abs_alpha = 0; // largest |a - b| over A
  double rmse = 0;
  int worst_x = 0, worst_y = 0, worst_channel = 0;
};
// Compares the RGB(A) of two images of the same size. Throws std::invalid_argument otherwise.
ImageDifference compare_images(const RenderImage& a, const RenderImage& b);

}  // namespace tilesplat
