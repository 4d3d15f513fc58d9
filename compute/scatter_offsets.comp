#version 460
// Key emission, step 1. The prefix sum ran over the tile counts in depth order; this hands each
// Gaussian its offset, so that the emission reads its per-Gaussian inputs in index order
// (sequential) instead of in depth order (four random reads per Gaussian instead of one write).
#extension GL_GOOGLE_include_directive : require
#define TS_SCATTER_OFFSETS_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x = 256) in;

#ifdef TS_TEXEL_BUFFERS
// The CPU-driver variant (scatter_offsets_texel): the same buffers through texel buffers, which llvmpipe
// reads with SIMD gathers (vk::texel_buffers_wanted).
layout(set = 0, binding = 0) uniform utextureBuffer depth_order_texels;
layout(set = 0, binding = 1) uniform utextureBuffer depth_offset_texels;
layout(set = 0, binding = 2, r32ui) uniform writeonly uimageBuffer offset_texels;
uint gaussian_at(uint position) { return texelFetch(depth_order_texels, int(position)).x; }
uint offset_at(uint position) { return texelFetch(depth_offset_texels, int(position)).x; }
void write_offset(uint gaussian, uint offset) { imageStore(offset_texels, int(gaussian), uvec4(offset)); }
#else
uint gaussian_at(uint position) { return pc.depth_order.v[position]; }
uint offset_at(uint position) { return pc.depth_offsets.v[position]; }
void write_offset(uint gaussian, uint offset) { pc.offsets.v[gaussian] = offset; }
#endif

void main() {
  uint position = gl_GlobalInvocationID.x;
  if (position < pc.count) write_offset(gaussian_at(position), offset_at(position));
}
