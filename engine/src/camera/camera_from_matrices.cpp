// Camera::from_matrices: a host application's view and projection matrices as the pinhole camera of
// the trainer's convention (OpenCV axes), so that a host renders splats with the camera it already has.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "camera/rotation_check.h"
#include "tilesplat/camera.h"

namespace tilesplat {
namespace {

using Matrix = std::array<double, 16>;

// Element (row, column) of a column-major 4x4 matrix.
double at(const Matrix& m, int row, int column) {
  return m[size_t(column) * 4 + size_t(row)];
}

[[noreturn]] void fail(const std::string& why) {
  throw std::invalid_argument("Camera::from_matrices: " + why);
}

std::string element(const char* matrix, int row, int column) {
  return std::string(matrix) + "(" + std::to_string(row) + ", " + std::to_string(column) + ")";
}

void check_view(const Matrix& view) {
  for (int row = 0; row < 4; ++row)
    for (int column = 0; column < 4; ++column)
      if (!std::isfinite(at(view, row, column))) fail(element("view", row, column) + " is not finite");
  if (at(view, 3, 0) != 0 || at(view, 3, 1) != 0 || at(view, 3, 2) != 0 || at(view, 3, 3) != 1)
    fail("the view matrix's last row must be 0 0 0 1 (a rigid transform of world to view space)");
  std::array<double, 9> block{};
  for (int row = 0; row < 3; ++row)
    for (int column = 0; column < 3; ++column) block[size_t(row * 3 + column)] = at(view, row, column);
  if (const std::optional<std::string> problem = orthonormality_problem(block))
    fail("the view matrix is not rigid: its 3x3 block " + *problem + "; scale the scene, not the camera");
}

// A relative zero: projections hosts build have exact zeros there, or float rounding of them.
bool negligible(double value, double scale) {
  return std::fabs(value) <= 1e-6 * scale;
}

}  // namespace

Camera Camera::from_matrices(const Matrix& view, const Matrix& projection, int width, int height,
                             ClipSpace clip) {
  if (width <= 0 || height <= 0)
    fail("image size " + std::to_string(width) + "x" + std::to_string(height) + " is not positive");
  check_view(view);
  for (int row = 0; row < 4; ++row)
    for (int column = 0; column < 4; ++column)
      if (!std::isfinite(at(projection, row, column)))
        fail(element("projection", row, column) + " is not finite");

  // Row 3 gives clip w. A pinhole's is +-k times view z alone; an orthographic projection's is 0 0 0 1.
  const double w_z = at(projection, 3, 2);
  const double scale = std::fabs(w_z);
  if (scale == 0 || !negligible(at(projection, 3, 3), scale))
    fail(
        "the projection is orthographic (clip w does not grow with depth): tilesplat renders pinhole cameras "
        "only");
  if (!negligible(at(projection, 3, 0), scale) || !negligible(at(projection, 3, 1), scale))
    fail("the projection's w row mixes in view x or y (row 3 must be 0 0 +-1 0): not a pinhole camera");
  const double x_x = at(projection, 0, 0), y_y = at(projection, 1, 1);
  if (x_x == 0 || y_y == 0) fail("the projection maps view x or y to nothing (a zero on its diagonal)");
  if (!negligible(at(projection, 0, 1), std::fabs(x_x)) || !negligible(at(projection, 1, 0), std::fabs(y_y)))
    fail("the projection is skewed (x and y mix): tilesplat renders pinhole cameras without skew only");
  if (!negligible(at(projection, 0, 3), std::fabs(x_x)) || !negligible(at(projection, 1, 3), std::fabs(y_y)))
    fail(
        "the projection shifts x or y by a constant (a column 3 entry in rows 0 or 1): not a pinhole camera");

  // Clip w = w_z z_view, so the forward distance is z_view * sign(w_z). NDC x = (x_x x + x_z z) / w
  // covers the image width over [-1, 1]: px = width / 2 (1 + ndc_x). With the camera's x along the image
  // columns (its sign chosen so that fx > 0) this is the pinhole px = cx + fx x_cam / z_cam.
  const double forward = w_z > 0 ? 1.0 : -1.0;
  const double x_sign = x_x > 0 ? 1.0 : -1.0;
  // Image rows run down: with NDC y down, row = height / 2 (1 + ndc_y); with NDC y up, (1 - ndc_y).
  const double ndc_y_to_rows = clip.y == ClipSpace::Y::kDown ? 1.0 : -1.0;
  const double y_sign = y_y * ndc_y_to_rows > 0 ? 1.0 : -1.0;

  Camera camera;
  camera.width = width;
  camera.height = height;
  camera.fx = 0.5 * width * std::fabs(x_x) / scale;
  camera.fy = 0.5 * height * std::fabs(y_y) / scale;
  camera.cx = 0.5 * width * (1.0 + at(projection, 0, 2) / w_z);
  camera.cy = 0.5 * height * (1.0 + ndc_y_to_rows * at(projection, 1, 2) / w_z);

  // The camera's axes are the view's rows, signed: x_cam = x_sign x_view, y_cam = y_sign y_view,
  // z_cam = forward z_view. Its centre is where the view puts the origin: -R^T t.
  const std::array<double, 3> signs = {x_sign, y_sign, forward};
  for (int row = 0; row < 3; ++row)
    for (int column = 0; column < 3; ++column)
      camera.rotation[size_t(row) * 3 + size_t(column)] = signs[size_t(row)] * at(view, row, column);
  for (int column = 0; column < 3; ++column) {
    double centre = 0;
    for (int row = 0; row < 3; ++row) centre -= at(view, row, column) * at(view, row, 3);
    camera.position[size_t(column)] = centre;
  }
  return camera;
}

}  // namespace tilesplat

namespace tilesplat {

DepthConvention DepthConvention::from_projection(const std::array<double, 16>& projection, ClipSpace clip) {
  auto at = [&](int row, int column) { return projection[size_t(column) * 4 + size_t(row)]; };
  for (double value : projection)
    if (!std::isfinite(value))
      throw std::invalid_argument("DepthConvention::from_projection: a non-finite entry");
  // Clip w = w_z z_view and the camera's z = sign(w_z) z_view (Camera::from_matrices), so NDC depth
  // = (z_z z_view + z_w) / (w_z z_view) = z_z / w_z + (z_w / |w_z|) / z.
  const double w_z = at(3, 2);
  if (w_z == 0 || at(3, 3) != 0)
    throw std::invalid_argument(
        "DepthConvention::from_projection: not a pinhole projection (clip w must be +-view z)");
  const double z_w = at(2, 3);
  if (z_w == 0)
    throw std::invalid_argument("DepthConvention::from_projection: depth does not vary with view depth");
  DepthConvention convention;
  convention.a = at(2, 2) / w_z;
  convention.b = z_w / std::fabs(w_z);
  if (clip.depth == ClipSpace::Depth::kMinusOneToOne) {  // window depth = (NDC + 1) / 2
    convention.a = 0.5 * (convention.a + 1.0);
    convention.b = 0.5 * convention.b;
  }
  return convention;
}

double DepthConvention::view_depth(double d) const {
  const double z = b / (d - a);
  return z > 0 ? z : std::numeric_limits<double>::infinity();  // at or beyond infinity: no surface
}

double DepthConvention::far_depth() const {
  return std::clamp(a, 0.0, 1.0);
}

}  // namespace tilesplat
