// Frames of a part of the image (RenderSettings::region), and images assembled from them.
//
// A region's frame keeps the camera's tile grid: it renders the tiles the region meets (their pixels
// within the image, tile_aligned) and the host keeps the region's pixels of them (crop). Since a pixel's
// tile list is the same whatever other tiles the frame has, each pixel is the whole frame's, bit for bit.
// The renderer uses regions itself for an image whose per-pixel buffers are past the device's largest
// allocation (bands_within) and for a rolling shutter, whose every band is exposed at its own time.
#pragma once

#include <cstdint>
#include <vector>

#include "tilesplat/image.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/renderer.h"

namespace tilesplat {

// The region itself, or the whole image for a whole region: the pixels a frame returns.
PixelRegion resolved_region(const PixelRegion& region, int image_width, int image_height);
// The pixels of the tiles (of kTileSize) the region meets, within the image: what the frame renders.
PixelRegion tile_aligned(const PixelRegion& region, int image_width, int image_height);
// The pixels `within` (in the image's coordinates) of an image that holds `held`.
RenderImage crop(const RenderImage& image, const PixelRegion& held, const PixelRegion& within);
// An image of the region's size with the outputs the settings ask for (all zero), for paste to fill.
RenderImage image_to_assemble(const PixelRegion& region, const RenderSettings& settings);
// Copies `part`, the pixels `at` of `into`'s image (whose pixels start at into_origin), into `into`.
void paste(RenderImage& into, const PixelRegion& into_origin, const RenderImage& part, const PixelRegion& at);

// Bands of whole tile rows that split `region` so that each band's per-pixel buffers take at most
// `bytes_per_band` at `bytes_per_pixel` (at least one row of tiles a band): one band, the region
// itself, when it fits.
std::vector<PixelRegion> bands_within(const PixelRegion& region, uint64_t bytes_per_pixel,
                                      uint64_t bytes_per_band);

// Device memory a frame holds per pixel of its outputs: colour, depth and counts, the composite state
// carried between chunks or parts (two halves of 32 bytes), and a host's depths. The largest single
// per-pixel buffer is the composite state, kLargestBytesPerPixel.
uint64_t frame_bytes_per_pixel(const RenderSettings& settings);
constexpr uint64_t kLargestBytesPerPixel = 64;

// Host memory the frame's RenderImage takes per pixel (colour, depth and counts as asked, a host's depth).
uint64_t image_bytes_per_pixel(const RenderSettings& settings);

// Adds a band's statistics to the frame's (FrameStats::image_bands); a frame of 0 bands takes the band's.
void add_band_stats(FrameStats& frame, const FrameStats& band);

}  // namespace tilesplat
