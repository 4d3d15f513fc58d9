#include "frame/image_regions.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "frame/frame_stats_sum.h"
#include "tilesplat/reference.h"    // kTileSize

namespace tilesplat {

PixelRegion resolved_region(const PixelRegion& region, int image_width, int image_height) {
  return region.whole() ? PixelRegion{0, 0, image_width, image_height} : region;
}

PixelRegion tile_aligned(const PixelRegion& region, int image_width, int image_height) {
  const PixelRegion r = resolved_region(region, image_width, image_height);
  const int x0 = r.x / kTileSize * kTileSize, y0 = r.y / kTileSize * kTileSize;
  const int x1 = std::min(image_width, (r.x + r.width + kTileSize - 1) / kTileSize * kTileSize);
  const int y1 = std::min(image_height, (r.y + r.height + kTileSize - 1) / kTileSize * kTileSize);
  return {x0, y0, x1 - x0, y1 - y0};
}

namespace {

// Copies rows of `width` pixels from `from` (pixels starting at from_origin) at (x, y) into `to` (pixels
// starting at to_origin), for every output `from` and `to` both hold.
void copy_pixels(const RenderImage& from, const PixelRegion& from_origin, RenderImage& to,
                 const PixelRegion& to_origin, const PixelRegion& pixels) {
  for (int row = pixels.y; row < pixels.y + pixels.height; ++row) {
    const size_t source = size_t(row - from_origin.y) * size_t(from.width) + size_t(pixels.x - from_origin.x);
    const size_t target = size_t(row - to_origin.y) * size_t(to.width) + size_t(pixels.x - to_origin.x);
    const size_t n = size_t(pixels.width);
    std::copy_n(from.rgba.begin() + ptrdiff_t(4 * source), 4 * n, to.rgba.begin() + ptrdiff_t(4 * target));
    if (!from.depth.empty() && !to.depth.empty())
      std::copy_n(from.depth.begin() + ptrdiff_t(source), n, to.depth.begin() + ptrdiff_t(target));
    if (!from.splat_count.empty() && !to.splat_count.empty())
      std::copy_n(from.splat_count.begin() + ptrdiff_t(source), n,
                  to.splat_count.begin() + ptrdiff_t(target));
    if (!from.host_depth.empty() && !to.host_depth.empty())
      std::copy_n(from.host_depth.begin() + ptrdiff_t(source), n, to.host_depth.begin() + ptrdiff_t(target));
  }
}

}  // namespace

RenderImage crop(const RenderImage& image, const PixelRegion& held, const PixelRegion& within) {
  if (held == within) return image;
  RenderImage out;
  out.width = within.width;
  out.height = within.height;
  const size_t pixels = out.pixels();
  out.rgba.resize(4 * pixels);
  if (!image.depth.empty()) out.depth.resize(pixels);
  if (!image.splat_count.empty()) out.splat_count.resize(pixels);
  if (!image.host_depth.empty()) out.host_depth.resize(pixels);
  copy_pixels(image, held, out, within, within);
  return out;
}

RenderImage image_to_assemble(const PixelRegion& region, const RenderSettings& settings) {
  RenderImage image;
  image.width = region.width;
  image.height = region.height;
  image.rgba.resize(4 * image.pixels());
  if (settings.depth) image.depth.resize(image.pixels());
  if (settings.splat_count) image.splat_count.resize(image.pixels());
  return image;
}

void paste(RenderImage& into, const PixelRegion& into_origin, const RenderImage& part,
           const PixelRegion& at) {
  copy_pixels(part, at, into, into_origin, at);
}

std::vector<PixelRegion> bands_within(const PixelRegion& region, uint64_t bytes_per_pixel,
                                      uint64_t bytes_per_band) {
  // A band's outputs are its tiles' pixels: the columns of the tiles the region meets.
  const int64_t first_column = int64_t(region.x) / kTileSize * kTileSize;
  const int64_t end_column = (int64_t(region.x) + region.width + kTileSize - 1) / kTileSize * kTileSize;
  const uint64_t row_bytes = uint64_t(end_column - first_column) * bytes_per_pixel;
  const int64_t first_row = int64_t(region.y) / kTileSize * kTileSize;
  const int64_t end_row = (int64_t(region.y) + region.height + kTileSize - 1) / kTileSize * kTileSize;
  if (uint64_t(end_row - first_row) * row_bytes <= bytes_per_band) return {region};
  // Whole rows of tiles a band, so that no tile is rendered twice.
  const uint64_t tile_rows = std::max<uint64_t>(1, bytes_per_band / (row_bytes * kTileSize));
  const int band_rows = int(std::min<uint64_t>(tile_rows * kTileSize, uint64_t(region.height)));
  std::vector<PixelRegion> bands;
  // The first band ends on a tile row of the image, so that every band after it starts on one.
  int y = region.y;
  const int end = region.y + region.height;
  int next = std::min(end, (y / kTileSize) * kTileSize + band_rows);
  while (y < end) {
    bands.push_back({region.x, y, region.width, next - y});
    y = next;
    next = std::min(end, y + band_rows);
  }
  return bands;
}

uint64_t frame_bytes_per_pixel(const RenderSettings& settings) {
  uint64_t bytes = 16 + (settings.depth ? 4 : 0) + (settings.splat_count ? 4 : 0) + kLargestBytesPerPixel;
  if (settings.host) bytes += 4 * (settings.host->write_depth ? 2 : 1);
  return bytes;
}

uint64_t image_bytes_per_pixel(const RenderSettings& settings) {
  return 16 + (settings.depth ? 4 : 0) + (settings.splat_count ? 4 : 0) +
         (settings.host && settings.host->write_depth ? 4 : 0);
}

void add_band_stats(FrameStats& frame, const FrameStats& band) {
  if (frame.image_bands == 0) {
    frame = band;
    frame.image_bands = 1;
    return;
  }
  add_frame_stats(frame, band, FrameCounts::kDisjoint);
  ++frame.image_bands;
}

}  // namespace tilesplat
