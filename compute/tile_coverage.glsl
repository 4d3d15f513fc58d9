// Which tiles of a splat's reference rect can receive any of it.
//
// The reference blends a splat into a pixel only where alpha = o exp(-q/2) >= 1/255 (the alpha
// cut-off, a mode), i.e. where q = d^T cov^-1 d <= tau = 2 ln(255 o). A tile none of whose pixel
// centres lies in that ellipse gets nothing from the splat, so leaving it out of the tile's list
// changes no pixel; it only saves sort and composite work. tau carries a margin so float rounding can never drop a contributing tile.
//
// The projection counts with row_span() and the key emission emits with it, from the same stored
// float inputs; `precise` keeps the two pipelines' arithmetic identical (no contraction). The
// composite uses ellipse_x_range() for the columns of a tile a splat reaches.

// alpha_inv = 1 / the alpha cut-off (255 in the reference; AccuracyModes::alpha_cutoff).
float coverage_tau(float opacity, float alpha_inv) {
  precise float tau = 2.0 * log(alpha_inv * opacity);
  return tau > 0.0 ? tau * 1.001 + 0.01 : -1.0;  // <= 0: alpha never reaches the cut-off
}

// x-range [left, right], relative to the mean, of the ellipse {d : d^T cov^-1 d <= tau} over the
// band of rows dy0 <= y - mean.y <= dy1; empty (left > right) when the band misses the ellipse.
vec2 ellipse_x_range(vec4 cov_det, float tau, float dy0, float dy1) {
  precise float a = cov_det.x, b = cov_det.y, c = cov_det.z, det = cov_det.w;
  precise float y_extent = sqrt(tau * c);
  if (!(tau > 0.0) || dy1 < -y_extent || dy0 > y_extent) return vec2(1.0, -1.0);
  dy0 = max(dy0, -y_extent);
  dy1 = min(dy1, y_extent);
  // x(dy) = (b dy +- sqrt(det (tau c - dy^2))) / c. The right branch is concave with its maximum
  // at dy* = b sqrt(tau / a); the left one convex with its minimum at -dy*. Over the band the
  // extremes are at those points clamped into the band.
  precise float dy_star = b * sqrt(tau / a);
  precise float dy_right = clamp(dy_star, dy0, dy1);
  precise float dy_left = clamp(-dy_star, dy0, dy1);
  precise float x_right = (b * dy_right + sqrt(max(0.0, det * (tau * c - dy_right * dy_right)))) / c;
  precise float x_left = (b * dy_left - sqrt(max(0.0, det * (tau * c - dy_left * dy_left)))) / c;
  return vec2(x_left, x_right);
}

// Tile x-range [first, last) of tile row `ty` covered by the ellipse around `mean` with the dilated
// 2D covariance (a, b, c) and its determinant, clipped to the reference rect [lo, hi).
uvec2 row_span(vec2 mean, vec4 cov_det, float tau, uint ty, uvec2 lo, uvec2 hi) {
  precise float dy0 = (float(ty * TILE_SIZE) + 0.5) - mean.y;
  precise float dy1 = dy0 + float(TILE_SIZE - 1);
  vec2 x = ellipse_x_range(cov_det, tau, dy0, dy1);
  if (!(x.x <= x.y)) return uvec2(0);
  // Tiles whose pixel centres [16 t + 0.5, 16 t + 15.5] meet [mean.x + x_left, mean.x + x_right].
  precise float first = ceil((mean.x + x.x - (float(TILE_SIZE) - 0.5)) / float(TILE_SIZE));
  precise float last = floor((mean.x + x.y - 0.5) / float(TILE_SIZE)) + 1.0;
  float f = clamp(first, float(lo.x), float(hi.x));
  float l = clamp(last, float(lo.x), float(hi.x));
  if (!(l > f)) return uvec2(0);
  return uvec2(uint(f), uint(l));
}
