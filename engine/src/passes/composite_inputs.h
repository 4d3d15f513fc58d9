// What every composite (sorted, per-pixel re-sorting, stochastic, raster) blends and where to: the
// inputs a frame hands each of them, and the output images they write.
#pragma once

#include <array>
#include <compare>
#include <cstdint>

#include "tilesplat/render_settings.h"
#include "vulkan/buffer.h"

namespace tilesplat {

struct OutputBuffers {
  vk::Buffer rgba;   // vec4 per pixel
  vk::Buffer depth;  // float per pixel (only when requested)
  vk::Buffer count;  // uint per pixel (only when requested)
  uint32_t width = 0, height = 0;
  // Where the images start in the camera's tile grid, x | y << 16 (TileGrid::packed_first): 0 for the
  // whole image, else a RenderSettings::region's first tile.
  uint32_t first_tile = 0;
};

// The cut-offs as in AccuracyModes (reference: 1/255 and 1e-4), and the cap on alpha
// (RenderSettings::max_alpha).
struct CompositeCutoffs {
  float alpha = 1.0f / 255.0f;
  float transmittance = 1e-4f;
  float max_alpha = float(kDefaultMaxAlpha);
  auto operator<=>(const CompositeCutoffs&) const = default;
};

// What every composite blends and where to: the projected splats, each tile's list of Gaussian
// indices (front to back for the sorted composites, in any order for the stochastic one) and its
// [start, end) in `ranges`, the output images, and what the frame asks of them.
struct CompositeInputs {
  const vk::Buffer& splats;      // ProjectedBuffers::splats
  const vk::Buffer& tile_lists;  // Gaussian indices, tile after tile
  const vk::Buffer& ranges;      // [start, end) of each tile's run in tile_lists
  OutputBuffers& out;
  std::array<float, 3> background = {0, 0, 0};
  bool write_depth = true;
  bool write_count = true;
  CompositeCutoffs cutoffs;
};

}  // namespace tilesplat
