#version 460
// The raster compositor's vertex stage (RasterCompositePass): instance i is the i-th splat in depth
// order, drawn as a triangle strip of four vertices around its alpha >= ALPHA_MIN ellipse
// (raster_quad.glsl). Instances are blended in the order they are drawn, so the fixed-function blend
// sees the splats front to back.
#extension GL_GOOGLE_include_directive : require
#define TS_RASTER_PUSH
#include "common.glsl"
#include "raster_quad.glsl"

// Flat: the fragment stage evaluates the Gaussian at its pixel.
layout(location = 0) flat out vec4 mean_depth_opacity;
layout(location = 1) flat out vec4 conic_mean_lo_x;
layout(location = 2) flat out vec4 colour_mean_lo_y;

void main() {
  RasterQuad q = raster_quad(gl_InstanceIndex);
  mean_depth_opacity = q.mean_depth_opacity;
  conic_mean_lo_x = q.conic_mean_lo_x;
  colour_mean_lo_y = q.colour_mean_lo_y;
  gl_Position = raster_corner(q, gl_VertexIndex);
}
