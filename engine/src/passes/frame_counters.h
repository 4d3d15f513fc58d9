// Layout of the small GPU counter buffer each frame writes and the host reads after it.
// Must match the COUNTER_* constants in compute/common.glsl.
#pragma once

#include <cstdint>

namespace tilesplat {

struct FrameCounters {
  uint32_t intersections;  // (Gaussian, tile) pairs wanted
  uint32_t sort_count;     // pairs emitted and sorted (capped by capacity)
  uint32_t overflow;       // 1 when the key buffers were too small
  uint32_t visible;        // Gaussians touching at least one tile
  uint32_t ranges_args[4]; // indirect dispatch of the tile-range pass (+ padding)
  uint32_t sort_args[3];   // indirect dispatch of the sort's per-block passes
  uint32_t sort_blocks;
  uint32_t reserved[4];
};
static_assert(sizeof(FrameCounters) == 64);

constexpr uint32_t kRangesArgsOffset = 4 * sizeof(uint32_t);
constexpr uint32_t kSortArgsOffset = 8 * sizeof(uint32_t);

}  // namespace tilesplat
