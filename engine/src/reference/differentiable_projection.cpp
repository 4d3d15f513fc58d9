// reference::project (reference_projection.cpp) for the pinhole camera, transcribed into dual numbers
// step by step: the same formulas in the same order, so that the values agree with the forward's and
// the derivatives are those of the forward the reference draws.
#include "reference/differentiable_projection.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "reference/sh_basis.h"

namespace tilesplat::reference {
namespace {

using D = GaussianDual;

double low_pass_dilation(Antialiasing mode) {
  return mode == Antialiasing::kMip ? 0.1 : 0.3;
}

D sigmoid(const D& logit) {
  const double s =
      logit.v >= 0 ? 1.0 / (1.0 + std::exp(-logit.v)) : std::exp(logit.v) / (1.0 + std::exp(logit.v));
  const double e = std::exp(-std::abs(logit.v));  // s (1 - s) without the cancellation of 1 - s near 1
  return chain(logit, s, e / ((1 + e) * (1 + e)));
}

// The row-major rotation of the quaternion as the renderers read it: normalized, and the identity for
// a quaternion of zeros and float denormals (which has no derivative).
std::array<D, 9> rotation_of(const float quat_wxyz[4]) {
  D q[4];
  for (size_t k = 0; k < 4; ++k) q[k] = D::input(quat_wxyz[k], kQuatW + k);
  const double largest = std::max({std::abs(q[0].v), std::abs(q[1].v), std::abs(q[2].v), std::abs(q[3].v)});
  D w = 1, x = 0, y = 0, z = 0;
  if (largest >= double(std::numeric_limits<float>::min())) {
    const D norm = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    w = q[0] / norm;
    x = q[1] / norm;
    y = q[2] / norm;
    z = q[3] / norm;
  }
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

// Sigma = R S S^T R^T, row-major.
std::array<D, 9> covariance3d(const float log_scale[3], const float quat_wxyz[4]) {
  const std::array<D, 9> r = rotation_of(quat_wxyz);
  D scale[3];
  for (size_t axis = 0; axis < 3; ++axis) scale[axis] = exp(D::input(log_scale[axis], kLogScaleX + axis));
  D m[9];
  for (size_t row = 0; row < 3; ++row)
    for (size_t col = 0; col < 3; ++col) m[row * 3 + col] = r[row * 3 + col] * scale[col];
  std::array<D, 9> sigma{};
  for (size_t row = 0; row < 3; ++row)
    for (size_t col = 0; col < 3; ++col)
      sigma[row * 3 + col] =
          m[row * 3 + 0] * m[col * 3 + 0] + m[row * 3 + 1] * m[col * 3 + 1] + m[row * 3 + 2] * m[col * 3 + 2];
  return sigma;
}

D clamp_to(const D& value, double limit) {
  if (value.v < -limit) return D(-limit);
  if (value.v > limit) return D(limit);
  return value;
}

}  // namespace

DifferentiableSplat project_differentiable(const GaussianScene& scene, size_t i, const Camera& camera,
                                           const camera_models::ModelLimits& limits,
                                           Antialiasing antialiasing) {
  DifferentiableSplat out;
  D mean[3];
  for (size_t k = 0; k < 3; ++k) mean[k] = D::input(scene.positions[3 * i + k], kMeanX + k);
  // Camera::to_camera's W x + t, t = -W c.
  const auto& w = camera.rotation;
  D t[3];
  for (size_t row = 0; row < 3; ++row) {
    const double* wr = &w[row * 3];
    const double translation =
        -(wr[0] * camera.position[0] + wr[1] * camera.position[1] + wr[2] * camera.position[2]);
    t[row] = wr[0] * mean[0] + wr[1] * mean[1] + wr[2] * mean[2] + translation;
  }
  out.depth = t[2];
  const std::array<D, 9> sigma = covariance3d(&scene.log_scales[3 * i], &scene.rotations[4 * i]);

  // The Jacobian at the centre clamped to the field of view's 1.3x: a clamped coordinate is a constant
  // times the depth, so its derivative flows through the depth alone.
  const D& tz = t[2];
  const D tx = clamp_to(t[0] / tz, limits.clamp_x) * tz;
  const D ty = clamp_to(t[1] / tz, limits.clamp_y) * tz;
  const D j00 = camera.fx / tz, j02 = -camera.fx * tx / (tz * tz);
  const D j11 = camera.fy / tz, j12 = -camera.fy * ty / (tz * tz);
  D t0[3], t1[3];
  for (size_t k = 0; k < 3; ++k) {
    t0[k] = j00 * w[k] + j02 * w[6 + k];
    t1[k] = j11 * w[3 + k] + j12 * w[6 + k];
  }
  out.mean[0] = camera.fx * t[0] / tz + camera.cx;
  out.mean[1] = camera.fy * t[1] / tz + camera.cy;

  D sigma_t0[3], sigma_t1[3];
  for (size_t r = 0; r < 3; ++r) {
    sigma_t0[r] = sigma[r * 3] * t0[0] + sigma[r * 3 + 1] * t0[1] + sigma[r * 3 + 2] * t0[2];
    sigma_t1[r] = sigma[r * 3] * t1[0] + sigma[r * 3 + 1] * t1[1] + sigma[r * 3 + 2] * t1[2];
  }
  const double dilation = low_pass_dilation(antialiasing);
  const D a0 = t0[0] * sigma_t0[0] + t0[1] * sigma_t0[1] + t0[2] * sigma_t0[2];
  const D b = t0[0] * sigma_t1[0] + t0[1] * sigma_t1[1] + t0[2] * sigma_t1[2];
  const D c0 = t1[0] * sigma_t1[0] + t1[1] * sigma_t1[1] + t1[2] * sigma_t1[2];
  const D a = a0 + dilation;
  const D c = c0 + dilation;
  const D det = a * c - b * b;
  out.conic[0] = c / det;
  out.conic[1] = -b / det;
  out.conic[2] = a / det;

  out.opacity = sigmoid(D::input(scene.opacity_logits[i], kOpacityLogit));
  if (antialiasing != Antialiasing::kClassic) {
    const D det0 = a0 * c0 - b * b;
    const D ratio = det0.v > 0 ? det0 / det : D(0);
    out.opacity = out.opacity * (ratio.v > 2.5e-5 ? sqrt(ratio) : D(std::sqrt(2.5e-5)));
  }

  D dir[3] = {mean[0] - camera.position[0], mean[1] - camera.position[1], mean[2] - camera.position[2]};
  const D dir_length = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  if (dir_length.v > 0)
    for (D& d : dir) d = d / dir_length;
  const std::array<D, 16> basis = sh_basis(scene.sh_degree, dir[0], dir[1], dir[2]);
  const size_t k_count = size_t(scene.sh_coefficients());
  for (size_t k = 0; k < 16; ++k) out.sh_basis[k] = basis[k].v;
  const float* coefficients = &scene.sh[i * k_count * 3];
  for (size_t ch = 0; ch < 3; ++ch) {
    D sum = 0;
    for (size_t k = 0; k < k_count; ++k) sum = sum + basis[k] * double(coefficients[k * 3 + ch]);
    out.colour_clamped[ch] = !(sum.v + 0.5 > 0);
    out.colour[ch] = out.colour_clamped[ch] ? D(0) : sum + 0.5;
  }
  return out;
}

}  // namespace tilesplat::reference
