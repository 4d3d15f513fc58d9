// The float64 CPU reference renderer: docs/rendering-math.md, step by step, tiles and all.
// Everything is computed in double from the scene's float inputs; only the per-tile sort key is
// rounded to float32, because the GPU sorts by float_bits(depth) and the reference must order
// splats exactly as it does.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "host_depth.h"
#include "lighting.h"
#include "tilesplat/reference.h"

namespace tilesplat {
namespace {

constexpr double kShC0 = 0.28209479177387814;
constexpr double kShC1 = 0.4886025119029199;
constexpr double kShC2[5] = {1.0925484305920792, -1.0925484305920792, 0.31539156525252005, -1.0925484305920792,
                             0.5462742152960396};
constexpr double kShC3[7] = {-0.5900435899266435, 2.890611442640554, -0.4570457994644658, 0.3731763325901154,
                             -0.4570457994644658, 1.445305721320277,  -0.5900435899266435};

constexpr double kFrustumClampFactor = 1.3;  // x/z, y/z clamp before the Jacobian, in units of tan(fov/2)
// The low-pass filter added to every 2D covariance, per antialiasing mode.
double low_pass_dilation(Antialiasing mode) { return mode == Antialiasing::kMip ? 0.1 : 0.3; }
constexpr double kMinEigenGap = 0.1;
constexpr double kMaxAlpha = 0.99;
constexpr double kMinAlpha = 1.0 / 255.0;
constexpr double kMinTransmittance = 1e-4;
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

unsigned worker_count(size_t work_items) {
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  return static_cast<unsigned>(std::min<size_t>(hardware, std::max<size_t>(1, work_items)));
}

// Runs body(begin, end) over [0, count) in chunks handed out by an atomic counter, so threads that
// draw cheap chunks (empty tiles, culled Gaussians) take more of them.
template <typename Body>
void parallel_chunks(size_t count, size_t chunk, const Body& body) {
  if (count == 0) return;
  const size_t chunks = (count + chunk - 1) / chunk;
  std::atomic<size_t> next_chunk{0};
  auto worker = [&] {
    for (size_t c = next_chunk.fetch_add(1); c < chunks; c = next_chunk.fetch_add(1))
      body(c * chunk, std::min(count, (c + 1) * chunk));
  };
  const unsigned threads = worker_count(chunks);
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& thread : pool) thread.join();
}

void check_scene(const GaussianScene& scene) {
  const size_t n = scene.size();
  if (scene.sh_degree < 0 || scene.sh_degree > 3)
    throw std::invalid_argument("render_reference: sh_degree must be 0..3, got " + std::to_string(scene.sh_degree));
  const size_t k = static_cast<size_t>(scene.sh_coefficients());
  if (scene.positions.size() != 3 * n || scene.log_scales.size() != 3 * n || scene.rotations.size() != 4 * n ||
      scene.sh.size() != n * k * 3)
    throw std::invalid_argument("render_reference: scene arrays have inconsistent sizes");
}

void check_normals(const GaussianScene& scene) {
  if (scene.has_normals() && scene.normals.size() != 3 * scene.size())
    throw std::invalid_argument("render_reference: scene normals must be empty or 3 per Gaussian");
}

// What the blending loop needs of a visible Gaussian, packed densely in front-to-back order.
struct Splat {
  double mean[2];
  double conic[3];
  double opacity;
  double color[3];
  double depth;
};

}  // namespace

namespace {

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
  const double toward_camera =
      n[0] * (camera.position[0] - x[0]) + n[1] * (camera.position[1] - x[1]) + n[2] * (camera.position[2] - x[2]);
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
  if (degree < 0 || degree > 3) throw std::invalid_argument("eval_sh: degree must be 0..3, got " + std::to_string(degree));
  std::array<double, 3> result{};
  auto sh = [coeffs](int k, int c) { return double(coeffs[k * 3 + c]); };
  const double x = dir[0], y = dir[1], z = dir[2];
  const double xx = x * x, yy = y * y, zz = z * z;
  const double xy = x * y, yz = y * z, xz = x * z;
  for (int c = 0; c < 3; ++c) {
    double sum = kShC0 * sh(0, c);
    if (degree > 0) {
      sum += -kShC1 * y * sh(1, c) + kShC1 * z * sh(2, c) - kShC1 * x * sh(3, c);
      if (degree > 1) {
        sum += kShC2[0] * xy * sh(4, c) + kShC2[1] * yz * sh(5, c) + kShC2[2] * (2 * zz - xx - yy) * sh(6, c) +
               kShC2[3] * xz * sh(7, c) + kShC2[4] * (xx - yy) * sh(8, c);
        if (degree > 2) {
          sum += kShC3[0] * y * (3 * xx - yy) * sh(9, c) + kShC3[1] * xy * z * sh(10, c) +
                 kShC3[2] * y * (4 * zz - xx - yy) * sh(11, c) +
                 kShC3[3] * z * (2 * zz - 3 * xx - 3 * yy) * sh(12, c) +
                 kShC3[4] * x * (4 * zz - xx - yy) * sh(13, c) + kShC3[5] * z * (xx - yy) * sh(14, c) +
                 kShC3[6] * x * (xx - 3 * yy) * sh(15, c);
        }
      }
    }
    result[static_cast<size_t>(c)] = sum;
  }
  return result;
}

namespace {

ProjectedGaussian project(const GaussianScene& scene, size_t i, const Camera& camera,
                          Antialiasing antialiasing, const PreparedLighting& lighting, double near_plane) {
  ProjectedGaussian out;
  const std::array<double, 3> mean = {scene.positions[3 * i], scene.positions[3 * i + 1], scene.positions[3 * i + 2]};
  const std::array<double, 3> t = camera.to_camera(mean);
  out.depth = t[2];
  // Written as a negated comparison so that a NaN depth is culled too.
  if (!(t[2] > near_plane) || !all_finite({t[0], t[1], t[2]})) return out;

  // Scales are float32 values: a log scale whose exp overflows a float is an infinite scale (the GPU
  // evaluates exp in float32), and an infinite scale has no usable covariance.
  for (int axis = 0; axis < 3; ++axis)
    if (!(std::exp(double(scene.log_scales[3 * i + size_t(axis)])) <= kFloatMax)) return out;
  const std::array<double, 9> sigma = covariance3d(&scene.log_scales[3 * i], &scene.rotations[4 * i]);

  // The Jacobian is evaluated at a point clamped to 1.3x the field of view so that splats far
  // outside the frame do not get absurdly stretched footprints; the mean itself is not clamped.
  const double limit_x = kFrustumClampFactor * camera.tan_half_fov_x();
  const double limit_y = kFrustumClampFactor * camera.tan_half_fov_y();
  const double tz = t[2];
  const double tx = std::clamp(t[0] / tz, -limit_x, limit_x) * tz;
  const double ty = std::clamp(t[1] / tz, -limit_y, limit_y) * tz;
  const double j00 = camera.fx / tz, j02 = -camera.fx * tx / (tz * tz);
  const double j11 = camera.fy / tz, j12 = -camera.fy * ty / (tz * tz);

  // T = J W (2x3).
  const auto& w = camera.rotation;
  const double t0[3] = {j00 * w[0] + j02 * w[6], j00 * w[1] + j02 * w[7], j00 * w[2] + j02 * w[8]};
  const double t1[3] = {j11 * w[3] + j12 * w[6], j11 * w[4] + j12 * w[7], j11 * w[5] + j12 * w[8]};
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
  out.mean[0] = camera.fx * t[0] / tz + camera.cx;
  out.mean[1] = camera.fy * t[1] / tz + camera.cy;

  const double det = a * c - b * b;
  // The composite works in float32 relative to the mean: a mean beyond the float range is culled.
  if (!all_finite({a, b, c, det, out.mean[0], out.mean[1]}) || !(det > 0) || !(std::abs(out.mean[0]) <= kFloatMax) ||
      !(std::abs(out.mean[1]) <= kFloatMax))
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
  std::array<double, 3> dir = {mean[0] - camera.position[0], mean[1] - camera.position[1],
                               mean[2] - camera.position[2]};
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
    const std::array<double, 3> factor = light_factor(lighting, mean, lighting_normal(scene, i, mean, camera));
    for (size_t ch = 0; ch < 3; ++ch) {
      out.color[ch] *= factor[ch];
      if (!(out.color[ch] <= kFloatMax)) return out;  // the lit colour must be a finite float too
    }
  }
  out.visible = true;
  return out;
}

// A near plane the reference can cull at (the GPU's plan refuses the same values).
void check_near_plane(double near_plane) {
  if (!(std::isfinite(near_plane) && near_plane > 0))
    throw std::invalid_argument("RenderSettings::near_plane must be a positive, finite view depth, got " +
                                std::to_string(near_plane));
}

}  // namespace

ProjectedGaussian project_gaussian(const GaussianScene& scene, size_t i, const Camera& camera,
                                   Antialiasing antialiasing, const Lighting& lighting, double near_plane) {
  if (i >= scene.size()) throw std::out_of_range("project_gaussian: index out of range");
  check_near_plane(near_plane);
  if (lighting.enabled()) check_normals(scene);
  return project(scene, i, camera, antialiasing, prepare_lighting(lighting), near_plane);
}

RenderImage render_reference(const GaussianScene& scene, const Camera& camera, const RenderSettings& settings) {
  validate(camera);
  check_scene(scene);
  validate_host_depth(settings, camera);
  check_near_plane(settings.near_plane);
  // A host's surfaces, as view depths: a splat blends only in front of them (RenderSettings::host).
  const std::vector<float> host_z = settings.host ? host_view_depths(*settings.host) : std::vector<float>{};
  const bool surface_out = settings.host && settings.host->write_depth;
  const double surface_alpha = surface_out ? settings.host->alpha_threshold : 0.0;
  const size_t n = scene.size();

  const PreparedLighting lighting = prepare_lighting(settings.lighting);  // validates
  if (settings.lighting.enabled()) check_normals(scene);

  std::vector<ProjectedGaussian> projected(n);
  parallel_chunks(n, 4096, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i)
      projected[i] = project(scene, i, camera, settings.antialiasing, lighting, settings.near_plane);
  });

  // Front to back by the float32 depth the GPU sorts on, ties by Gaussian index.
  std::vector<uint32_t> order;
  for (size_t i = 0; i < n; ++i)
    if (projected[i].visible) order.push_back(static_cast<uint32_t>(i));
  std::stable_sort(order.begin(), order.end(), [&](uint32_t lhs, uint32_t rhs) {
    return static_cast<float>(projected[lhs].depth) < static_cast<float>(projected[rhs].depth);
  });

  std::vector<Splat> splats(order.size());
  for (size_t s = 0; s < order.size(); ++s) {
    const ProjectedGaussian& g = projected[order[s]];
    splats[s] = {{g.mean[0], g.mean[1]}, {g.conic[0], g.conic[1], g.conic[2]}, g.opacity,
                 {g.color[0], g.color[1], g.color[2]}, g.depth};
  }

  // Bin the splats into per-tile lists (counting sort); filling in front-to-back order keeps
  // every list sorted.
  const int grid_x = (camera.width + kTileSize - 1) / kTileSize;
  const int grid_y = (camera.height + kTileSize - 1) / kTileSize;
  const size_t tiles = size_t(grid_x) * size_t(grid_y);
  std::vector<size_t> tile_offsets(tiles + 1, 0);
  for (uint32_t index : order) {
    const ProjectedGaussian& g = projected[index];
    for (int ty = g.tile_min[1]; ty < g.tile_max[1]; ++ty)
      for (int tx = g.tile_min[0]; tx < g.tile_max[0]; ++tx) ++tile_offsets[size_t(ty) * size_t(grid_x) + size_t(tx) + 1];
  }
  std::partial_sum(tile_offsets.begin(), tile_offsets.end(), tile_offsets.begin());
  std::vector<uint32_t> tile_splats(tile_offsets.back());
  {
    std::vector<size_t> cursor(tile_offsets.begin(), tile_offsets.end() - 1);
    for (size_t s = 0; s < order.size(); ++s) {
      const ProjectedGaussian& g = projected[order[s]];
      for (int ty = g.tile_min[1]; ty < g.tile_max[1]; ++ty)
        for (int tx = g.tile_min[0]; tx < g.tile_max[0]; ++tx)
          tile_splats[cursor[size_t(ty) * size_t(grid_x) + size_t(tx)]++] = static_cast<uint32_t>(s);
    }
  }
  projected.clear();
  projected.shrink_to_fit();

  RenderImage image;
  image.width = camera.width;
  image.height = camera.height;
  image.rgba.assign(image.pixels() * 4, 0.0f);
  if (settings.depth) image.depth.assign(image.pixels(), 0.0f);
  if (settings.splat_count) image.splat_count.assign(image.pixels(), 0);
  if (surface_out) image.host_depth.assign(image.pixels(), 0.0f);

  const double background[3] = {settings.background[0], settings.background[1], settings.background[2]};
  const size_t width = size_t(camera.width);
  parallel_chunks(size_t(grid_y), 1, [&](size_t row_begin, size_t row_end) {
    for (size_t ty = row_begin; ty < row_end; ++ty)
      for (size_t tx = 0; tx < size_t(grid_x); ++tx) {
        const size_t tile = ty * size_t(grid_x) + tx;
        const uint32_t* list_begin = tile_splats.data() + tile_offsets[tile];
        const uint32_t* list_end = tile_splats.data() + tile_offsets[tile + 1];
        const size_t y_end = std::min(size_t(camera.height), (ty + 1) * kTileSize);
        const size_t x_end = std::min(width, (tx + 1) * kTileSize);
        for (size_t py = ty * kTileSize; py < y_end; ++py)
          for (size_t px = tx * kTileSize; px < x_end; ++px) {
            const double pixel_x = double(px) + 0.5, pixel_y = double(py) + 0.5;
            double transmittance = 1.0;
            double color[3] = {0, 0, 0};
            double depth_sum = 0, weight_sum = 0;
            double surface = 0;  // the depth at which 1 - T reached the host's threshold; 0: never
            uint32_t blended = 0;
            const float surface_z = host_z.empty() ? 0.0f : host_z[py * width + px];
            for (const uint32_t* it = list_begin; it != list_end; ++it) {
              const Splat& splat = splats[*it];
              const double dx = splat.mean[0] - pixel_x;
              const double dy = splat.mean[1] - pixel_y;
              const double power =
                  -0.5 * (splat.conic[0] * dx * dx + splat.conic[2] * dy * dy) - splat.conic[1] * dx * dy;
              if (power > 0) continue;
              const double alpha = std::min(kMaxAlpha, splat.opacity * std::exp(power));
              if (alpha < kMinAlpha) continue;
              // Behind (or at) the host's opaque surface; compared as the float depths the GPU sorts on.
              if (!host_z.empty() && !(static_cast<float>(splat.depth) < surface_z)) continue;
              const double next_transmittance = transmittance * (1 - alpha);
              if (next_transmittance < kMinTransmittance) break;
              const double weight = alpha * transmittance;
              for (int ch = 0; ch < 3; ++ch) color[ch] += splat.color[ch] * weight;
              depth_sum += weight * splat.depth;
              weight_sum += weight;
              transmittance = next_transmittance;
              if (surface_out && surface == 0 && 1 - transmittance >= surface_alpha) surface = splat.depth;
              ++blended;
            }
            const size_t pixel = py * width + px;
            for (size_t ch = 0; ch < 3; ++ch)
              image.rgba[pixel * 4 + ch] = static_cast<float>(color[ch] + transmittance * background[ch]);
            image.rgba[pixel * 4 + 3] = static_cast<float>(1.0 - transmittance);
            if (settings.depth) image.depth[pixel] = weight_sum > 0 ? static_cast<float>(depth_sum / weight_sum) : 0.0f;
            if (settings.splat_count) image.splat_count[pixel] = blended;
            if (surface_out) image.host_depth[pixel] = host_depth_out(*settings.host, surface, pixel);
          }
      }
  });
  return image;
}

}  // namespace tilesplat
