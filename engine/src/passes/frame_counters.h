// Layout of the small GPU counter buffer each frame writes and the host reads after it, checked
// against the COUNTER_* and SORT_* indices of compute/shader_io.h, which the shaders use.
#pragma once

#include <cstddef>
#include <cstdint>

#include "shader_io.h"
#include "tilesplat/image.h"

namespace tilesplat {

// One sort's state: the key count (set before the sort runs) and what the sort derives from it on
// the GPU. A sort strategy is handed the buffer and offset of its block.
struct SortState {
  uint32_t count;    // keys to sort
  uint32_t blocks;   // blocks the strategy split them into
  uint32_t args[3];  // indirect dispatch of the strategy's per-block passes
  uint32_t own[3];   // for the running strategy's own use (SORT_OWN)
};
static_assert(sizeof(SortState) == shader_io::SORT_STATE_UINTS * 4 &&
              offsetof(SortState, count) == shader_io::SORT_COUNT * 4 &&
              offsetof(SortState, blocks) == shader_io::SORT_BLOCKS * 4 &&
              offsetof(SortState, args) == shader_io::SORT_ARGS * 4 && offsetof(SortState, own) == shader_io::SORT_OWN * 4);

struct FrameCounters {
  uint32_t intersections;       // (Gaussian, tile) pairs wanted, modulo 2^32
  uint32_t intersections_high;  // the high 32 bits of that total
  uint32_t overflow;        // 1 when the key buffers were too small
  uint32_t visible;         // Gaussians touching at least one tile
  uint32_t ranges_args[4];  // indirect dispatch of the tile-range pass (+ padding)
  SortState depth_sort;     // the Gaussians by view depth
  SortState tile_sort;      // the (tile, Gaussian) pairs by tile; count = pairs sorted (0 on overflow)
  uint32_t depth_range[2];  // float bits of the nearest and farthest visible depth (16-bit depth keys only)
  uint32_t pairs_low;       // the projection's running low word of the total (for its carries)
  uint32_t max_tile_pairs;  // the longest tile list, when longer than the composite's chunk (else 0)
  uint32_t big_splats[3];   // indirect dispatch of key_emission_big.comp: splats listed, 1, 1
  uint32_t saturated;       // colour values pack_colour.comp saturated to half's range (render_to_image)
  uint32_t saturated_mean;  // linear colours sample_accumulate.comp saturated to float's range

  uint64_t wanted_intersections() const { return uint64_t(intersections_high) << 32 | intersections; }
  // What the frame's passes saturated (FrameStats::saturated): sample_accumulate.comp the linear colours of
  // accumulated samples, pack_colour.comp those of a frame copied into a host's image.
  SaturatedValues saturation() const {
    SaturatedValues values;
    if (saturated_mean > 0) values.channels["linear sample mean RGB"] = saturated_mean;
    if (saturated > 0) values.channels["host image RGBA"] = saturated;
    return values;
  }
};
// The shaders' indices (shader_io.h), field by field.
#define TS_COUNTER_AT(field, index) static_assert(offsetof(FrameCounters, field) == shader_io::index * 4, #field)
static_assert(sizeof(FrameCounters) == shader_io::COUNTER_UINTS * 4);
TS_COUNTER_AT(intersections, COUNTER_INTERSECTIONS);
TS_COUNTER_AT(intersections_high, COUNTER_PAIRS_HIGH);
TS_COUNTER_AT(overflow, COUNTER_OVERFLOW);
TS_COUNTER_AT(visible, COUNTER_VISIBLE);
TS_COUNTER_AT(saturated, COUNTER_SATURATED);
TS_COUNTER_AT(saturated_mean, COUNTER_SATURATED_MEAN);
TS_COUNTER_AT(ranges_args, COUNTER_RANGES_ARGS);
TS_COUNTER_AT(depth_sort, COUNTER_DEPTH_SORT);
TS_COUNTER_AT(tile_sort, COUNTER_TILE_SORT);
TS_COUNTER_AT(tile_sort.count, COUNTER_SORT_COUNT);
TS_COUNTER_AT(depth_range, COUNTER_DEPTH_MIN);
TS_COUNTER_AT(depth_range[1], COUNTER_DEPTH_MAX);
TS_COUNTER_AT(pairs_low, COUNTER_PAIRS_LOW);
TS_COUNTER_AT(max_tile_pairs, COUNTER_MAX_TILE_PAIRS);
TS_COUNTER_AT(big_splats, COUNTER_BIG_SPLATS);
#undef TS_COUNTER_AT

constexpr uint32_t kRangesArgsOffset = offsetof(FrameCounters, ranges_args);
constexpr uint32_t kDepthSortOffset = offsetof(FrameCounters, depth_sort);
constexpr uint32_t kTileSortOffset = offsetof(FrameCounters, tile_sort);
constexpr uint32_t kDepthRangeOffset = offsetof(FrameCounters, depth_range);
constexpr uint32_t kBigSplatsOffset = offsetof(FrameCounters, big_splats);
constexpr uint32_t kSortArgsOffset = offsetof(SortState, args);  // within a SortState

}  // namespace tilesplat
