// The frame's tiles (FramePlan::tiles), shared by the plan and the passes that bin and composite by tile.
#pragma once

#include <cstdint>

namespace tilesplat {

// The frame's 16x16 tiles: the camera's grid, or the part of it a RenderSettings::region meets, which
// starts at tile (first_x, first_y) of the camera's grid (frame/image_regions.h). width x height are the
// outputs' pixels, those of the tiles within the image. Tile ids count from the first tile and run to
// `count` inclusive (the key emission's padding uses that id), hence tile_bits = bit_width(count).
struct TileGrid {
  uint32_t width = 0, height = 0;  // pixels
  uint32_t first_x = 0, first_y = 0;
  uint32_t tiles_x = 0, tiles_y = 0, count = 0;
  uint32_t tile_bits = 0;
  // The first tile as the shaders' push constants hold it (first_tile_of in common.glsl).
  uint32_t packed_first() const { return first_x | first_y << 16; }
  bool operator==(const TileGrid&) const = default;
};

}  // namespace tilesplat
