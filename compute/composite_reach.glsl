// Which pixels of a 16x16 tile a staged splat can reach, shared by the composites that stage splats
// through shared memory (composite.comp, composite_stochastic.comp). Include after tile_coverage.glsl.
//
// A splat's reach is the columns its alpha >= cut-off ellipse meets in rows 0-7 and in rows 8-15.
// Pixels outside would be no-ops (the reference skips them too). GPUs simply branch on it; CPU drivers
// execute both sides of every branch under a lane mask and only leave a loop for real, so there each
// invocation lists the splats that reach its column and then loops over just those.

// Inclusive range of tile-local pixel indices i whose centres i + 0.5 lie in [lo, hi] (relative to
// the tile origin), clamped to the tile; x > y when there is none. 1e-3 px of slack on top of
// coverage_tau's margin: the range may only ever be too large.
ivec2 pixel_span(float lo, float hi) {
  float first = ceil(lo - 0.5 - 1e-3);
  float last = floor(hi - 0.5 + 1e-3);
  if (!(last >= 0.0 && first <= float(TILE_SIZE - 1) && first <= last)) return ivec2(1, 0);
  return ivec2(clamp(first, 0.0, float(TILE_SIZE - 1)), clamp(last, 0.0, float(TILE_SIZE - 1)));
}

// Which columns of the tile the splat's alpha >= cut-off ellipse reaches within rows 0-7 (bits 0-15)
// and within rows 8-15 (bits 16-31): the ellipse cut to a band of rows is convex, so per band it
// is one x-range (ellipse_x_range, shared with the tile coverage). alpha_inv = 1 / the cut-off.
uint splat_reach(vec2 centre, float opacity, vec4 cov_det, float alpha_inv) {
  float tau = coverage_tau(opacity, alpha_inv);
  uint reach = 0u;
  for (uint band = 0; band < 2; ++band) {
    float band_top = float(band * 8) + 0.5 - centre.y;
    vec2 x = ellipse_x_range(cov_det, tau, band_top, band_top + 7.0);
    ivec2 columns = pixel_span(centre.x + x.x, centre.x + x.y);
    if (columns.x <= columns.y)  // an empty x-range gives an empty span
      reach |= ((2u << columns.y) - (1u << columns.x)) << (16 * band);
  }
  return reach;
}

// An invocation's bits in a splat's reach mask: its column local_x, in the band(s) of its
// pixels_per_invocation rows starting at local_y0.
uint my_reach_bits(uint local_x, uint local_y0, uint pixels_per_invocation) {
  uint bands = pixels_per_invocation > 8 ? 0x10001u : 1u << (16 * (local_y0 / 8));
  return bands << local_x;
}
