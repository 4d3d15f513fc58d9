// The raster compositor's quads (RasterCompositePass), shared by its vertex stage (raster_quad.vert,
// four vertices an instance) and its mesh stage (raster_quads.mesh, 32 splats a workgroup): the i-th
// splat in depth order and the corners of the quad it is drawn as. Needs RasterPush (TS_RASTER_PUSH).
//
// The quad: the splat's 2D covariance (the projection's, dilated) has eigenvalues l1 >= l2 along e1,
// e2; alpha = opacity exp(-m^2 / 2) reaches ALPHA_MIN at the Mahalanobis radius m = sqrt(2 ln(opacity
// / ALPHA_MIN)), so the ellipse fits the rectangle of half-axes m sqrt(l1), m sqrt(l2) along e1, e2. A
// margin (a thousandth and a tenth of a pixel) keeps every pixel centre the fragment stage would keep
// inside the quad whatever the float rounding of the corners: outside it alpha < ALPHA_MIN, and the
// fragment stage discards those, so the margin changes no pixel.

layout(constant_id = 0) const float ALPHA_INV = 255.0;  // 1 / ALPHA_MIN (AccuracyModes::alpha_cutoff)
// A host's surfaces in the depth attachment (RenderSettings::host), as view depths times 2^-64
// (raster_host_surfaces.comp): the splat's view depth scaled alike is its depth, and the depth test
// LESS is the tile compositor's `splat depth < host depth` to the bit (a power-of-two scaling keeps
// every float's order; view depths lie between the near plane and 2^64).
layout(constant_id = 3) const bool HOST_DEPTH = false;

// The corners of a quad in the order of a triangle strip (the mesh stage's two triangles: 0 1 2, 2 1 3).
const vec2 QUAD_CORNERS[4] = vec2[4](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));
const float QUAD_MARGIN_SCALE = 1.001;
const float QUAD_MARGIN_PIXELS = 0.1;

// The splat's record as composite.comp reads it: (mean hi x, y, depth, opacity), (conic A, B, C,
// mean lo x), (rgb, mean lo y), which the fragment stage takes flat; and its quad in clip space.
struct RasterQuad {
  vec4 mean_depth_opacity;
  vec4 conic_mean_lo_x;
  vec4 colour_mean_lo_y;
  vec2 centre;    // pixels
  vec2 axis_x;    // half-axis vectors in pixels: a corner is centre +- axis_x +- axis_y
  vec2 axis_y;
  float depth;    // the clip-space z of every corner
};

RasterQuad raster_quad(uint position) {
  uint g = pc.depth_order.v[position];
  RasterQuad q;
  q.mean_depth_opacity = pc.splats.v[SPLAT_VEC4S * g];
  q.conic_mean_lo_x = pc.splats.v[SPLAT_VEC4S * g + 1];
  q.colour_mean_lo_y = pc.splats.v[SPLAT_VEC4S * g + 2];
  vec4 cov = pc.splats.v[SPLAT_VEC4S * g + 3];  // a, b, c of [[a b] [b c]], determinant
  vec4 mdo = q.mean_depth_opacity;

  float m2 = min(2.0 * log(mdo.w * ALPHA_INV), 200.0);  // Mahalanobis radius squared where alpha = ALPHA_MIN
  float half_trace = 0.5 * (cov.x + cov.z);
  float spread = length(vec2(0.5 * (cov.x - cov.z), cov.y));
  float l1 = half_trace + spread;
  float l2 = max(half_trace - spread, 0.0);
  // e1 is along either column of cov - l2 I = (l1 - l2) e1 e1^T; the one whose diagonal entry is at
  // least `spread` has no cancellation. A circle takes any axes.
  vec2 column = cov.x >= cov.z ? vec2(half_trace + spread - cov.z, cov.y) : vec2(cov.y, half_trace + spread - cov.x);
  vec2 e1 = spread > 0.0 ? normalize(column) : vec2(1.0, 0.0);
  vec2 e2 = vec2(-e1.y, e1.x);
  vec2 half_axes = sqrt(max(m2, 0.0) * vec2(l1, l2)) * QUAD_MARGIN_SCALE + QUAD_MARGIN_PIXELS;
  // A splat that can never reach ALPHA_MIN is a point: no pixel.
  half_axes = m2 > 0.0 ? half_axes : vec2(0.0);
  q.centre = vec2(mdo.x + q.conic_mean_lo_x.w, mdo.y + q.colour_mean_lo_y.w);
  q.axis_x = half_axes.x * e1;
  q.axis_y = half_axes.y * e2;
  q.depth = HOST_DEPTH ? ldexp(mdo.z, -64) : 0.0;
  return q;
}

vec4 raster_corner(RasterQuad q, uint corner) {
  vec2 pixel = q.centre + QUAD_CORNERS[corner].x * q.axis_x + QUAD_CORNERS[corner].y * q.axis_y;
  // The camera's pixel in the attachments, which start at their first tile's corner (a region's).
  pixel -= vec2(first_tile_of(pc.first_tile) * TILE_SIZE);
  return vec4(pixel / vec2(pc.width, pc.height) * 2.0 - 1.0, q.depth, 1.0);
}
