// Model transforms of Gaussian scenes (rigid motion and uniform scale, with the exact rotation of the
// spherical-harmonics colour) and merging several scenes into one.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "camera/rotation_interpolation.h"
#include "scene/scene_merge.h"
#include "tilesplat/reference.h"
#include "tilesplat/scene_description.h"

namespace tilesplat {
namespace {

using Quaternion = std::array<double, 4>;  // w x y z
using Matrix3 = std::array<double, 9>;     // row-major

constexpr double kQuaternionNormTolerance = 1e-3;
// Scales this close (relative) count as equal: three copies of one computed number may differ in
// the last bit, which changes nothing a float scene can show.
constexpr double kUniformScaleTolerance = 1e-9;
constexpr int kMaxShDegree = 3;
constexpr int kShBasisCount = (kMaxShDegree + 1) * (kMaxShDegree + 1);
// Sample directions for fitting each band's rotation matrix: a band's functions are polynomials of
// degree l on the sphere, exactly determined by 2l+1 generic directions; using many well-spread
// ones by least squares keeps the fit as well conditioned as the basis itself.
constexpr int kFitDirections = 64;

Quaternion multiply(const Quaternion& a, const Quaternion& b) {
  return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
          a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
          a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
          a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}

double norm(const Quaternion& q) { return std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]); }

Quaternion normalized(const Quaternion& q) {
  const double n = norm(q);
  return {q[0] / n, q[1] / n, q[2] / n, q[3] / n};
}

Quaternion axis_rotation(size_t axis, double radians) {
  Quaternion q = {std::cos(radians / 2), 0, 0, 0};
  q[1 + axis] = std::sin(radians / 2);
  return q;
}

bool is_identity_rotation(const Quaternion& q) { return q[0] == 1 && q[1] == 0 && q[2] == 0 && q[3] == 0; }

std::array<double, 3> times(const Matrix3& m, const std::array<double, 3>& v) {
  return {m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
          m[6] * v[0] + m[7] * v[1] + m[8] * v[2]};
}

std::string format_vector(const std::array<double, 3>& v) {
  std::ostringstream out;
  out.precision(10);
  out << "(" << v[0] << ", " << v[1] << ", " << v[2] << ")";
  return out.str();
}

// Every real SH basis function up to degree 3 at `direction`, taken from eval_sh itself (a unit
// coefficient per function), so that the rotation uses exactly the renderers' basis and signs.
std::array<double, kShBasisCount> sh_basis(const std::array<double, 3>& direction) {
  std::array<double, kShBasisCount> values{};
  std::array<float, kShBasisCount * 3> unit{};
  for (size_t k = 0; k < values.size(); ++k) {
    unit[k * 3] = 1.0f;
    values[k] = eval_sh(kMaxShDegree, unit.data(), direction)[0];
    unit[k * 3] = 0.0f;
  }
  return values;
}

// Fibonacci sphere: near-uniform directions, none of them special for any band.
std::vector<std::array<double, 3>> fit_directions() {
  std::vector<std::array<double, 3>> directions;
  const double golden_angle = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < kFitDirections; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / kFitDirections;
    const double r = std::sqrt(1.0 - z * z);
    directions.push_back({r * std::cos(golden_angle * i), r * std::sin(golden_angle * i), z});
  }
  return directions;
}

// Solves lhs X = rhs for n x n lhs and n x m rhs (row-major) by Gaussian elimination with partial
// pivoting. lhs here is a Gram matrix of a basis on well-spread directions: far from singular.
std::vector<double> solve(std::vector<double> lhs, std::vector<double> rhs, size_t n, size_t m) {
  for (size_t col = 0; col < n; ++col) {
    size_t pivot = col;
    for (size_t row = col + 1; row < n; ++row)
      if (std::abs(lhs[row * n + col]) > std::abs(lhs[pivot * n + col])) pivot = row;
    for (size_t k = 0; k < n; ++k) std::swap(lhs[col * n + k], lhs[pivot * n + k]);
    for (size_t k = 0; k < m; ++k) std::swap(rhs[col * m + k], rhs[pivot * m + k]);
    for (size_t row = 0; row < n; ++row) {
      if (row == col) continue;
      const double factor = lhs[row * n + col] / lhs[col * n + col];
      for (size_t k = 0; k < n; ++k) lhs[row * n + k] -= factor * lhs[col * n + k];
      for (size_t k = 0; k < m; ++k) rhs[row * m + k] -= factor * rhs[col * m + k];
    }
  }
  for (size_t row = 0; row < n; ++row)
    for (size_t k = 0; k < m; ++k) rhs[row * m + k] /= lhs[row * n + row];
  return rhs;
}

// Band l's matrix M with c' = M c. The rotated function g(x) = f(R^T x) satisfies g(R d) = f(d);
// sampled at directions x_i: A c' = B c with A_ij = Y_j(x_i) and B_ij = Y_j(R^T x_i), so
// M = (A^T A)^-1 A^T B.
std::vector<double> fit_band(int l, const std::vector<std::array<double, kShBasisCount>>& at_directions,
                             const std::vector<std::array<double, kShBasisCount>>& at_rotated) {
  const size_t n = size_t(2 * l + 1);
  const size_t first = size_t(l * l);
  std::vector<double> gram(n * n, 0.0), cross(n * n, 0.0);
  for (size_t i = 0; i < at_directions.size(); ++i)
    for (size_t r = 0; r < n; ++r)
      for (size_t c = 0; c < n; ++c) {
        gram[r * n + c] += at_directions[i][first + r] * at_directions[i][first + c];
        cross[r * n + c] += at_directions[i][first + r] * at_rotated[i][first + c];
      }
  return solve(std::move(gram), std::move(cross), n, n);
}

size_t sh_values_per_gaussian(int degree) { return size_t((degree + 1) * (degree + 1)) * 3; }

void check_sh_degree(int degree, const char* function) {
  if (degree < 0 || degree > kMaxShDegree)
    throw std::invalid_argument(std::string(function) + ": the SH degree must be 0..3, got " + std::to_string(degree));
}

// The arrays of a scene must agree in size: a scene built by hand may not.
void check_arrays(const GaussianScene& scene, const char* function) {
  check_sh_degree(scene.sh_degree, function);
  const size_t n = scene.size();
  const bool consistent = scene.positions.size() == 3 * n && scene.log_scales.size() == 3 * n &&
                          scene.rotations.size() == 4 * n &&
                          scene.sh.size() == n * sh_values_per_gaussian(scene.sh_degree) &&
                          (scene.normals.empty() || scene.normals.size() == 3 * n);
  if (!consistent)
    throw std::invalid_argument(std::string(function) + ": the scene's arrays disagree in size with its " +
                                std::to_string(n) + " opacities");
}

float to_float_checked(double value, size_t gaussian, const char* what) {
  if (!(std::abs(value) <= double(std::numeric_limits<float>::max())))
    throw std::invalid_argument("transform_scene: the " + std::string(what) + " of Gaussian " +
                                std::to_string(gaussian) + " overflows float after the transform");
  return static_cast<float>(value);
}

void scale_log_scales(GaussianScene& scene, double s) {
  const double log_s = std::log(s);
  for (size_t i = 0; i < scene.log_scales.size(); ++i)
    scene.log_scales[i] = to_float_checked(double(scene.log_scales[i]) + log_s, i / 3, "log scale");
}

void rotate_quaternions(GaussianScene& scene, const Quaternion& q_r) {
  for (size_t i = 0; i < scene.size(); ++i) {
    float* q = &scene.rotations[4 * i];
    const Quaternion original = {q[0], q[1], q[2], q[3]};
    // The zero quaternion means the identity (as the loader and the renderers treat it).
    const bool zero = std::max({std::abs(original[0]), std::abs(original[1]), std::abs(original[2]),
                                std::abs(original[3])}) < double(std::numeric_limits<float>::min());
    const Quaternion rotated = zero ? q_r : normalized(multiply(q_r, original));
    for (size_t k = 0; k < 4; ++k) q[k] = static_cast<float>(rotated[k]);
  }
}

void rotate_normals(GaussianScene& scene, const Matrix3& r) {
  for (size_t i = 0; i < scene.normals.size() / 3; ++i) {
    float* n = &scene.normals[3 * i];
    const auto rotated = times(r, {n[0], n[1], n[2]});
    for (size_t a = 0; a < 3; ++a) n[a] = static_cast<float>(rotated[a]);
  }
}

void rotate_sh(GaussianScene& scene, const Matrix3& r) {
  if (scene.sh_degree == 0) return;
  const ShRotation rotation(r);
  const size_t stride = sh_values_per_gaussian(scene.sh_degree);
  for (size_t i = 0; i < scene.size(); ++i) rotation.apply(scene.sh_degree, &scene.sh[i * stride]);
}

// Appends one scene's SH re-laid to `degree` bands (dropping or zero-filling bands).
void append_sh(std::vector<float>& out, const GaussianScene& scene, int degree, size_t first, size_t count) {
  const size_t from = sh_values_per_gaussian(scene.sh_degree);
  const size_t to = sh_values_per_gaussian(degree);
  const size_t kept = std::min(from, to);
  for (size_t i = first; i < first + count; ++i) {
    const auto values = scene.sh.begin() + static_cast<std::ptrdiff_t>(i * from);
    out.insert(out.end(), values, values + static_cast<std::ptrdiff_t>(kept));
    out.insert(out.end(), to - kept, 0.0f);
  }
}

void append_sh(std::vector<float>& out, const GaussianScene& scene, int degree) {
  append_sh(out, scene, degree, 0, scene.size());
}

// Appends the `width` values of each of Gaussians [first, first + count).
template <typename T>
void append(std::vector<T>& out, const std::vector<T>& values, size_t first, size_t count, size_t width) {
  const auto begin = values.begin() + static_cast<std::ptrdiff_t>(first * width);
  out.insert(out.end(), begin, begin + static_cast<std::ptrdiff_t>(count * width));
}

}  // namespace

bool ModelTransform::is_identity() const {
  return translation == std::array<double, 3>{0, 0, 0} && is_identity_rotation(rotation) &&
         scale == std::array<double, 3>{1, 1, 1} && !z_up;
}

std::array<double, 4> z_up_rotation() { return axis_rotation(0, std::numbers::pi / 2); }

std::array<double, 4> quaternion_from_euler_xyz_deg(const std::array<double, 3>& degrees) {
  const double to_radians = std::numbers::pi / 180.0;
  Quaternion q = {1, 0, 0, 0};
  // Extrinsic X, then Y, then Z: each later rotation multiplies from the left.
  for (size_t axis = 0; axis < 3; ++axis) {
    if (degrees[axis] == 0) continue;
    q = multiply(axis_rotation(axis, degrees[axis] * to_radians), q);
  }
  return q;
}

std::array<double, 9> rotation_matrix(const std::array<double, 4>& quaternion) {
  const Quaternion q = normalized(quaternion);
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

std::array<double, 4> total_rotation(const ModelTransform& transform) {
  if (!transform.z_up) return transform.rotation;
  return normalized(multiply(normalized(transform.rotation), z_up_rotation()));
}

ModelTransform transform_between(const ModelTransform& start, const ModelTransform& end, double t) {
  if (!(t >= 0 && t <= 1))
    throw std::invalid_argument("transform_between: t must be in [0, 1], got " + std::to_string(t));
  validate(start);
  validate(end);
  if (start.z_up != end.z_up)
    throw std::invalid_argument("transform_between: the end transform's z_up differs from the start's");
  if (t == 0) return start;
  if (t == 1) return end;
  const auto blend = [t](double a, double b) { return a + (b - a) * t; };
  ModelTransform between = start;
  for (size_t k = 0; k < 3; ++k) {
    between.translation[k] = blend(start.translation[k], end.translation[k]);
    between.scale[k] = blend(start.scale[k], end.scale[k]);
  }
  // The quaternions as written (normalised, so that the slerp's result is one too): a still rotation stays
  // bit-identical.
  if (start.rotation != end.rotation)
    between.rotation = slerp(normalized(start.rotation), normalized(end.rotation), t);
  return between;
}

void validate(const ModelTransform& transform) {
  for (const double value : transform.translation)
    if (!std::isfinite(value)) throw std::invalid_argument("the translation must be finite");
  const double q_norm = norm(transform.rotation);
  if (!std::isfinite(q_norm) || !(std::abs(q_norm - 1.0) <= kQuaternionNormTolerance)) {
    std::ostringstream message;
    message << "the rotation must be a unit quaternion w x y z (norm 1 within " << kQuaternionNormTolerance
            << "), its norm is " << q_norm;
    throw std::invalid_argument(message.str());
  }
  for (const double value : transform.scale)
    if (!std::isfinite(value) || !(value > 0))
      throw std::invalid_argument("the scale must be positive and finite, got " + format_vector(transform.scale));
  const auto [low, high] = std::minmax({transform.scale[0], transform.scale[1], transform.scale[2]});
  if (high - low > kUniformScaleTolerance * high)
    throw std::invalid_argument(
        "non-uniform scale " + format_vector(transform.scale) +
        " is not supported: a Gaussian's view-dependent colour (spherical harmonics) is a function of the "
        "view direction, and a non-uniform scale bends directions in a way no SH of degree 3 or less can "
        "follow, so the scaled scene would not look like the stretched capture; use one uniform scale");
}

ShRotation::ShRotation(const std::array<double, 9>& rotation) {
  const auto directions = fit_directions();
  std::vector<std::array<double, kShBasisCount>> at_directions, at_rotated;
  for (const auto& x : directions) {
    at_directions.push_back(sh_basis(x));
    // R^T x: the direction that R takes to x.
    const std::array<double, 3> back = {rotation[0] * x[0] + rotation[3] * x[1] + rotation[6] * x[2],
                                        rotation[1] * x[0] + rotation[4] * x[1] + rotation[7] * x[2],
                                        rotation[2] * x[0] + rotation[5] * x[1] + rotation[8] * x[2]};
    at_rotated.push_back(sh_basis(back));
  }
  bands_[0] = {1.0};  // the DC term does not depend on direction
  for (int l = 1; l <= kMaxShDegree; ++l) bands_[size_t(l)] = fit_band(l, at_directions, at_rotated);
}

void ShRotation::apply(int degree, float* coefficients) const {
  check_sh_degree(degree, "ShRotation::apply");
  for (int l = 1; l <= degree; ++l) {
    const size_t n = size_t(2 * l + 1);
    const size_t first = size_t(l * l);
    const std::vector<double>& m = bands_[size_t(l)];
    for (size_t channel = 0; channel < 3; ++channel) {
      std::array<double, 7> in{};
      for (size_t j = 0; j < n; ++j) in[j] = coefficients[(first + j) * 3 + channel];
      for (size_t i = 0; i < n; ++i) {
        double sum = 0;
        for (size_t j = 0; j < n; ++j) sum += m[i * n + j] * in[j];
        coefficients[(first + i) * 3 + channel] = static_cast<float>(sum);
      }
    }
  }
}

std::span<const double> ShRotation::band(int l) const {
  if (l < 0 || l > kMaxShDegree) throw std::out_of_range("ShRotation::band: l must be 0..3");
  return bands_[size_t(l)];
}

GaussianScene transform_scene(const GaussianScene& scene, const ModelTransform& transform) {
  try {
    validate(transform);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(std::string("transform_scene: ") + error.what());
  }
  check_arrays(scene, "transform_scene");
  if (transform.is_identity()) return scene;

  const Quaternion q_r = normalized(total_rotation(transform));
  const bool rotates = !is_identity_rotation(q_r);
  const Matrix3 r = rotation_matrix(q_r);
  const double s = transform.scale[0];

  GaussianScene out = scene;
  const detail::PositionPlacement placement(transform);
  for (size_t i = 0; i < out.size(); ++i) {
    const std::array<float, 3> p = placement.place(&out.positions[3 * i], i);
    std::copy(p.begin(), p.end(), &out.positions[3 * i]);
  }
  if (s != 1.0) scale_log_scales(out, s);
  if (rotates) {
    rotate_quaternions(out, q_r);
    rotate_sh(out, r);
    rotate_normals(out, r);
  }
  return out;
}

Camera transform_camera(const Camera& camera, const ModelTransform& transform) {
  validate(transform);
  const Matrix3 r = rotation_matrix(total_rotation(transform));
  const double s = transform.scale[0];
  Camera out = camera;
  const auto centre = times(r, camera.position);
  for (size_t a = 0; a < 3; ++a) out.position[a] = s * centre[a] + transform.translation[a];
  // W' = W R^T: a world point's camera coordinates are unchanged by moving both (up to the scale s).
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < 3; ++j) {
      double sum = 0;
      for (size_t k = 0; k < 3; ++k) sum += camera.rotation[i * 3 + k] * r[j * 3 + k];
      out.rotation[i * 3 + j] = sum;
    }
  return out;
}

GaussianScene with_sh_degree(const GaussianScene& scene, int degree) {
  check_sh_degree(degree, "with_sh_degree");
  check_arrays(scene, "with_sh_degree");
  if (degree == scene.sh_degree) return scene;
  GaussianScene out = scene;
  out.sh_degree = degree;
  out.sh.clear();
  out.sh.reserve(scene.size() * sh_values_per_gaussian(degree));
  append_sh(out.sh, scene, degree);
  return out;
}

namespace detail {

PositionPlacement::PositionPlacement(const ModelTransform& transform)
    : rotation_(rotation_matrix(normalized(total_rotation(transform)))),
      rotates_(!is_identity_rotation(normalized(total_rotation(transform)))),
      scale_(transform.scale[0]),
      translation_(transform.translation) {}

std::array<float, 3> PositionPlacement::place(const float* p, size_t gaussian) const {
  std::array<double, 3> v = {p[0], p[1], p[2]};
  if (rotates_) v = times(rotation_, v);
  std::array<float, 3> out;
  for (size_t a = 0; a < 3; ++a)
    out[a] = to_float_checked(scale_ * v[a] + translation_[a], gaussian, "position");
  return out;
}

void reserve_merged(GaussianScene& out, size_t total, int sh_degree, bool with_normals) {
  out.sh_degree = sh_degree;
  out.positions.reserve(3 * total);
  out.log_scales.reserve(3 * total);
  out.rotations.reserve(4 * total);
  out.opacity_logits.reserve(total);
  out.sh.reserve(total * sh_values_per_gaussian(sh_degree));
  if (with_normals) out.normals.reserve(3 * total);
}

void append_merged(GaussianScene& out, const GaussianScene& scene, bool with_normals) {
  append_merged(out, scene, with_normals, 0, scene.size());
}

void append_merged(GaussianScene& out, const GaussianScene& scene, bool with_normals, size_t first,
                   size_t count) {
  check_arrays(scene, "merge_scenes");
  if (first > scene.size() || count > scene.size() - first)
    throw std::invalid_argument("merge_scenes: Gaussians " + std::to_string(first) + " to " +
                                std::to_string(first + count) + " of a scene of " +
                                std::to_string(scene.size()));
  append(out.positions, scene.positions, first, count, 3);
  append(out.log_scales, scene.log_scales, first, count, 3);
  append(out.rotations, scene.rotations, first, count, 4);
  append(out.opacity_logits, scene.opacity_logits, first, count, 1);
  append_sh(out.sh, scene, out.sh_degree, first, count);
  if (!with_normals) return;
  if (scene.has_normals())
    append(out.normals, scene.normals, first, count, 3);
  else
    out.normals.insert(out.normals.end(), 3 * count, 0.0f);
}

}  // namespace detail

GaussianScene merge_scenes(std::span<const GaussianScene> scenes) {
  GaussianScene out;
  size_t total = 0;
  int sh_degree = 0;
  bool any_normals = false;
  for (const GaussianScene& scene : scenes) {
    check_arrays(scene, "merge_scenes");
    sh_degree = std::max(sh_degree, scene.sh_degree);
    total += scene.size();
    any_normals = any_normals || scene.has_normals();
  }
  detail::reserve_merged(out, total, sh_degree, any_normals);
  for (const GaussianScene& scene : scenes) detail::append_merged(out, scene, any_normals);
  return out;
}

}  // namespace tilesplat
