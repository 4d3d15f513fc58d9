#version 460
// The raster compositor's depth attachment (RasterCompositePass, RenderSettings::host): the host's
// surfaces as view depths (+inf where it drew nothing) times 2^-64, which keeps their order to the
// bit and puts them in the attachment's range [0, 1]: 1 where there is no surface. raster_quad.vert
// gives each splat its view depth scaled alike.
#extension GL_GOOGLE_include_directive : require
#define TS_RASTER_HOST_SURFACES_PUSH
#include "common.glsl"

layout(local_size_x = 256) in;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.pixels) return;
  pc.scaled.v[i] = min(ldexp(pc.view_depth.v[i], -64), 1.0);
}
