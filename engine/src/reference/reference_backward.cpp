// The float64 reference's backward (tilesplat/gradients.h, docs/gradients.md). The forward is
// render_reference's own steps (reference_frame.h); each pixel's blended splats are then walked back to
// front, as the 3DGS trainer's and gsplat's kernels walk them, giving every splat's screen-space gradient
// (mean, conic, opacity, colour, depth); the projection's forward-mode derivatives
// (differentiable_projection.h) carry those to the Gaussian's parameters.
#include "reference/reference_backward.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "backward/gradient_checks.h"
#include "camera/camera_models.h"
#include "reference/differentiable_projection.h"
#include "reference/parallel_chunks.h"
#include "reference/reference_frame.h"
#include "tilesplat/gradients.h"

namespace tilesplat {

namespace reference {
namespace {

// The frame as the forward drew it, kept for the backward: the splats in depth order and the tiles' lists.
struct ForwardFrame {
  ProjectedRecords projected;
  std::vector<uint32_t> order;  // splat s is record order[s]: Gaussian order[s] (pinhole: one record each)
  std::vector<Splat> splats;
  TileLists lists;
  BlendRules rules;
  double background[3] = {0, 0, 0};
};

ForwardFrame draw_forward(const GaussianScene& scene, const Camera& camera, const RenderSettings& settings,
                          const char* caller) {
  check_differentiable(camera, settings, caller);
  check_frame(scene, camera, settings, caller);
  ForwardFrame frame;
  frame.projected = project_records(scene, camera, settings);
  frame.order = depth_order(frame.projected);
  frame.splats = splats_in_order(frame.projected, frame.order);
  frame.lists = bin_into_tiles(frame.projected.records, frame.order, camera, false);
  frame.rules.max_alpha = settings.max_alpha;
  for (size_t ch = 0; ch < 3; ++ch) frame.background[ch] = settings.background[ch];
  return frame;
}

// One splat blended into one pixel: which, its alpha, and the transmittance in front of it.
struct BlendedSplat {
  uint32_t splat;
  double alpha;
  double transmittance;
};

// Blends pixel (px, py) through its tile's list, recording each splat it blends (when `blended` is given).
PixelBlend blend_pixel(const ForwardFrame& frame, size_t px, size_t py, std::vector<BlendedSplat>* blended) {
  const size_t tile = (py / kTileSize) * size_t(frame.lists.grid_x) + px / kTileSize;
  PixelBlend pixel;
  pixel.pixel_x = double(px) + 0.5;
  pixel.pixel_y = double(py) + 0.5;
  if (blended) blended->clear();
  for (size_t at = frame.lists.offsets[tile]; at < frame.lists.offsets[tile + 1]; ++at) {
    const uint32_t s = frame.lists.splats[at];
    const double alpha = pixel.alpha_at(frame.splats[s], frame.rules);
    if (alpha < 0) continue;
    const double transmittance = pixel.transmittance;
    if (!pixel.blend(frame.splats[s], alpha, frame.rules)) break;
    if (blended) blended->push_back({s, alpha, transmittance});
  }
  return pixel;
}

// dL/d(what the composite reads of a splat), summed over pixels.
struct SplatGradient {
  double mean[2] = {0, 0};
  double conic[3] = {0, 0, 0};
  double opacity = 0;
  double colour[3] = {0, 0, 0};
  double depth = 0;
  double mean_abs[2] = {0, 0};
};

// dL/d(one pixel's outputs), with 0 for a channel the loss did not read.
struct PixelGradient {
  double rgb[3] = {0, 0, 0};
  double alpha = 0;
  double expected_depth = 0;
  double accumulated_depth = 0;
};

PixelGradient pixel_gradient(const FrameGradients& gradients, size_t pixel) {
  PixelGradient g;
  if (!gradients.rgb.empty())
    for (size_t ch = 0; ch < 3; ++ch) g.rgb[ch] = gradients.rgb[pixel * 3 + ch];
  if (!gradients.alpha.empty()) g.alpha = gradients.alpha[pixel];
  if (!gradients.expected_depth.empty()) g.expected_depth = gradients.expected_depth[pixel];
  if (!gradients.accumulated_depth.empty()) g.accumulated_depth = gradients.accumulated_depth[pixel];
  return g;
}

// The pixel's blend walked back to front. Each output is F = sum_i v_i alpha_i T_i + b T_N for a per-splat
// value v (colour, depth, or 1 for the weight sum) and a background b (the colour's; 0 for the others),
// so dF/dv_i = alpha_i T_i and dF/dalpha_i = T_i v_i - S_i / (1 - alpha_i), S_i being F's part behind
// splat i (its background term included). Alpha A = 1 - T_N has dA/dalpha_i = T_N / (1 - alpha_i).
// The expected depth E = D / W (D = sum w z, W = sum w) passes its gradient to D and W.
void backward_pixel(const ForwardFrame& frame, const PixelBlend& pixel,
                    const std::vector<BlendedSplat>& blended, const PixelGradient& g,
                    std::vector<SplatGradient>& out) {
  const double final_t = pixel.transmittance;
  const double w_sum = pixel.weight_sum;
  const double g_depth = g.accumulated_depth + (w_sum > 0 ? g.expected_depth / w_sum : 0.0);
  const double g_weight = w_sum > 0 ? -g.expected_depth * pixel.depth_sum / (w_sum * w_sum) : 0.0;
  double behind_rgb[3];
  for (size_t ch = 0; ch < 3; ++ch) behind_rgb[ch] = frame.background[ch] * final_t;
  double behind_depth = 0, behind_weight = 0;
  for (auto it = blended.rbegin(); it != blended.rend(); ++it) {
    const Splat& splat = frame.splats[it->splat];
    SplatGradient& sg = out[it->splat];
    const double alpha = it->alpha, t = it->transmittance, weight = alpha * t;
    const double one_minus = 1.0 - alpha;
    double g_alpha = g.alpha * final_t / one_minus;
    for (size_t ch = 0; ch < 3; ++ch) {
      sg.colour[ch] += g.rgb[ch] * weight;
      g_alpha += g.rgb[ch] * (t * splat.color[ch] - behind_rgb[ch] / one_minus);
      behind_rgb[ch] += splat.color[ch] * weight;
    }
    sg.depth += g_depth * weight;
    g_alpha += g_depth * (t * splat.depth - behind_depth / one_minus);
    g_alpha += g_weight * (t - behind_weight / one_minus);
    behind_depth += splat.depth * weight;
    behind_weight += weight;

    // alpha = min(max_alpha, opacity G), G = exp(power): a capped alpha passes nothing further.
    const double dx = splat.mean[0] - pixel.pixel_x;
    const double dy = splat.mean[1] - pixel.pixel_y;
    const double gaussian =
        std::exp(-0.5 * (splat.conic[0] * dx * dx + splat.conic[2] * dy * dy) - splat.conic[1] * dx * dy);
    if (splat.opacity * gaussian > frame.rules.max_alpha) continue;
    sg.opacity += g_alpha * gaussian;
    const double g_power = g_alpha * alpha;
    sg.conic[0] += -0.5 * dx * dx * g_power;
    sg.conic[1] += -dx * dy * g_power;
    sg.conic[2] += -0.5 * dy * dy * g_power;
    const double g_mean_x = -(splat.conic[0] * dx + splat.conic[1] * dy) * g_power;
    const double g_mean_y = -(splat.conic[2] * dy + splat.conic[1] * dx) * g_power;
    sg.mean[0] += g_mean_x;
    sg.mean[1] += g_mean_y;
    sg.mean_abs[0] += std::abs(g_mean_x);
    sg.mean_abs[1] += std::abs(g_mean_y);
  }
}

// Every pixel's backward, rows of tiles dealt to the threads in a fixed pattern and their sums added in
// thread order: the same gradients from run to run on the same machine.
std::vector<SplatGradient> composite_backward(const ForwardFrame& frame, const Camera& camera,
                                              const FrameGradients& gradients) {
  const size_t rows = size_t(frame.lists.grid_y);
  const unsigned threads = worker_count(rows);
  std::vector<std::vector<SplatGradient>> partial(threads, std::vector<SplatGradient>(frame.splats.size()));
  auto work = [&](unsigned thread) {
    std::vector<BlendedSplat> blended;
    for (size_t ty = thread; ty < rows; ty += threads)
      for (size_t py = ty * kTileSize; py < std::min(size_t(camera.height), (ty + 1) * kTileSize); ++py)
        for (size_t px = 0; px < size_t(camera.width); ++px) {
          const PixelBlend pixel = blend_pixel(frame, px, py, &blended);
          backward_pixel(frame, pixel, blended, pixel_gradient(gradients, py * size_t(camera.width) + px),
                         partial[thread]);
        }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work, t);
  work(0);
  for (auto& thread : pool) thread.join();
  std::vector<SplatGradient> sum = std::move(partial[0]);
  for (unsigned t = 1; t < threads; ++t)
    for (size_t s = 0; s < sum.size(); ++s) {
      const SplatGradient& p = partial[t][s];
      SplatGradient& q = sum[s];
      for (size_t k = 0; k < 2; ++k) q.mean[k] += p.mean[k], q.mean_abs[k] += p.mean_abs[k];
      for (size_t k = 0; k < 3; ++k) q.conic[k] += p.conic[k], q.colour[k] += p.colour[k];
      q.opacity += p.opacity;
      q.depth += p.depth;
    }
  return sum;
}

// Gaussian i's gradients from its splat's: through the projection's derivatives. False where a value is
// not finite (the caller leaves the Gaussian at zero and counts it).
bool gaussian_backward(const GaussianScene& scene, size_t i, const Camera& camera,
                       const camera_models::ModelLimits& limits, Antialiasing antialiasing,
                       const SplatGradient& g, SceneGradients& out) {
  const DifferentiableSplat d = project_differentiable(scene, i, camera, limits, antialiasing);
  double input[kGaussianInputs] = {};
  auto add = [&](const GaussianDual& output, double gradient) {
    for (size_t k = 0; k < kGaussianInputs; ++k) input[k] += gradient * output.d[k];
  };
  for (size_t k = 0; k < 2; ++k) add(d.mean[k], g.mean[k]);
  for (size_t k = 0; k < 3; ++k) add(d.conic[k], g.conic[k]);
  add(d.opacity, g.opacity);
  add(d.depth, g.depth);
  for (size_t ch = 0; ch < 3; ++ch) add(d.colour[ch], g.colour[ch]);
  const size_t k_count = size_t(scene.sh_coefficients());
  std::vector<double> sh(k_count * 3);
  for (size_t k = 0; k < k_count; ++k)
    for (size_t ch = 0; ch < 3; ++ch)
      sh[k * 3 + ch] = d.colour_clamped[ch] ? 0.0 : d.sh_basis[k] * g.colour[ch];

  auto finite_float = [](double v) { return std::abs(v) <= double(std::numeric_limits<float>::max()); };
  for (double v : input)
    if (!finite_float(v)) return false;
  for (double v : sh)
    if (!finite_float(v)) return false;
  for (size_t k = 0; k < 2; ++k)
    if (!finite_float(g.mean[k]) || !finite_float(g.mean_abs[k])) return false;
  for (size_t k = 0; k < 3; ++k) {
    out.positions[3 * i + k] = float(input[kMeanX + k]);
    out.log_scales[3 * i + k] = float(input[kLogScaleX + k]);
  }
  for (size_t k = 0; k < 4; ++k) out.rotations[4 * i + k] = float(input[kQuatW + k]);
  out.opacity_logits[i] = float(input[kOpacityLogit]);
  for (size_t k = 0; k < sh.size(); ++k) out.sh[i * k_count * 3 + k] = float(sh[k]);
  for (size_t k = 0; k < 2; ++k) {
    out.means2d[2 * i + k] = float(g.mean[k]);
    out.means2d_abs[2 * i + k] = float(g.mean_abs[k]);
  }
  return true;
}

}  // namespace

FrameF64 render_f64(const GaussianScene& scene, const Camera& camera, const RenderSettings& settings) {
  const ForwardFrame frame = draw_forward(scene, camera, settings, "render_f64");
  const size_t pixels = size_t(camera.width) * size_t(camera.height);
  FrameF64 out{std::vector<double>(3 * pixels), std::vector<double>(pixels), std::vector<double>(pixels),
               std::vector<double>(pixels)};
  parallel_chunks(size_t(camera.height), 1, [&](size_t row_begin, size_t row_end) {
    for (size_t py = row_begin; py < row_end; ++py)
      for (size_t px = 0; px < size_t(camera.width); ++px) {
        const PixelBlend pixel = blend_pixel(frame, px, py, nullptr);
        const size_t at = py * size_t(camera.width) + px;
        for (size_t ch = 0; ch < 3; ++ch)
          out.rgb[3 * at + ch] = pixel.color[ch] + pixel.transmittance * frame.background[ch];
        out.alpha[at] = 1.0 - pixel.transmittance;
        out.expected_depth[at] = pixel.weight_sum > 0 ? pixel.depth_sum / pixel.weight_sum : 0.0;
        out.accumulated_depth[at] = pixel.depth_sum;
      }
  });
  return out;
}

}  // namespace reference

SceneGradients reference_backward(const GaussianScene& scene, const Camera& camera,
                                  const RenderSettings& settings, const FrameGradients& gradients) {
  using namespace reference;
  const ForwardFrame frame = draw_forward(scene, camera, settings, "reference_backward");
  check_frame_gradients(gradients, camera.width, camera.height, "reference_backward");

  const std::vector<SplatGradient> splat_gradients = composite_backward(frame, camera, gradients);
  const size_t n = scene.size();
  SceneGradients out;
  out.positions.assign(3 * n, 0.0f);
  out.log_scales.assign(3 * n, 0.0f);
  out.rotations.assign(4 * n, 0.0f);
  out.opacity_logits.assign(n, 0.0f);
  out.sh.assign(scene.sh.size(), 0.0f);
  out.means2d.assign(2 * n, 0.0f);
  out.means2d_abs.assign(2 * n, 0.0f);
  const camera_models::ModelLimits limits = camera_models::model_limits(camera);
  std::vector<uint8_t> unformed(frame.order.size(), 0);
  parallel_chunks(frame.order.size(), 1024, [&](size_t begin, size_t end) {
    for (size_t s = begin; s < end; ++s)
      if (!gaussian_backward(scene, frame.order[s], camera, limits, settings.antialiasing, splat_gradients[s],
                             out))
        unformed[s] = 1;
  });
  // Each unformed Gaussian was left at zero as a whole: gaussian_backward checks every value before it
  // writes one.
  out.unformed = uint64_t(std::count(unformed.begin(), unformed.end(), uint8_t(1)));
  return out;
}

}  // namespace tilesplat
