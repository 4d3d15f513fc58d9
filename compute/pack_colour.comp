#version 460
// Pack colour: the frame's float RGBA (premultiplied) into the texel layout of a host's colour image
// that is not R32G32B32A32_SFLOAT, for render_to_image to copy. One invocation per pixel.
//   FORMAT 0: R16G16B16A16_SFLOAT (round to nearest half; 8 bytes a texel)
//   FORMAT 1: R8G8B8A8_UNORM (clamped to [0, 1], round(255 c); 4 bytes)
//   FORMAT 2: R8G8B8A8_SRGB (R G B through the sRGB transfer function, A linear, then as UNORM): a
//             host sampling or blending the image reads the premultiplied linear colour back.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 16, local_size_y = 16) in;
layout(constant_id = 0) const uint FORMAT = 0;

layout(push_constant) uniform Push {
  Vec4Array rgba;
  UintArray packed;
  uint width;
  uint height;
}
pc;

vec3 srgb_encode(vec3 linear) {
  vec3 c = clamp(linear, 0.0, 1.0);
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

void main() {
  uvec2 pixel = gl_GlobalInvocationID.xy;
  if (pixel.x >= pc.width || pixel.y >= pc.height) return;
  uint i = pixel.y * pc.width + pixel.x;
  vec4 c = pc.rgba.v[i];
  if (FORMAT == 0) {
    pc.packed.v[2 * i] = packHalf2x16(c.rg);
    pc.packed.v[2 * i + 1] = packHalf2x16(c.ba);
  } else {
    if (FORMAT == 2) c.rgb = srgb_encode(c.rgb);
    pc.packed.v[i] = packUnorm4x8(c);
  }
}
