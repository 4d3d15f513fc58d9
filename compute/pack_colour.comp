#version 460
// Pack colour: the frame's float RGBA (premultiplied) into the texel layout of a host's colour image
// that is not R32G32B32A32_SFLOAT, for render_to_image to copy. One invocation per pixel.
//   FORMAT 0: R16G16B16A16_SFLOAT (round to nearest half; 8 bytes a texel). A finite value past half's
//             range becomes the largest finite half with its sign, never an infinity, and is counted in
//             COUNTER_SATURATED (FrameStats::saturated).
//   FORMAT 1: R8G8B8A8_UNORM and R8G8B8A8_SRGB (clamped to [0, 1], round(255 c); 4 bytes). The frame's
//             colours are already sRGB-encoded display values (docs/colour.md), so an _SRGB image gets the
//             same bytes: a host sampling it reads linear light, and a second encoding would wash it out.
#extension GL_GOOGLE_include_directive : require
#define TS_PACK_COLOUR_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;
layout(constant_id = 0) const uint FORMAT = 0;

void main() {
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= pc.width || pixel.y >= pc.height) return;
  uint i = pixel.y * pc.width + pixel.x;
  vec4 c = pc.rgba.v[i];
  if (FORMAT == 0) {
    const float kHalfMax = 65504.0;
    uvec4 past = uvec4(greaterThan(abs(c), vec4(kHalfMax)));
    uint saturated = past.x + past.y + past.z + past.w;
    if (saturated > 0u) atomicAdd(pc.counters.v[COUNTER_SATURATED], saturated);
    c = clamp(c, vec4(-kHalfMax), vec4(kHalfMax));
    pc.packed.v[2 * i] = packHalf2x16(c.rg);
    pc.packed.v[2 * i + 1] = packHalf2x16(c.ba);
  } else {
    pc.packed.v[i] = packUnorm4x8(c);
  }
}
