// The camera models' float64 math: distortion, the fisheye's angle mapping, their Jacobians, where
// each stops drawing, and their inverses. compute/projection.comp's project_centre is the same code
// in GLSL; docs/cameras.md derives the Jacobians.
#include "camera/camera_models.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace tilesplat::camera_models {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kFrustumClampFactor = 1.3;  // as the pinhole's (reference_projection.cpp)

// OpenCV's radial factor (1 + k1 r2 + k2 r2^2 + k3 r2^3) / (1 + k4 r2 + k5 r2^2 + k6 r2^3) and its
// derivative with respect to r2. Coefficients in OpenCV's order k1 k2 p1 p2 k3 k4 k5 k6.
std::array<double, 2> radial_factor(const std::array<double, 8>& k, double r2) {
  const double num = 1 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
  const double den = 1 + r2 * (k[5] + r2 * (k[6] + r2 * k[7]));
  const double dnum = k[0] + r2 * (2 * k[1] + r2 * 3 * k[4]);
  const double dden = k[5] + r2 * (2 * k[6] + r2 * 3 * k[7]);
  return {num / den, (dnum * den - num * dden) / (den * den)};
}

// The first point of [0, end] where f stops being positive, by a scan of `steps` and bisection;
// +infinity where f stays positive. f(0) > 0 for every model (the identity's slope).
template <typename Slope>
double first_fold(Slope slope, double end, int steps) {
  double previous = 0;
  for (int i = 1; i <= steps; ++i) {
    const double x = end * i / steps;
    if (!(slope(x) > 0)) {
      double lo = previous, hi = x;
      for (int b = 0; b < 60; ++b) {
        const double mid = 0.5 * (lo + hi);
        (slope(mid) > 0 ? lo : hi) = mid;
      }
      return lo;
    }
    previous = x;
  }
  return kInfinity;
}

// The OpenCV radius where r radial(r^2) stops growing, or where the rational denominator vanishes.
// Scanned to tan(89.4 degrees): nothing a pinhole image shows lies further out.
double opencv_fold(const std::array<double, 8>& k) {
  return first_fold(
      [&k](double r) {
        const double r2 = r * r;
        const double den = 1 + r2 * (k[5] + r2 * (k[6] + r2 * k[7]));
        if (!(den > 0)) return 0.0;
        const auto [radial, slope] = radial_factor(k, r2);
        return radial + 2 * r2 * slope;
      },
      100.0, 100000);
}

double fisheye_fold(const std::array<double, 8>& k) {
  return std::min(std::numbers::pi, first_fold([&k](double theta) { return fisheye_theta_d(k, theta)[1]; },
                                               std::numbers::pi, 20000));
}

// Solves distort(x, y) = (xd, yd) by Newton's method from (xd, yd); false where it does not converge
// inside the fold radius.
bool undistort(const std::array<double, 8>& k, double reach, double xd, double yd, double& x, double& y) {
  x = xd;
  y = yd;
  for (int iteration = 0; iteration < 100; ++iteration) {
    const Distorted d = distort(k, x, y);
    const double ex = d.point[0] - xd, ey = d.point[1] - yd;
    if (std::abs(ex) + std::abs(ey) < 1e-14 * (1 + std::abs(xd) + std::abs(yd)))
      return std::hypot(x, y) < reach;
    const auto& j = d.jacobian;
    const double det = j[0] * j[3] - j[1] * j[2];
    if (!(std::abs(det) > 0) || !std::isfinite(det)) return false;
    double step_x = (j[3] * ex - j[1] * ey) / det, step_y = (j[0] * ey - j[2] * ex) / det;
    // Never step past the fold: halve until inside.
    for (int halving = 0; halving < 60 && !(std::hypot(x - step_x, y - step_y) < reach); ++halving) {
      step_x *= 0.5;
      step_y *= 0.5;
    }
    x -= step_x;
    y -= step_y;
  }
  return false;
}

// Solves theta_d(theta) = radius on [0, reach) by bisection (theta_d grows there).
double fisheye_theta_for(const std::array<double, 8>& k, double reach, double radius) {
  double lo = 0, hi = reach;
  for (int b = 0; b < 80; ++b) {
    const double mid = 0.5 * (lo + hi);
    (fisheye_theta_d(k, mid)[0] < radius ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

Distorted distort(const std::array<double, 8>& k, double x, double y) {
  const double p1 = k[2], p2 = k[3];
  const double r2 = x * x + y * y;
  const auto [radial, slope] = radial_factor(k, r2);
  Distorted d;
  d.point = {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
             y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
  const double cross = 2 * x * y * slope + 2 * p1 * x + 2 * p2 * y;
  d.jacobian = {radial + 2 * x * x * slope + 2 * p1 * y + 6 * p2 * x, cross,  //
                cross, radial + 2 * y * y * slope + 6 * p1 * y + 2 * p2 * x};
  return d;
}

std::array<double, 2> fisheye_theta_d(const std::array<double, 8>& k, double theta) {
  const double t2 = theta * theta;
  const double poly = 1 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3])));
  const double slope = 1 + t2 * (3 * k[0] + t2 * (5 * k[1] + t2 * (7 * k[2] + t2 * 9 * k[3])));
  return {theta * poly, slope};
}

// model_limits, computed: the fold's scan and the undistorted border cost tens of thousands of evaluations.
ModelLimits compute_limits(const Camera& camera) {
  ModelLimits limits;
  limits.reach = kInfinity;
  // The image's extent from the principal point, in normalized (distorted) coordinates.
  const double left = camera.cx / camera.fx, right = (camera.width - camera.cx) / camera.fx;
  const double top = camera.cy / camera.fy, bottom = (camera.height - camera.cy) / camera.fy;
  switch (drawn_model(camera)) {
    case CameraModel::kPinhole:
      limits.clamp_x = kFrustumClampFactor * camera.tan_half_fov_x();
      limits.clamp_y = kFrustumClampFactor * camera.tan_half_fov_y();
      break;
    case CameraModel::kOpenCV: {
      limits.reach = opencv_fold(camera.distortion);
      // The undistorted extent of the image's border, walked in 256 steps a side; a border point
      // past the fold (the image shows the folded rim) counts as the fold itself.
      double extent_x = 0, extent_y = 0;
      constexpr int kSteps = 256;
      for (int side = 0; side < 4; ++side)
        for (int i = 0; i <= kSteps; ++i) {
          const double f = double(i) / kSteps;
          const double xd = side < 2 ? (side == 0 ? -left : right) : -left + f * (left + right);
          const double yd = side < 2 ? -top + f * (top + bottom) : (side == 2 ? -top : bottom);
          double x = 0, y = 0;
          if (!undistort(camera.distortion, limits.reach, xd, yd, x, y)) {
            const double r = std::hypot(xd, yd);
            const double scale = std::isfinite(limits.reach) && r > 0 ? limits.reach / r : 1.0;
            x = xd * scale;
            y = yd * scale;
          }
          extent_x = std::max(extent_x, std::abs(x));
          extent_y = std::max(extent_y, std::abs(y));
        }
      limits.clamp_x = kFrustumClampFactor * extent_x;
      limits.clamp_y = kFrustumClampFactor * extent_y;
      break;
    }
    case CameraModel::kFisheye:
      limits.reach = fisheye_fold(camera.distortion);
      break;
    case CameraModel::kOrthographic:
    case CameraModel::kEquirectangular:
      break;
  }
  return limits;
}

const ModelLimits& model_limits(const Camera& camera) {
  // The camera last asked about on this thread: every frame (ProjectionPass::set_camera, each lens or
  // shutter sample) and every Camera::project or ray_direction call asks again about the same intrinsics.
  struct Entry {
    bool valid = false;
    CameraModel model = CameraModel::kPinhole;
    std::array<double, 8> distortion{};
    std::array<double, 4> intrinsics{};
    std::array<int, 2> size{};
    ModelLimits limits;
  };
  thread_local Entry entry;
  const std::array<double, 4> intrinsics = {camera.fx, camera.fy, camera.cx, camera.cy};
  const std::array<int, 2> size = {camera.width, camera.height};
  if (!entry.valid || entry.model != camera.model || entry.distortion != camera.distortion ||
      entry.intrinsics != intrinsics || entry.size != size)
    entry = {true, camera.model, camera.distortion, intrinsics, size, compute_limits(camera)};
  return entry.limits;
}

CentreProjection project_centre(const Camera& camera, const ModelLimits& limits,
                                const std::array<double, 3>& t, double near_plane, uint32_t seam_copy) {
  CentreProjection out;
  const double x = t[0], y = t[1], z = t[2];
  const double fx = camera.fx, fy = camera.fy;
  switch (camera.model) {
    case CameraModel::kPinhole: {
      if (!(z > near_plane)) return out;
      const double tx = std::clamp(x / z, -limits.clamp_x, limits.clamp_x) * z;
      const double ty = std::clamp(y / z, -limits.clamp_y, limits.clamp_y) * z;
      out.pixel = {fx * x / z + camera.cx, fy * y / z + camera.cy};
      out.jacobian_u = {fx / z, 0, -fx * tx / (z * z)};
      out.jacobian_v = {0, fy / z, -fy * ty / (z * z)};
      out.depth = z;
      break;
    }
    case CameraModel::kOpenCV: {
      if (!(z > near_plane)) return out;
      const double xn = x / z, yn = y / z;
      if (!(xn * xn + yn * yn < limits.reach * limits.reach)) return out;
      const Distorted centre = distort(camera.distortion, xn, yn);
      out.pixel = {fx * centre.point[0] + camera.cx, fy * centre.point[1] + camera.cy};
      // The Jacobian at the clamped point: K D(xc, yc) P, P = d(x/z, y/z)/dt there.
      const double xc = std::clamp(xn, -limits.clamp_x, limits.clamp_x);
      const double yc = std::clamp(yn, -limits.clamp_y, limits.clamp_y);
      const auto& d = distort(camera.distortion, xc, yc).jacobian;
      if (!(d[0] * d[3] - d[1] * d[2] > 0)) return out;  // folded where the shape is taken
      const double inv_z = 1 / z;
      out.jacobian_u = {fx * d[0] * inv_z, fx * d[1] * inv_z, -fx * (d[0] * xc + d[1] * yc) * inv_z};
      out.jacobian_v = {fy * d[2] * inv_z, fy * d[3] * inv_z, -fy * (d[2] * xc + d[3] * yc) * inv_z};
      out.depth = z;
      break;
    }
    case CameraModel::kFisheye: {
      const double r2 = x * x + y * y;
      const double rho2 = r2 + z * z;
      const double rho = std::sqrt(rho2);
      if (!(rho > near_plane)) return out;
      const double r = std::sqrt(r2);
      const double theta = std::atan2(r, z);
      if (!(theta < limits.reach)) return out;
      const auto [theta_d, slope] = fisheye_theta_d(camera.distortion, theta);
      // s = theta_d / r scales (x, y) to the distorted radius; at the axis its limit is 1 / z, and
      // h = (ds/dx) / x = (slope z / rho^2 - s) / r^2 tends to (2 k1 - 2/3) / z^3.
      double s, h;
      if (r2 > 0) {
        s = theta_d / r;
        h = (slope * z / rho2 - s) / r2;
      } else {
        s = 1 / z;
        h = (2 * camera.distortion[0] - 2.0 / 3.0) / (z * z * z);
      }
      out.pixel = {fx * s * x + camera.cx, fy * s * y + camera.cy};
      const double along = slope / rho2;
      out.jacobian_u = {fx * (s + x * x * h), fx * x * y * h, -fx * x * along};
      out.jacobian_v = {fy * x * y * h, fy * (s + y * y * h), -fy * y * along};
      out.depth = rho;
      break;
    }
    case CameraModel::kOrthographic:
      if (!(z > near_plane)) return out;
      out.pixel = {fx * x + camera.cx, fy * y + camera.cy};
      out.jacobian_u = {fx, 0, 0};
      out.jacobian_v = {0, fy, 0};
      out.depth = z;
      break;
    case CameraModel::kEquirectangular: {
      // Longitude atan2(x, z) and latitude atan2(y, q), q = sqrt(x^2 + z^2): at the poles (q = 0) the
      // longitude is undefined and the splat is not drawn.
      const double q2 = x * x + z * z;
      const double rho2 = q2 + y * y;
      const double rho = std::sqrt(rho2);
      if (!(rho > near_plane) || !(q2 > 0)) return out;
      const double q = std::sqrt(q2);
      double longitude = std::atan2(x, z);
      if (seam_copy == 1) longitude += longitude < 0 ? 2 * std::numbers::pi : -2 * std::numbers::pi;
      out.pixel = {fx * longitude + camera.cx, fy * std::atan2(y, q) + camera.cy};
      out.jacobian_u = {fx * z / q2, 0, -fx * x / q2};
      const double across = fy / (q * rho2);
      out.jacobian_v = {-across * x * y, fy * q / rho2, -across * y * z};
      out.depth = rho;
      break;
    }
  }
  out.visible = true;
  return out;
}

CentreProjection project_point(const Camera& camera, const std::array<double, 3>& t) {
  return project_centre(camera, model_limits(camera), t, 0.0);
}

bool pixel_ray(const Camera& camera, double u, double v, std::array<double, 3>& ray) {
  const double xd = (u - camera.cx) / camera.fx, yd = (v - camera.cy) / camera.fy;
  double x = xd, y = yd, z = 1;
  switch (camera.model) {
    case CameraModel::kPinhole:
      break;
    case CameraModel::kOpenCV:
      if (!undistort(camera.distortion, model_limits(camera).reach, xd, yd, x, y)) return false;
      break;
    case CameraModel::kFisheye: {
      const double radius = std::hypot(xd, yd);
      const double reach = model_limits(camera).reach;
      if (!(radius < fisheye_theta_d(camera.distortion, reach)[0])) return false;
      const double theta = fisheye_theta_for(camera.distortion, reach, radius);
      const double across = radius > 0 ? std::sin(theta) / radius : 0;
      x = xd * across;
      y = yd * across;
      z = std::cos(theta);
      break;
    }
    case CameraModel::kOrthographic:
      ray = {0, 0, 1};
      return true;
    case CameraModel::kEquirectangular: {
      const double longitude = xd, latitude = yd;
      if (!(std::abs(latitude) < std::numbers::pi / 2)) return false;
      x = std::cos(latitude) * std::sin(longitude);
      y = std::sin(latitude);
      z = std::cos(latitude) * std::cos(longitude);
      break;
    }
  }
  const double length = std::sqrt(x * x + y * y + z * z);
  ray = {x / length, y / length, z / length};
  return true;
}

}  // namespace tilesplat::camera_models
