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

const float FLT_MAX = 3.402823466e+38;  // the largest finite float
const float FLT_MIN = 1.175494351e-38;  // the smallest normal float

// The layouts the host shares (counters, sort state, record sizes, push constants): shader_io.h.
#include "shader_io.h"

// Popcount of a subgroup ballot, valid for any subgroup size up to 128.
uint ballot_count(uvec4 b) { return bitCount(b.x) + bitCount(b.y) + bitCount(b.z) + bitCount(b.w); }

// A push constant's first tile of the frame in the camera's tile grid, x | y << 16 (the host's
// pack_first_tile): (0, 0) for the whole image, else the first tile a RenderSettings::region meets.
// Pixels and tile rects stay in the camera's coordinates, so a region's pixels are the whole frame's.
uvec2 first_tile_of(uint packed) { return uvec2(packed & 0xffffu, packed >> 16); }
