#include "reference/pixel_order.h"

#include <cmath>

#include "tilesplat/reference.h"

namespace tilesplat::reference {

RayDepthQuadric ray_depth_quadric(const GaussianScene& scene, size_t i, const Camera& camera) {
  const std::array<double, 9> sigma = covariance3d(&scene.log_scales[3 * i], &scene.rotations[4 * i]);
  const auto& w = camera.rotation;
  // S = W Sigma W^T, the camera-space covariance.
  double ws[9], s[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      ws[r * 3 + c] = w[size_t(r * 3)] * sigma[size_t(c)] + w[size_t(r * 3 + 1)] * sigma[size_t(3 + c)] +
                      w[size_t(r * 3 + 2)] * sigma[size_t(6 + c)];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      s[r * 3 + c] = ws[r * 3] * w[size_t(c * 3)] + ws[r * 3 + 1] * w[size_t(c * 3 + 1)] +
                     ws[r * 3 + 2] * w[size_t(c * 3 + 2)];
  RayDepthQuadric out;
  // The adjugate of S: symmetric, Q = det(S) S^-1.
  const double qxx = s[4] * s[8] - s[5] * s[7];
  const double qxy = s[5] * s[6] - s[3] * s[8];
  const double qxz = s[3] * s[7] - s[4] * s[6];
  const double qyy = s[0] * s[8] - s[2] * s[6];
  const double qyz = s[1] * s[6] - s[0] * s[7];
  const double qzz = s[0] * s[4] - s[1] * s[3];
  out.q = {qxx, qxy, qxz, qyy, qyz, qzz};
  const std::array<double, 3> mean = {scene.positions[3 * i], scene.positions[3 * i + 1],
                                      scene.positions[3 * i + 2]};
  const std::array<double, 3> mu = camera.to_camera(mean);
  out.q_mu = {qxx * mu[0] + qxy * mu[1] + qxz * mu[2], qxy * mu[0] + qyy * mu[1] + qyz * mu[2],
              qxz * mu[0] + qyz * mu[1] + qzz * mu[2]};
  out.mean_depth = mu[2];
  return out;
}

std::array<double, 2> pixel_direction(const Camera& camera, double x, double y) {
  return {(x - camera.cx) / camera.fx, (y - camera.cy) / camera.fy};
}

double ray_depth(const RayDepthQuadric& quadric, const std::array<double, 2>& d) {
  const double dx = d[0], dy = d[1];
  const auto& q = quadric.q;
  const double numerator = dx * quadric.q_mu[0] + dy * quadric.q_mu[1] + quadric.q_mu[2];
  const double denominator = dx * (q[0] * dx + 2 * (q[1] * dy + q[2])) + dy * (q[3] * dy + 2 * q[4]) + q[5];
  const double t = numerator / denominator;
  return denominator > 0 && std::isfinite(t) ? t : quadric.mean_depth;
}

}  // namespace tilesplat::reference
