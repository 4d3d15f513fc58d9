#version 460
// The raster compositor's vertex stage (RasterCompositePass): instance i is the i-th splat in depth
// order, drawn as a triangle strip of four vertices around its alpha >= ALPHA_MIN ellipse. Instances
// are blended in the order they are drawn, so the fixed-function blend sees the splats front to back.
//
// The quad: the splat's 2D covariance (the projection's, dilated) has eigenvalues l1 >= l2 along e1,
// e2; alpha = opacity exp(-m^2 / 2) reaches ALPHA_MIN at the Mahalanobis radius m = sqrt(2 ln(opacity
// / ALPHA_MIN)), so the ellipse fits the rectangle of half-axes m sqrt(l1), m sqrt(l2) along e1, e2. A
// pixel's margin on each side keeps every pixel centre the fragment stage would keep inside the quad
// whatever the float rounding of the corners: outside it alpha < ALPHA_MIN, and the fragment stage
// discards those, so the margin changes no pixel.
#extension GL_GOOGLE_include_directive : require
#define TS_RASTER_PUSH
#include "common.glsl"

layout(constant_id = 0) const float ALPHA_INV = 255.0;  // 1 / ALPHA_MIN (AccuracyModes::alpha_cutoff)
// A host's surfaces in the depth attachment (RenderSettings::host), as view depths times 2^-64
// (raster_host_surfaces.comp): the splat's view depth scaled alike is its depth, and the depth test
// LESS is the tile compositor's `splat depth < host depth` to the bit (a power-of-two scaling keeps
// every float's order; view depths lie between the near plane and 2^64).
layout(constant_id = 3) const bool HOST_DEPTH = false;

// The splat's record as composite.comp reads it: (mean hi x, y, depth, opacity), (conic A, B, C,
// mean lo x), (rgb, mean lo y). Flat: the fragment stage evaluates the Gaussian at its pixel.
layout(location = 0) flat out vec4 mean_depth_opacity;
layout(location = 1) flat out vec4 conic_mean_lo_x;
layout(location = 2) flat out vec4 colour_mean_lo_y;

const vec2 CORNERS[4] = vec2[4](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));
const float MARGIN_SCALE = 1.001;
const float MARGIN_PIXELS = 0.1;

void main() {
  uint g = pc.depth_order.v[gl_InstanceIndex];
  vec4 mdo = pc.splats.v[SPLAT_VEC4S * g];
  vec4 conic = pc.splats.v[SPLAT_VEC4S * g + 1];
  vec4 colour_lo = pc.splats.v[SPLAT_VEC4S * g + 2];
  vec4 cov = pc.splats.v[SPLAT_VEC4S * g + 3];  // a, b, c of [[a b] [b c]], determinant
  mean_depth_opacity = mdo;
  conic_mean_lo_x = conic;
  colour_mean_lo_y = colour_lo;

  float m2 = 2.0 * log(mdo.w * ALPHA_INV);  // Mahalanobis radius squared where alpha = ALPHA_MIN
  float half_trace = 0.5 * (cov.x + cov.z);
  float spread = length(vec2(0.5 * (cov.x - cov.z), cov.y));
  float l1 = half_trace + spread;
  float l2 = max(half_trace - spread, 0.0);
  // e1 is along either column of cov - l2 I = (l1 - l2) e1 e1^T; the one whose diagonal entry is at
  // least `spread` has no cancellation. A circle takes any axes.
  vec2 column = cov.x >= cov.z ? vec2(half_trace + spread - cov.z, cov.y) : vec2(cov.y, half_trace + spread - cov.x);
  vec2 e1 = spread > 0.0 ? normalize(column) : vec2(1.0, 0.0);
  vec2 e2 = vec2(-e1.y, e1.x);
  vec2 half_axes = sqrt(max(m2, 0.0) * vec2(l1, l2)) * MARGIN_SCALE + MARGIN_PIXELS;
  vec2 mean = vec2(mdo.x + conic.w, mdo.y + colour_lo.w);
  vec2 corner = mean + CORNERS[gl_VertexIndex].x * half_axes.x * e1 + CORNERS[gl_VertexIndex].y * half_axes.y * e2;
  // A splat that can never reach ALPHA_MIN is a point: no pixel.
  corner = m2 > 0.0 ? corner : mean;
  gl_Position = vec4(corner / vec2(pc.width, pc.height) * 2.0 - 1.0, HOST_DEPTH ? ldexp(mdo.z, -64) : 0.0, 1.0);
}
