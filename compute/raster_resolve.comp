#version 460
// The raster compositor's last step (RasterCompositePass): the blended attachments, copied to the
// output buffers, become what the tile compositor writes: the background under the splats (the
// remaining transmittance T = 1 - alpha of it), the weighted mean depth (the weights sum to 1 - T),
// and the splat counts as integers (the colour from 16-bit floats with fp16-blend); a host's depth out
// (the splat depth at which the alpha reached its threshold) as composite.comp writes it, 0 where it
// never did.
#extension GL_GOOGLE_include_directive : require
#define TS_RASTER_RESOLVE_PUSH
#include "common.glsl"

layout(local_size_x = 256) in;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.pixels) return;
  vec4 rgba = pc.half_colour != 0
                  ? vec4(unpackHalf2x16(pc.half_rgba.v[2 * i]), unpackHalf2x16(pc.half_rgba.v[2 * i + 1]))
                  : pc.rgba.v[i];
  float transmittance = 1.0 - rgba.a;
  pc.rgba.v[i] = vec4(rgba.rgb + transmittance * pc.background.rgb, rgba.a);
  if (pc.write_depth != 0) {
    vec4 sums = pc.depth_sums.v[i];
    pc.out_depth.v[i] = sums.a > 0.0 ? sums.x / sums.a : 0.0;
  }
  if (pc.write_count != 0) pc.count.v[i] = uint(uintBitsToFloat(pc.count.v[i]));
  if (pc.write_surface != 0 && isinf(pc.surface.v[i])) pc.surface.v[i] = 0.0;
}
