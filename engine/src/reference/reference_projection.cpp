// The float64 reference's projection of one Gaussian (docs/rendering-math.md): its rotation and 3D
// covariance, the camera transform and culls, the EWA Jacobian and the dilated 2D covariance, the
// tile rectangle, the SH colour and the light factor. render_reference (reference_renderer.cpp) sorts
// and blends what this returns. Everything is computed in double from the scene's float inputs.
#include "reference/reference_projection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <string>

#include "camera/camera_models.h"
#include "lighting.h"
#include "reference/sh_basis.h"
#include "settings_checks.h"
#include "tilesplat/reference.h"

namespace tilesplat {
namespace {

// The low-pass filter added to every 2D covariance, per antialiasing mode.
double low_pass_dilation(Antialiasing mode) {
  return mode == Antialiasing::kMip ? 0.1 : 0.3;
}
constexpr double kMinEigenGap = 0.1;
constexpr double kFloatMax = std::numeric_limits<float>::max();

double sigmoid(double logit) {
  // exp of a large positive argument overflows; use the form whose exponent is never positive.
  if (logit >= 0) return 1.0 / (1.0 + std::exp(-logit));
  const double e = std::exp(logit);
  return e / (1.0 + e);
}

bool all_finite(std::initializer_list<double> values) {
  for (double v : values)
    if (!std::isfinite(v)) return false;
  return true;
}

// floor(value / tile) clamped to [0, grid] in double, so a huge or infinite value cannot overflow int.
int clamped_tile(double value, int grid) {
  const double tile = std::floor(value / kTileSize);
  return static_cast<int>(std::clamp(tile, 0.0, static_cast<double>(grid)));
}

// Row-major rotation of a w x y z quaternion as the renderers read it (normalized; zero = identity).
std::array<double, 9> rotation_of(const float quat_wxyz[4]) {
  double w = quat_wxyz[0], x = quat_wxyz[1], y = quat_wxyz[2], z = quat_wxyz[3];
  const double norm = std::sqrt(w * w + x * x + y * y + z * z);
  // A quaternion of zeros and float denormals is the zero quaternion: GPUs may flush denormals to
  // zero on load, and every renderer must agree on which rotation the splat has.
  const double largest = std::max({std::abs(w), std::abs(x), std::abs(y), std::abs(z)});
  if (largest < double(std::numeric_limits<float>::min())) {
    w = 1;
    x = y = z = 0;
  } else {
    w /= norm;
    x /= norm;
    y /= norm;
    z /= norm;
  }
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

// The normal relighting uses (tilesplat::Lighting): the file's when finite and non-zero, else the
// shortest axis; turned toward the camera.
std::array<double, 3> lighting_normal(const GaussianScene& scene, size_t i, const std::array<double, 3>& x,
                                      const Camera& camera) {
  std::array<double, 3> n = {0, 0, 0};
  bool from_file = false;
  if (scene.has_normals()) {
    const float* f = &scene.normals[3 * i];
    // Zeros and float denormals are no normal: a GPU may flush denormals to zero on load, and
    // both renderers must decide alike (as for the zero quaternion).
    const float largest = std::max({std::abs(f[0]), std::abs(f[1]), std::abs(f[2])});
    if (std::isfinite(f[0]) && std::isfinite(f[1]) && std::isfinite(f[2]) &&
        largest >= std::numeric_limits<float>::min()) {
      n = {f[0], f[1], f[2]};
      const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (double& v : n) v /= length;
      from_file = true;
    }
  }
  if (!from_file) {
    // The axis of the smallest scale, compared as the stored floats (exp is monotonic), first on ties.
    const float* s = &scene.log_scales[3 * i];
    const size_t axis = s[0] <= s[1] && s[0] <= s[2] ? 0 : s[1] <= s[2] ? 1 : 2;
    const std::array<double, 9> r = rotation_of(&scene.rotations[4 * i]);
    n = {r[axis], r[3 + axis], r[6 + axis]};
  }
  const double toward_camera = n[0] * (camera.position[0] - x[0]) + n[1] * (camera.position[1] - x[1]) +
                               n[2] * (camera.position[2] - x[2]);
  if (toward_camera < 0)
    for (double& v : n) v = -v;
  return n;
}

}  // namespace

std::array<double, 9> covariance3d(const float log_scale[3], const float quat_wxyz[4]) {
  const double sx = std::exp(double(log_scale[0]));
  const double sy = std::exp(double(log_scale[1]));
  const double sz = std::exp(double(log_scale[2]));
  const std::array<double, 9> r = rotation_of(quat_wxyz);
  // M = R S scales the columns of R; Sigma = M M^T.
  const double scale[3] = {sx, sy, sz};
  double m[9];
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) m[row * 3 + col] = r[size_t(row * 3 + col)] * scale[col];
  std::array<double, 9> sigma{};
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col)
      sigma[static_cast<size_t>(row * 3 + col)] =
          m[row * 3 + 0] * m[col * 3 + 0] + m[row * 3 + 1] * m[col * 3 + 1] + m[row * 3 + 2] * m[col * 3 + 2];
  return sigma;
}

std::array<double, 3> eval_sh(int degree, const float* coeffs, const std::array<double, 3>& dir) {
  if (degree < 0 || degree > 3)
    throw std::invalid_argument("eval_sh: degree must be 0..3, got " + std::to_string(degree));
  const std::array<double, 16> basis = reference::sh_basis(degree, dir[0], dir[1], dir[2]);
  const int k_count = (degree + 1) * (degree + 1);
  std::array<double, 3> result{};
  for (int c = 0; c < 3; ++c) {
    double sum = 0;
    for (int k = 0; k < k_count; ++k) sum += basis[size_t(k)] * double(coeffs[k * 3 + c]);
    result[size_t(c)] = sum;
  }
  return result;
}

namespace reference {

ProjectedGaussian project(const GaussianScene& scene, size_t i, const Camera& camera,
                          const camera_models::ModelLimits& limits, Antialiasing antialiasing,
                          const PreparedLighting& lighting, double near_plane, uint32_t seam_copy) {
  ProjectedGaussian out;
  const std::array<double, 3> mean = {scene.positions[3 * i], scene.positions[3 * i + 1],
                                      scene.positions[3 * i + 2]};
  const std::array<double, 3> t = camera.to_camera(mean);
  out.depth = t[2];
  const bool pinhole = camera_models::drawn_model(camera) == CameraModel::kPinhole;
  if (pinhole) {
    // Written as a negated comparison so that a NaN depth is culled too.
    if (!(t[2] > near_plane) || !all_finite({t[0], t[1], t[2]})) return out;
  } else if (!all_finite({t[0], t[1], t[2]})) {
    return out;
  }

  // Scales are float32 values: a log scale whose exp overflows a float is an infinite scale (the GPU
  // evaluates exp in float32), and an infinite scale has no usable covariance.
  for (int axis = 0; axis < 3; ++axis)
    if (!(std::exp(double(scene.log_scales[3 * i + size_t(axis)])) <= kFloatMax)) return out;
  const std::array<double, 9> sigma = covariance3d(&scene.log_scales[3 * i], &scene.rotations[4 * i]);

  // T = J W (2x3), J the projection's Jacobian at the centre.
  const auto& w = camera.rotation;
  double t0[3], t1[3];
  if (pinhole) {
    // The Jacobian is evaluated at a point clamped to 1.3x the field of view so that splats far
    // outside the frame do not get absurdly stretched footprints; the mean itself is not clamped.
    const double limit_x = limits.clamp_x;
    const double limit_y = limits.clamp_y;
    const double tz = t[2];
    const double tx = std::clamp(t[0] / tz, -limit_x, limit_x) * tz;
    const double ty = std::clamp(t[1] / tz, -limit_y, limit_y) * tz;
    const double j00 = camera.fx / tz, j02 = -camera.fx * tx / (tz * tz);
    const double j11 = camera.fy / tz, j12 = -camera.fy * ty / (tz * tz);
    for (size_t k = 0; k < 3; ++k) {
      t0[k] = j00 * w[k] + j02 * w[6 + k];
      t1[k] = j11 * w[3 + k] + j12 * w[6 + k];
    }
    out.mean[0] = camera.fx * t[0] / tz + camera.cx;
    out.mean[1] = camera.fy * t[1] / tz + camera.cy;
  } else {  // the other models' centre and Jacobian (camera_models.cpp)
    const camera_models::CentreProjection centre =
        camera_models::project_centre(camera, limits, t, near_plane, seam_copy);
    out.depth = centre.depth;
    if (!centre.visible) return out;
    const auto& ju = centre.jacobian_u;
    const auto& jv = centre.jacobian_v;
    for (size_t k = 0; k < 3; ++k) {
      t0[k] = ju[0] * w[k] + ju[1] * w[3 + k] + ju[2] * w[6 + k];
      t1[k] = jv[0] * w[k] + jv[1] * w[3 + k] + jv[2] * w[6 + k];
    }
    out.mean[0] = centre.pixel[0];
    out.mean[1] = centre.pixel[1];
  }
  double sigma_t0[3], sigma_t1[3];
  for (size_t r = 0; r < 3; ++r) {
    sigma_t0[r] = sigma[r * 3] * t0[0] + sigma[r * 3 + 1] * t0[1] + sigma[r * 3 + 2] * t0[2];
    sigma_t1[r] = sigma[r * 3] * t1[0] + sigma[r * 3 + 1] * t1[1] + sigma[r * 3 + 2] * t1[2];
  }
  const double dilation = low_pass_dilation(antialiasing);
  const double a0 = t0[0] * sigma_t0[0] + t0[1] * sigma_t0[1] + t0[2] * sigma_t0[2];
  const double b = t0[0] * sigma_t1[0] + t0[1] * sigma_t1[1] + t0[2] * sigma_t1[2];
  const double c0 = t1[0] * sigma_t1[0] + t1[1] * sigma_t1[1] + t1[2] * sigma_t1[2];
  const double a = a0 + dilation;
  const double c = c0 + dilation;
  out.cov2d[0] = a;
  out.cov2d[1] = b;
  out.cov2d[2] = c;

  const double det = a * c - b * b;
  // The composite works in float32 relative to the mean: a mean beyond the float range is culled.
  if (!all_finite({a, b, c, det, out.mean[0], out.mean[1]}) || !(det > 0) ||
      !(std::abs(out.mean[0]) <= kFloatMax) || !(std::abs(out.mean[1]) <= kFloatMax))
    return out;
  out.conic[0] = c / det;
  out.conic[1] = -b / det;
  out.conic[2] = a / det;

  const double mid = 0.5 * (a + c);
  const double lambda = mid + std::sqrt(std::max(kMinEigenGap, mid * mid - det));
  const double radius = std::ceil(3.0 * std::sqrt(lambda));
  if (!all_finite({out.conic[0], out.conic[1], out.conic[2], radius})) return out;
  out.radius = static_cast<int>(std::min(radius, double(std::numeric_limits<int>::max())));

  const int grid_x = (camera.width + kTileSize - 1) / kTileSize;
  const int grid_y = (camera.height + kTileSize - 1) / kTileSize;
  out.tile_min[0] = clamped_tile(out.mean[0] - radius, grid_x);
  out.tile_min[1] = clamped_tile(out.mean[1] - radius, grid_y);
  out.tile_max[0] = clamped_tile(out.mean[0] + radius + kTileSize - 1, grid_x);
  out.tile_max[1] = clamped_tile(out.mean[1] + radius + kTileSize - 1, grid_y);
  const long long tiles_touched = static_cast<long long>(out.tile_max[0] - out.tile_min[0]) *
                                  static_cast<long long>(out.tile_max[1] - out.tile_min[1]);
  if (tiles_touched <= 0) return out;

  // A NaN opacity or a non-finite colour has no meaning: the splat is culled rather than blended
  // (std::min(0.99, NaN) would draw it opaque). +-inf logits are opacities 1 and 0 and stay.
  if (std::isnan(scene.opacity_logits[i])) return out;
  out.opacity = sigmoid(scene.opacity_logits[i]);
  // The filtered footprint is larger than the splat; these modes keep its integral (its energy).
  if (antialiasing != Antialiasing::kClassic)
    out.opacity *= std::sqrt(std::max(2.5e-5, std::max(0.0, a0 * c0 - b * b) / det));
  // The SH are seen along the ray from the camera; an orthographic camera's rays are all its axis.
  std::array<double, 3> dir = {mean[0] - camera.position[0], mean[1] - camera.position[1],
                               mean[2] - camera.position[2]};
  if (camera.model == CameraModel::kOrthographic) dir = {w[6], w[7], w[8]};
  const double dir_length = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  if (dir_length > 0)
    for (double& d : dir) d /= dir_length;
  const size_t k = static_cast<size_t>(scene.sh_coefficients());
  const std::array<double, 3> sh = eval_sh(scene.sh_degree, &scene.sh[i * k * 3], dir);
  for (size_t ch = 0; ch < 3; ++ch) {
    if (!(std::abs(sh[ch] + 0.5) <= kFloatMax)) return out;  // the colour must be a finite float
    out.color[ch] = std::max(sh[ch] + 0.5, 0.0);
  }
  if (!lighting.lights.empty()) {  // relighting: the unlit colour is the albedo
    const std::array<double, 3> factor =
        light_factor(lighting, mean, lighting_normal(scene, i, mean, camera));
    for (size_t ch = 0; ch < 3; ++ch) {
      out.color[ch] *= factor[ch];
      if (!(out.color[ch] <= kFloatMax)) return out;  // the lit colour must be a finite float too
    }
  }
  out.visible = true;
  return out;
}

void check_normals(const GaussianScene& scene) {
  if (scene.has_normals() && scene.normals.size() != 3 * scene.size())
    throw std::invalid_argument("render_reference: scene normals must be empty or 3 per Gaussian");
}

}  // namespace reference

ProjectedGaussian project_gaussian(const GaussianScene& scene, size_t i, const Camera& camera,
                                   Antialiasing antialiasing, const Lighting& lighting, double near_plane) {
  if (i >= scene.size()) throw std::out_of_range("project_gaussian: index out of range");
  check_near_plane(near_plane);
  if (lighting.enabled()) reference::check_normals(scene);
  validate(camera);
  return reference::project(scene, i, camera, camera_models::model_limits(camera), antialiasing,
                            prepare_lighting(lighting), near_plane);
}

}  // namespace tilesplat
