// Shared declarations for every tilesplat compute shader.
// All buffers are reached through 64-bit device addresses passed in push constants: no descriptor
// sets, and no maxStorageBufferRange limit (lavapipe caps a binding at 128 MiB; scenes exceed it).
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
// Texel buffers (the CPU-driver variants) are declared as textureBuffer and read with texelFetch, no
// sampler: a sampled image of a buffer is invalid SPIR-V from version 1.6 on, which the validation
// layer checks against on drivers of Vulkan 1.3 and later (Mesa 25's lavapipe).
#extension GL_EXT_samplerless_texture_functions : require

layout(buffer_reference, std430, buffer_reference_align = 4) buffer FloatArray { float v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer UintArray { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer Uint64Array { uint64_t v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer Uvec2Array { uvec2 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Vec4Array { vec4 v[]; };

const uint TILE_SIZE = 16;
const float FLT_MAX = 3.402823466e+38;  // the largest finite float
const float FLT_MIN = 1.175494351e-38;  // the smallest normal float

// Counters written on the GPU during a frame and read by the host after it (see frame_counters.h).
const uint COUNTER_INTERSECTIONS = 0;  // total (Gaussian, tile) pairs wanted this frame, modulo 2^32
const uint COUNTER_PAIRS_HIGH = 1;     // the total's high 32 bits (projection.comp, count_pairs)
const uint COUNTER_OVERFLOW = 2;       // 1 when total exceeded capacity (the host grows and retries)
const uint COUNTER_VISIBLE = 3;        // Gaussians that touch at least one tile
const uint COUNTER_RANGES_ARGS = 4;    // 3 uints: indirect dispatch of the tile-range pass
const uint COUNTER_DEPTH_SORT = 8;     // SORT_STATE_UINTS: the sort of the Gaussians by depth
const uint COUNTER_TILE_SORT = 16;     // SORT_STATE_UINTS: the sort of the (tile, Gaussian) pairs
const uint COUNTER_DEPTH_MIN = 24;     // float bits of the nearest and farthest visible depths, for
const uint COUNTER_DEPTH_MAX = 25;     // 16-bit depth keys (AccuracyModes::depth_key_bits)
const uint COUNTER_PAIRS_LOW = 26;     // the projection's own low word of the total, for its carries
const uint COUNTER_MAX_TILE_PAIRS = 27;  // the longest tile list over the composite's chunk size
const uint COUNTER_BIG_SPLATS = 28;    // 3 uints: splats listed for key_emission_big.comp (its dispatch)

// Pairs above which a splat's keys are written by a workgroup (key_emission_big.comp).
const uint BIG_SPLAT_PAIRS = 1024;

// A sort's state block: the key count it sorts (set before the sort runs) and what the sort derives
// from it on the GPU (its block count and the indirect dispatch of its per-block passes).
const uint SORT_COUNT = 0;
const uint SORT_BLOCKS = 1;
const uint SORT_ARGS = 2;  // 3 uints
const uint SORT_OWN = 5;   // 3 uints the running strategy may use for itself
const uint SORT_STATE_UINTS = 8;

// Pairs emitted and sorted: the total, or 0 when it exceeds the capacity (the frame is re-run).
const uint COUNTER_SORT_COUNT = COUNTER_TILE_SORT + SORT_COUNT;

// Projected splat record: four vec4 per Gaussian. The composite reads [0..2], the key emission [0], [3].
//   [0] mean.x, mean.y (float hi parts), view depth, opacity
//   [1] conic A, B, C, mean.x lo part
//   [2] colour r, g, b, mean.y lo part
//   [3] dilated 2D covariance a, b, c and its determinant (for the exact tile coverage)
const uint SPLAT_VEC4S = 4;

// Per-pixel re-sorting data (AccuracyModes::resort_window), written by the projection only in that
// mode: see write_ray_depth in projection.comp.
const uint RAY_DEPTH_VEC4S = 3;

// Popcount of a subgroup ballot, valid for any subgroup size up to 128.
uint ballot_count(uvec4 b) { return bitCount(b.x) + bitCount(b.y) + bitCount(b.z) + bitCount(b.w); }
