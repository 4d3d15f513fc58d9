// One definition of what the compute shaders and the host share: the frame's counter indices, a
// sort's state block, the per-splat record sizes, and the push-constant blocks of the composites.
// Compiled as GLSL (common.glsl includes it) and as C++ (engine/src/passes/frame_counters.h and the
// passes), in the manner of nvpro's vk_gaussian_splatting shaderio.h: a layout is written once here,
// and the C++ side checks its structs against these numbers at compile time (static_assert).
//
// In C++ everything is in namespace tilesplat::shader_io; a buffer reference (TS_REF) is the
// buffer's VkDeviceAddress, and a vec4 is 16-byte aligned, as std430 lays it out in a push block.
#ifndef TILESPLAT_SHADER_IO_H
#define TILESPLAT_SHADER_IO_H

#ifdef __cplusplus
#include <cstdint>
namespace tilesplat::shader_io {
using uint = uint32_t;
struct alignas(16) vec4 {
  float x = 0, y = 0, z = 0, w = 0;
};
#define TS_CONST inline constexpr
#define TS_REF(Type) uint64_t
#define TS_PUSH_CONSTANTS(Name) struct Name
#define TS_PUSH_INSTANCE
#else
#define TS_CONST const
#define TS_REF(Type) Type
// The block's instance is `pc` in every shader: pc.width, pc.splats, ...
#define TS_PUSH_CONSTANTS(Name) layout(push_constant) uniform Name
#define TS_PUSH_INSTANCE pc
#endif

TS_CONST uint TILE_SIZE = 16;  // pixels per tile side (tilesplat::kTileSize)

// Counters written on the GPU during a frame and read by the host after it (FrameCounters), in uints.
TS_CONST uint COUNTER_INTERSECTIONS = 0;    // total (Gaussian, tile) pairs wanted this frame, modulo 2^32
TS_CONST uint COUNTER_PAIRS_HIGH = 1;       // the total's high 32 bits (projection.comp, count_pairs)
TS_CONST uint COUNTER_OVERFLOW = 2;         // 1 when total exceeded capacity (the host grows and retries)
TS_CONST uint COUNTER_VISIBLE = 3;          // Gaussians that touch at least one tile
TS_CONST uint COUNTER_RANGES_ARGS = 4;      // 3 uints: indirect dispatch of the tile-range pass (+ 1 spare)
TS_CONST uint COUNTER_DEPTH_SORT = 8;       // SORT_STATE_UINTS: the sort of the Gaussians by depth
TS_CONST uint COUNTER_TILE_SORT = 16;       // SORT_STATE_UINTS: the sort of the (tile, Gaussian) pairs
TS_CONST uint COUNTER_DEPTH_MIN = 24;       // float bits of the nearest and farthest visible depths, for
TS_CONST uint COUNTER_DEPTH_MAX = 25;       // 16-bit depth keys (AccuracyModes::depth_key_bits)
TS_CONST uint COUNTER_PAIRS_LOW = 26;       // the projection's own low word of the total, for its carries
TS_CONST uint COUNTER_MAX_TILE_PAIRS = 27;  // the longest tile list over the composite's chunk size
TS_CONST uint COUNTER_BIG_SPLATS = 28;      // 3 uints: splats listed for key_emission_big.comp (its dispatch)
TS_CONST uint COUNTER_UINTS = 32;           // the block's size (one spare uint at the end)

// A sort's state block (SortState): the key count it sorts (set before the sort runs) and what the
// sort derives from it on the GPU (its block count and the indirect dispatch of its per-block passes).
TS_CONST uint SORT_COUNT = 0;
TS_CONST uint SORT_BLOCKS = 1;
TS_CONST uint SORT_ARGS = 2;  // 3 uints
TS_CONST uint SORT_OWN = 5;   // 3 uints the running strategy may use for itself
TS_CONST uint SORT_STATE_UINTS = 8;

// Pairs emitted and sorted: the total, or 0 when it exceeds the capacity (the frame is re-run).
TS_CONST uint COUNTER_SORT_COUNT = COUNTER_TILE_SORT + SORT_COUNT;

// Pairs above which a splat's keys are written by a workgroup (key_emission_big.comp).
TS_CONST uint BIG_SPLAT_PAIRS = 1024;

// Projected splat record: four vec4 per Gaussian (kSplatRecordBytes). The composite reads [0..2], the
// key emission [0], [3].
//   [0] mean.x, mean.y (float hi parts), view depth, opacity
//   [1] conic A, B, C, mean.x lo part
//   [2] colour r, g, b, mean.y lo part
//   [3] dilated 2D covariance a, b, c and its determinant (for the exact tile coverage)
TS_CONST uint SPLAT_VEC4S = 4;

// Per-pixel re-sorting data (AccuracyModes::resort_window), written by the projection only in that
// mode: see write_ray_depth in projection.comp (kRayDepthBytes).
TS_CONST uint RAY_DEPTH_VEC4S = 3;

// The push constants of the three composites. A shader declares the block of its pass by defining
// the macro before including common.glsl; C++ sees them all.

#if defined(__cplusplus) || defined(TS_COMPOSITE_PUSH)
// composite.comp (CompositePass).
TS_PUSH_CONSTANTS(CompositePush) {
  TS_REF(Vec4Array) splats;
  TS_REF(UintArray) sorted_indices;
  TS_REF(Uvec2Array) ranges;
  TS_REF(Vec4Array) out_rgba;
  TS_REF(FloatArray) out_depth;
  TS_REF(UintArray) out_count;
  TS_REF(Vec4Array)
  state;  // 2 vec4 per pixel between chunks: (colour, T), (depth sum, weight sum, blended, surface z)
  TS_REF(UintArray) counters;    // COUNTER_MAX_TILE_PAIRS
  TS_REF(FloatArray) host_z;     // HOST_DEPTH: per pixel, the host's surface as view depth (+inf: none)
  TS_REF(FloatArray) surface_z;  // SURFACE_DEPTH: per pixel, the depth at which alpha reached surface_alpha
  vec4 background;
  uint width;
  uint height;
  uint tiles_x;
  uint chunk_start;  // position in each tile's list where this dispatch starts
  uint chunk_size;   // splats per tile this dispatch blends at most
  uint last_chunk;   // 1: write the outputs whatever is left
  float surface_alpha;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_COMPOSITE_RESORT_PUSH)
// composite_resort.comp (CompositeResortPass).
TS_PUSH_CONSTANTS(CompositeResortPush) {
  TS_REF(Vec4Array) splats;
  TS_REF(Vec4Array) ray_depth;  // RAY_DEPTH_VEC4S per Gaussian (write_ray_depth in projection.comp)
  TS_REF(UintArray) sorted_indices;
  TS_REF(Uvec2Array) ranges;
  TS_REF(Vec4Array) out_rgba;
  TS_REF(FloatArray) out_depth;
  TS_REF(UintArray) out_count;
  uint width;
  uint height;
  vec4 background;
  vec4 intrinsics;  // fx, fy, cx, cy
  uint tiles_x;
  uint max_splats;             // the longest list a tile may have (llvmpipe's loop limit; see composite.comp)
  TS_REF(UintArray) counters;  // COUNTER_MAX_TILE_PAIRS: a longer list, which the host reports as an error
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_STOCHASTIC_COMPOSITE_PUSH)
// composite_stochastic.comp (StochasticCompositePass).
TS_PUSH_CONSTANTS(StochasticCompositePush) {
  TS_REF(Vec4Array) splats;
  TS_REF(UintArray) indices;  // each tile's Gaussians, binned by tile, in no depth order
  TS_REF(Uvec2Array) ranges;
  TS_REF(Vec4Array) out_rgba;
  TS_REF(FloatArray) out_depth;
  TS_REF(UintArray) out_count;
  // 32 bytes per pixel: vec4 (sum of the winners' rgb, samples with a winner), float (sum of the
  // winners' depths), float unused, uint64 (the nearest kept splat's order key, carried between
  // chunks). Unused (0) with one sample in one chunk.
  TS_REF(Vec4Array) state;
  TS_REF(UintArray) counters;  // COUNTER_MAX_TILE_PAIRS
  vec4 background;
  uint width;
  uint height;
  uint tiles_x;
  uint chunk_start;   // position in each tile's list where this dispatch starts
  uint chunk_size;    // splats per tile this dispatch tests at most
  uint last_chunk;    // 1: finish the sample whatever is left
  uint sample_index;  // this dispatch's sample, 0 .. samples - 1
  uint samples;       // samples averaged: the last one writes the outputs
  uint seed;
}
TS_PUSH_INSTANCE;
#endif

#ifdef __cplusplus
}  // namespace tilesplat::shader_io
#endif
#endif  // TILESPLAT_SHADER_IO_H
