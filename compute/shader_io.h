// One definition of what the compute shaders and the host share: the frame's counter indices, a
// sort's state block, the per-splat record sizes, and the push-constant block of every pass.
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
struct alignas(8) uvec2 {
  uint x = 0, y = 0;
};
struct alignas(16) uvec4 {
  uint x = 0, y = 0, z = 0, w = 0;
};
#define TS_CONST inline constexpr
#define TS_REF(Type) uint64_t
#define TS_PUSH_CONSTANTS(Name) struct Name
#define TS_PUSH_INSTANCE
// A block the host writes and a shader reads through its address.
#define TS_BUFFER(Name) struct Name
// A double: one in C++, its bits as a uvec2 in GLSL (unpackDouble2x32), so that the float32 variants'
// SPIR-V needs no Float64 capability.
#define TS_F64 double
// A block's trailing runtime-sized array: GLSL's alone; the C++ struct is the block's header.
#define TS_RUNTIME_ARRAY(Type, name)
#else
#define TS_CONST const
#define TS_REF(Type) Type
// The block's instance is `pc` in every shader: pc.width, pc.splats, ...
#define TS_PUSH_CONSTANTS(Name) layout(push_constant) uniform Name
#define TS_PUSH_INSTANCE pc
#define TS_BUFFER(Name) layout(buffer_reference, std430, buffer_reference_align = 8) buffer Name
#define TS_F64 uvec2
#define TS_RUNTIME_ARRAY(Type, name) Type name[];
#endif

TS_CONST uint TILE_SIZE = 16;  // pixels per tile side (tilesplat::kTileSize)

// Laine and Karras's permutation as Burley gives it ("Practical Hash-based Owen Scrambling", JCGT 2020):
// x += seed, then x ^= x * M for each multiplier in turn; each bit changes only the bits above it. The
// effects' Sobol samples (engine/src/camera/effect_samples.cpp) and the stochastic compositor's
// (composite_stochastic.comp) scramble with it, so host and shader scramble alike.
TS_CONST uint LAINE_KARRAS_MULTIPLIER_0 = 0x6c50b47cu;
TS_CONST uint LAINE_KARRAS_MULTIPLIER_1 = 0xb82f1e52u;
TS_CONST uint LAINE_KARRAS_MULTIPLIER_2 = 0xc7afe638u;
TS_CONST uint LAINE_KARRAS_MULTIPLIER_3 = 0x8d22f6e6u;

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
TS_CONST uint COUNTER_SATURATED = 31;       // colour values saturated to half's range (pack_colour.comp)
TS_CONST uint COUNTER_SATURATED_MEAN = 32;  // linear colours saturated to float's (sample_accumulate.comp)
TS_CONST uint COUNTER_UINTS = 33;           // the block's size

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

// The push constants, the composites first. A shader declares the block of its pass by defining
// the macro before including common.glsl; C++ sees them all.

// CompositePush::flags.
TS_CONST uint COMPOSITE_LAST_CHUNK = 1;  // the last dispatch: write the outputs whatever is left
TS_CONST uint COMPOSITE_CARRY_IN = 2;    // a later part of the scene: start from the previous part's state
TS_CONST uint COMPOSITE_CARRY_OUT = 4;   // not the last part: leave the state for the next, no outputs
TS_CONST uint COMPOSITE_STATE_HIGH = 8;  // write the state buffer's upper half (read the lower at chunk 0)

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
  uint flags;        // COMPOSITE_LAST_CHUNK, COMPOSITE_CARRY_IN, COMPOSITE_CARRY_OUT, COMPOSITE_STATE_HIGH
  float surface_alpha;
  uint first_tile;  // the outputs' first tile in the camera's grid, x | y << 16 (first_tile_of)
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
  uint first_tile;             // the outputs' first tile in the camera's grid (first_tile_of)
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
  uint first_tile;  // the outputs' first tile in the camera's grid (first_tile_of)
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_RASTER_PUSH)
// raster_quad.vert and raster_blend.frag (RasterCompositePass): one instance per visible splat, in
// depth order, each a quad around its alpha >= alpha_min ellipse.
TS_PUSH_CONSTANTS(RasterPush) {
  TS_REF(Vec4Array) splats;
  TS_REF(UintArray) depth_order;  // the depth sort's result: record indices, visible ones first
  TS_REF(UintArray) counters;     // COUNTER_VISIBLE: how many of them the mesh stage draws
  uint width;                     // of the attachments: the image's, or a region's tiles'
  uint height;
  uint first_tile;  // the attachments' first tile in the camera's grid (first_tile_of)
  float surface_alpha;  // raster_blend_surface: the alpha at which a pixel's depth out is taken
}
TS_PUSH_INSTANCE;
#endif

// Splats one workgroup of raster_quads.mesh draws (4 vertices and 2 triangles each).
TS_CONST uint RASTER_MESH_SPLATS = 32;

#if defined(__cplusplus) || defined(TS_RASTER_MESH_ARGS_PUSH)
// raster_mesh_args.comp (RasterCompositePass): the mesh-stage draw's workgroup counts.
TS_PUSH_CONSTANTS(RasterMeshArgsPush) {
  TS_REF(UintArray) counters;  // COUNTER_VISIBLE
  TS_REF(UintArray) args;      // VkDrawMeshTasksIndirectCommandEXT
  uint max_groups_x;           // VkPhysicalDeviceMeshShaderPropertiesEXT::maxMeshWorkGroupCount[0]
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_RASTER_HOST_SURFACES_PUSH)
// raster_host_surfaces.comp (RasterCompositePass): the host's view depths for the depth attachment.
TS_PUSH_CONSTANTS(RasterHostSurfacesPush) {
  TS_REF(FloatArray) view_depth;  // per pixel, +inf where the host drew nothing
  TS_REF(FloatArray) scaled;      // per pixel, view depth times 2^-64, at most 1
  uint pixels;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_RASTER_RESOLVE_PUSH)
// raster_resolve.comp (RasterCompositePass): the attachments, copied to buffers, into the outputs.
TS_PUSH_CONSTANTS(RasterResolvePush) {
  TS_REF(Vec4Array) rgba;        // in: (sum of w rgb, 1 - T); out: with the background under it
  TS_REF(Vec4Array) depth_sums;  // in: (sum of w depth, -, -, 1 - T), when the depth is written
  TS_REF(FloatArray) out_depth;  // the weighted mean depth
  TS_REF(UintArray) count;       // in: float counts; out: the same as uints
  TS_REF(FloatArray) surface;    // in: the depth out's MIN (+inf: none); out: the same, 0 for none
  TS_REF(UintArray) half_rgba;   // fp16-blend: the RGBA16F attachment's texels, read into rgba
  vec4 background;
  uint pixels;
  uint write_depth;
  uint write_count;
  uint write_surface;
  uint half_colour;  // the colour comes from half_rgba (fp16-blend), else it is in rgba already
}
TS_PUSH_INSTANCE;
#endif

// ---------------------------------------------------------------------------------------------
// The push constants of the frame's other passes (engine/src/passes/), in frame order.

#if defined(__cplusplus) || defined(TS_PACK_SH_HALF_PUSH)
// pack_sh_half.comp (ProjectionPass, fp16-sh): the SH as 16-bit floats.
TS_PUSH_CONSTANTS(PackShHalfPush) {
  TS_REF(FloatArray) sh;
  TS_REF(UintArray) sh_half;
  uint values;  // floats in sh
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_PACK_COVARIANCE_HALF_PUSH)
// pack_covariance_half.comp (ProjectionPass, fp16-cov): the 3D covariances as 16-bit floats.
TS_PUSH_CONSTANTS(PackCovarianceHalfPush) {
  TS_REF(FloatArray) log_scales;
  TS_REF(FloatArray) rotations;
  TS_REF(UintArray) covariances;
  uint count;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_PROJECTION_PUSH) || defined(TS_PROJECTION_BACKWARD_PUSH)
// The camera of projection.comp (and of projection_backward.comp, which reads the forward's), written by the
// host each frame (ProjectionPass::set_camera).
TS_BUFFER(CameraParams) {
  TS_F64 rotation[9];         // world-to-camera rotation, row-major
  TS_F64 centre[3];           // camera centre (world)
  TS_F64 focal_principal[4];  // fx, fy, cx, cy
  // The Jacobian's clamp of x/z and y/z (1.3 tan(fov_x/2), 1.3 tan(fov_y/2) for the pinhole), the near
  // plane, the model's reach (camera_models::ModelLimits): the reference compares in double, and a
  // float 0.2 would cull a splat on the plane that the reference keeps.
  TS_F64 clip[4];
  // The frame's tiles in the camera's grid, [first x, first y] to [end x, end y): the image's, or those a
  // region meets (RenderSettings::region). A splat's tile rect is clamped to them.
  uvec4 tiles;
  TS_F64 distortion[8];  // Camera::distortion (CAMERA_MODEL other than the pinhole)
};
// The same as uvec2 words (projection.comp's camera_word): where each field starts.
TS_CONST uint CAMERA_ROTATION = 0, CAMERA_CENTRE = 9, CAMERA_FOCAL = 12, CAMERA_CLIP = 16, CAMERA_TILES = 20,
              CAMERA_DISTORTION = 22;
#endif

#if defined(__cplusplus) || defined(TS_PROJECTION_PUSH)
// The frame's lights, written by the host (ProjectionPass::set_lighting) in float64 from the same
// prepared values as the reference's (engine/src/lighting.h).
struct LightRecord {
  TS_F64 vector[3];    // directional: the unit vector toward the light; point: its position
  TS_F64 radiance[3];  // colour * intensity
  uint point;          // 1: a point light
  uint pad;
};
TS_BUFFER(LightParams) {
  uint64_t normals;  // FILE_NORMALS: 3 floats per Gaussian (the PLY's nx ny nz, possibly zero)
  TS_F64 ambient[3];
  uint count;
  uint pad;
  TS_RUNTIME_ARRAY(LightRecord, lights)  // count of them
};

// projection.comp (ProjectionPass). camera and lighting are the addresses of the blocks above.
TS_PUSH_CONSTANTS(ProjectionPush) {
  TS_REF(FloatArray) positions;
  TS_REF(FloatArray) log_scales;
  TS_REF(FloatArray) rotations;
  TS_REF(FloatArray) opacity_logits;
  uint64_t sh;      // floats, or packed halves (SH_HALF)
  uint64_t camera;  // CameraParams
  TS_REF(Vec4Array) splats;
  TS_REF(Uvec2Array) rects;
  TS_REF(UintArray) tile_counts;
  TS_REF(UintArray) depth_keys;  // the depth sort's input (32-bit keys): view depth bits, culled last
  TS_REF(UintArray) depth_values;
  TS_REF(UintArray) counters;
  TS_REF(UintArray) covariances;  // COV_HALF: 3 uints (xx xy, xz yy, yz zz as halves) per Gaussian
  TS_REF(Vec4Array) ray_depth;    // RAY_DEPTH: RAY_DEPTH_VEC4S per Gaussian (composite_resort.comp)
  uint64_t lighting;              // LIGHTING: LightParams
  uint count;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_DEPTH_QUANTIZE_PUSH)
// depth_quantize.comp (DepthQuantizePass, depth16).
TS_PUSH_CONSTANTS(DepthQuantizePush) {
  TS_REF(UintArray) depth_keys;
  TS_REF(UintArray) counters;
  uint count;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_PREFIX_SUM_BLOCKS_PUSH)
// prefix_sum_blocks.comp (PrefixSumPass).
TS_PUSH_CONSTANTS(PrefixSumBlocksPush) {
  TS_REF(UintArray) src;
  TS_REF(UintArray) dst;         // may alias src
  TS_REF(UintArray) block_sums;  // one per workgroup
  TS_REF(UintArray) order;       // when gather != 0, value k is src[order[k]] instead of src[k]
  uint count;
  uint gather;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_PREFIX_SUM_ADD_PUSH)
// prefix_sum_add.comp (PrefixSumPass).
TS_PUSH_CONSTANTS(PrefixSumAddPush) {
  TS_REF(UintArray) data;
  TS_REF(UintArray) block_offsets;
  uint count;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_FRAME_SETUP_PUSH)
// frame_setup.comp (KeyEmissionPass).
TS_PUSH_CONSTANTS(FrameSetupPush) {
  TS_REF(UintArray) counters;
  uint capacity;  // keys the key/value buffers hold
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_SCATTER_OFFSETS_PUSH)
// scatter_offsets.comp (KeyEmissionPass).
TS_PUSH_CONSTANTS(ScatterOffsetsPush) {
  TS_REF(UintArray) depth_order;    // Gaussian indices, front to back
  TS_REF(UintArray) depth_offsets;  // exclusive prefix sum of the tile counts, in depth order
  TS_REF(UintArray) offsets;        // out: the same offsets, per Gaussian
  uint count;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_KEY_EMISSION_PUSH)
// key_emission.comp and key_emission_big.comp (KeyEmissionPass).
TS_PUSH_CONSTANTS(KeyEmissionPush) {
  TS_REF(Vec4Array) splats;
  TS_REF(Uvec2Array) rects;
  TS_REF(UintArray) tile_counts;
  TS_REF(UintArray) offsets;  // per Gaussian: where its pairs start (scatter_offsets.comp)
  uint64_t keys;              // see sort_keys.glsl
  TS_REF(UintArray) values;
  TS_REF(UintArray) depth_keys;  // WIDE_KEYS: per Gaussian, written by the projection
  TS_REF(UintArray) big_splats;  // Gaussians with more than BIG_SPLAT_PAIRS pairs, for key_emission_big.comp
  TS_REF(UintArray) counters;
  uint count;
  uint tiles_x;  // of the frame's tiles: a region's (RenderSettings::region) or the image's
  uint capacity;
  uint tiles;
  uint first_tile;  // the frame's first tile in the camera's grid (first_tile_of): tile ids count from it
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_TILE_RANGES_PUSH)
// tile_ranges.comp (TileRangesPass).
TS_PUSH_CONSTANTS(TileRangesPush) {
  uint64_t keys;              // the sorted keys: tile ids, or tile << 32 | depth bits (64-bit keys)
  TS_REF(Uvec2Array) ranges;  // zero-filled before this pass
  TS_REF(UintArray) counters;
  uint tiles;  // keys with a tile id >= tiles are padding (see key_emission.comp)
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_HOST_DEPTH_PUSH)
// host_depth.comp (HostDepthPass).
TS_PUSH_CONSTANTS(HostDepthPush) {
  TS_REF(FloatArray) window;  // the host's window depths, one float a pixel
  TS_REF(FloatArray) view;    // view depths, written (DIRECTION 0) or the splats' surface depths, read (1)
  uvec2 a_bits;               // the convention's a and b as float64 bits
  uvec2 b_bits;
  float a32;  // and as float32
  float b32;
  uint width;
  uint height;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_SAMPLE_ACCUMULATE_PUSH)
// sample_accumulate.comp (SampleAccumulatePass).
TS_PUSH_CONSTANTS(SampleAccumulatePush) {
  TS_REF(Vec4Array) rgba;    // the sample frame's colour, replaced by the mean's
  TS_REF(FloatArray) depth;  // its depth, likewise (when write_depth)
  TS_REF(UintArray) count;   // its splat counts, likewise (when write_count)
  TS_REF(Vec4Array) sums;    // two halves of 2 vec4 a pixel: (mean linear RGB, sum of alpha), (sums of
                             // alpha * depth and count, -, -)
  TS_REF(UintArray) counters;  // COUNTER_SATURATED_MEAN: linear colours past float's range
  uint pixels;
  uint samples_before;  // samples in the sums already: the half read is samples_before % 2
  uint write_depth;
  uint write_count;
  uint opaque;  // the frames were blended over a background: their colours are not premultiplied
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_PACK_COLOUR_PUSH)
// pack_colour.comp (PackColourPass).
TS_PUSH_CONSTANTS(PackColourPush) {
  TS_REF(Vec4Array) rgba;
  TS_REF(UintArray) packed;
  TS_REF(UintArray) counters;  // COUNTER_SATURATED: values past half's range (FORMAT 0)
  uint width;
  uint height;
}
TS_PUSH_INSTANCE;
#endif

// ---------------------------------------------------------------------------------------------
// The push constants of the built-in sort strategies (engine/src/sort/). Each sorts the keys of a
// KeyBuffers in place with its state block (SORT_STATE_UINTS) counting them.

#if defined(__cplusplus) || defined(TS_RADIX_SETUP_PUSH)
// radix_setup.comp (RadixSort).
TS_PUSH_CONSTANTS(RadixSetupPush) {
  TS_REF(UintArray) state;  // the sort's state block
  uint block_keys;          // the block size for counts below large_count
  uint large_count;         // from this count on, blocks are twice as large
  uint subgroups_per_workgroup;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_RADIX_PASS_PUSH)
// radix_histogram.comp and radix_scatter.comp (RadixSort), one digit a pass.
TS_PUSH_CONSTANTS(RadixPassPush) {
  uint64_t keys_in;  // see sort_keys.glsl
  TS_REF(UintArray) values_in;
  uint64_t keys_out;
  TS_REF(UintArray) values_out;
  TS_REF(UintArray) histogram;     // RADIX * blocks, digit-major: histogram[digit * blocks + block]
  TS_REF(UintArray) digit_totals;  // RADIX
  TS_REF(UintArray) state;         // the sort's state block (SORT_COUNT, SORT_BLOCKS)
  uint shift;                      // which 8-bit digit this pass sorts on
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_RADIX_SCAN_PUSH)
// radix_scan.comp (RadixSort).
TS_PUSH_CONSTANTS(RadixScanPush) {
  TS_REF(UintArray) histogram;
  TS_REF(UintArray) digit_totals;
  TS_REF(UintArray) state;  // the sort's state block
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_ONESWEEP_SETUP_PUSH)
// onesweep_setup.comp (OnesweepSort).
TS_PUSH_CONSTANTS(OnesweepSetupPush) {
  TS_REF(UintArray) state;    // the sort's state block
  TS_REF(UintArray) control;  // CTRL_UINTS
  uint partition_keys;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_ONESWEEP_HISTOGRAM_PUSH)
// onesweep_histogram.comp (OnesweepSort).
TS_PUSH_CONSTANTS(OnesweepHistogramPush) {
  uint64_t keys;              // see sort_keys.glsl
  TS_REF(UintArray) control;  // CTRL_UINTS (onesweep_common.glsl)
  TS_REF(UintArray) status;   // the first digit pass's status rows, RADIX per partition
  TS_REF(UintArray) state;    // the sort's state block
  uint passes;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_ONESWEEP_PASS_PUSH)
// onesweep_pass.comp (OnesweepSort), one digit a pass.
TS_PUSH_CONSTANTS(OnesweepPassPush) {
  uint64_t keys_in;  // see sort_keys.glsl
  TS_REF(UintArray) values_in;
  uint64_t keys_out;
  TS_REF(UintArray) values_out;
  TS_REF(UintArray) control;      // CTRL_UINTS (onesweep_common.glsl)
  TS_REF(UintArray) status;       // this pass's status rows, RADIX per partition
  TS_REF(UintArray) status_next;  // the next pass's rows, cleared here (the pass before last used them)
  TS_REF(UintArray) state;        // the sort's state block
  TS_REF(UintArray) fallbacks;    // [0]: look-back steps that gave up waiting, over the strategy's life
  uint shift;                     // which 8-bit digit this pass sorts on
  uint pass;
  uint spin_limit;  // polling rounds on an unpublished status before counting it here; 0 forces it
  uint clear_next;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_BITONIC_SETUP_PUSH)
// bitonic_setup.comp (BitonicSort).
TS_PUSH_CONSTANTS(BitonicSetupPush) {
  TS_REF(UintArray) state;  // the sort's state block
  uint capacity;
  uint group_keys;  // keys per invocation
  uint workgroup_size;
  uint max_workgroups;  // the dispatch limit (lower on CPU drivers); the kernels loop over the rest
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_BITONIC_PASS_PUSH)
// bitonic_sort_groups.comp and bitonic_merge.comp (BitonicSort).
TS_PUSH_CONSTANTS(BitonicPassPush) {
  uint64_t keys_in;             // the keys to sort (read by the first pass only; see sort_keys.glsl)
  TS_REF(UintArray) values_in;  // the payloads, gathered by the last pass
  uint64_t keys;                // the network's keys, in place (keys_alt, or 64-bit scratch when PACKED)
  uint64_t keys_out;            // the sorted keys, written by the last pass (keys_alt)
  TS_REF(UintArray) positions;  // each key's input position while the network runs (not PACKED)
  // The gathered payloads: values_alt, the same memory as the positions (a pass stores the indices it
  // loaded, so the last one replaces each position).
  TS_REF(UintArray) values_out;
  TS_REF(UintArray) state;  // the sort's state block (SORT_COUNT)
  uint capacity;            // the key buffers' size: a larger count is clamped rather than overrun
  uint position_bits;       // PACKED: the low bits of a network key that hold the position
  uint stage;               // k (merge passes)
  uint stride;              // the largest stride of this pass
  uint steps;               // the steps this pass runs (strides stride ... stride >> (steps - 1))
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_TILE_LOCAL_SETUP_PUSH)
// tile_local_setup.comp (TileLocalSort).
TS_PUSH_CONSTANTS(TileLocalSetupPush) {
  TS_REF(UintArray) state;  // the sort's state block
  uint capacity;
  uint workgroup_size;
  uint max_workgroups;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_TILE_LOCAL_BIN_PUSH)
// tile_local_bin.comp (TileLocalSort).
TS_PUSH_CONSTANTS(TileLocalBinPush) {
  uint64_t keys_in;                 // see sort_keys.glsl
  uint64_t keys_out;                // keys_alt (scatter)
  TS_REF(UintArray) positions_out;  // values_alt (scatter)
  TS_REF(UintArray) bins;           // see tile_local_bins.glsl
  TS_REF(UintArray) state;          // the sort's state block
  uint capacity;
  uint bin_count;
  uint shift;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_TILE_LOCAL_SCAN_PUSH)
// tile_local_scan.comp (TileLocalSort).
TS_PUSH_CONSTANTS(TileLocalScanPush) {
  TS_REF(UintArray) bins;  // see tile_local_bins.glsl
  uint bin_count;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_TILE_LOCAL_SORT_PUSH)
// tile_local_sort.comp (TileLocalSort).
TS_PUSH_CONSTANTS(TileLocalSortPush) {
  uint64_t keys;       // keys_alt: the binned keys; the sorted keys at the end
  uint64_t positions;  // values_alt: each binned key's input position; the gathered payloads at the end
  TS_REF(UintArray) values_in;  // the payloads, by input position
  TS_REF(UintArray) bins;       // see tile_local_bins.glsl
  uint bin_count;
  uint shift;           // local key bits: a key is bin << shift | local key
  uint big_workgroups;  // the most workgroups of the BIG variant's indirect dispatch
}
TS_PUSH_INSTANCE;
#endif

// The backward passes (docs/gradients.md). A splat's screen-space gradient: SPLAT_GRADIENT_FLOATS floats
// per projected record, summed over the pixels it was blended into:
//   [0, 1] dL/d mean (pixels)        [2, 3, 4] dL/d conic A, B, C     [5] dL/d opacity
//   [6, 7, 8] dL/d colour r, g, b    [9] dL/d view depth              [10, 11] sum of |dL/d mean| per pixel
TS_CONST uint SPLAT_GRADIENT_FLOATS = 12;
// Per pixel, the loss's gradient of the frame's outputs (FrameGradients): dL/d(r, g, b, alpha), then
// dL/d(expected depth, accumulated depth) as a second, vec2-aligned array.
// The projection backward's per-Gaussian outputs, laid out as GaussianScene's arrays, and its counter.
TS_CONST uint BACKWARD_COUNTER_UNFORMED = 0;  // drawn Gaussians whose gradient was not finite (set to 0)

#if defined(__cplusplus) || defined(TS_COMPOSITE_BACKWARD_PUSH)
// composite_backward.comp (CompositeBackwardPass).
TS_PUSH_CONSTANTS(CompositeBackwardPush) {
  TS_REF(Vec4Array) splats;          // the forward's projected records
  TS_REF(UintArray) sorted_indices;  // the forward's tile lists
  TS_REF(Uvec2Array) ranges;
  TS_REF(Vec4Array) pixel_rgba_gradients;  // dL/d(r, g, b, alpha) per pixel
  TS_REF(Uvec2Array)
  pixel_depth_gradients;               // dL/d(expected depth, accumulated depth) per pixel (as float bits)
  TS_REF(FloatArray) splat_gradients;  // SPLAT_GRADIENT_FLOATS per record, summed into
  vec4 background;
  uint width;
  uint height;
  uint tiles_x;
}
TS_PUSH_INSTANCE;
#endif

#if defined(__cplusplus) || defined(TS_PROJECTION_BACKWARD_PUSH)
// projection_backward.comp (ProjectionBackwardPass).
TS_PUSH_CONSTANTS(ProjectionBackwardPush) {
  TS_REF(FloatArray) positions;  // the scene, as the projection read it
  TS_REF(FloatArray) log_scales;
  TS_REF(FloatArray) rotations;
  TS_REF(FloatArray) opacity_logits;
  TS_REF(FloatArray) sh;
  uint64_t camera;                     // the forward's CameraParams
  TS_REF(UintArray) tile_counts;       // the forward's: 0 = not drawn
  TS_REF(FloatArray) splat_gradients;  // composite_backward.comp's sums
  // Out: 3 + 3 + 4 + 1 + 3 K + 2 + 2 floats per Gaussian, each array at its own address.
  TS_REF(FloatArray) gradients;  // positions (3N), log scales (3N), rotations (4N), logits (N), SH (3KN)
  TS_REF(UintArray) counters;    // BACKWARD_COUNTER_UNFORMED
  uint count;
}
TS_PUSH_INSTANCE;
#endif

#ifdef __cplusplus
// What the C++ compiler can check of the layouts: the blocks' sizes (std430 lays the members out as
// C++ does here: scalars, 8-byte addresses and doubles, 16-byte vec4) and the 128 bytes of push
// constants that every Vulkan device accepts (maxPushConstantsSize).
static_assert(sizeof(CameraParams) == 240 && CAMERA_TILES * sizeof(uvec2) == 160 &&
              CAMERA_DISTORTION * sizeof(uvec2) == 176);
static_assert(sizeof(LightRecord) == 56 && sizeof(LightParams) == 40);
static_assert(sizeof(CompositePush) <= 128 && sizeof(CompositeResortPush) <= 128 &&
              sizeof(StochasticCompositePush) <= 128 && sizeof(PackShHalfPush) <= 128 &&
              sizeof(PackCovarianceHalfPush) <= 128 && sizeof(ProjectionPush) <= 128 &&
              sizeof(DepthQuantizePush) <= 128 && sizeof(PrefixSumBlocksPush) <= 128 &&
              sizeof(PrefixSumAddPush) <= 128 && sizeof(FrameSetupPush) <= 128 &&
              sizeof(ScatterOffsetsPush) <= 128 && sizeof(KeyEmissionPush) <= 128 &&
              sizeof(TileRangesPush) <= 128 && sizeof(HostDepthPush) <= 128 &&
              sizeof(PackColourPush) <= 128 && sizeof(SampleAccumulatePush) <= 128 &&
              sizeof(RadixSetupPush) <= 128 && sizeof(RadixPassPush) <= 128 && sizeof(RadixScanPush) <= 128 &&
              sizeof(OnesweepSetupPush) <= 128 && sizeof(OnesweepHistogramPush) <= 128 &&
              sizeof(OnesweepPassPush) <= 128 && sizeof(BitonicSetupPush) <= 128 &&
              sizeof(BitonicPassPush) <= 128 && sizeof(TileLocalSetupPush) <= 128 &&
              sizeof(TileLocalBinPush) <= 128 && sizeof(TileLocalScanPush) <= 128 &&
              sizeof(TileLocalSortPush) <= 128 && sizeof(CompositeBackwardPush) <= 128 &&
              sizeof(ProjectionBackwardPush) <= 128);
}  // namespace tilesplat::shader_io
#endif
#endif  // TILESPLAT_SHADER_IO_H
