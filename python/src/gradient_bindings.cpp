// Gradients for Python (tilesplat/gradients.h): Renderer.backward on the device and reference_backward in
// float64, each taking dL/d(each output) as numpy arrays and returning dL/d(each scene array) as a dict of
// numpy arrays. NotDifferentiable reaches Python as tilesplat.NotDifferentiable, a NotImplementedError.
#include <nanobind/nanobind.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "settings.h"
#include "tilesplat/gradients.h"
#include "tilesplat/renderer.h"

namespace tilesplat::python {
namespace {

using namespace nb::literals;

// The loss's gradients of a width x height frame's outputs; each argument None or an array of the
// output's shape (H, W, 3) or (H, W).
using OptionalInput = std::optional<FloatInput>;

FrameGradients frame_gradients(const Camera& camera, const OptionalInput& rgb, const OptionalInput& alpha,
                               const OptionalInput& expected_depth, const OptionalInput& accumulated_depth) {
  const int64_t h = camera.height, w = camera.width;
  FrameGradients g;
  if (rgb) g.rgb = finite_values(*rgb, "grad_rgb", {h, w, 3});
  if (alpha) g.alpha = finite_values(*alpha, "grad_alpha", {h, w});
  if (expected_depth) g.expected_depth = finite_values(*expected_depth, "grad_expected_depth", {h, w});
  if (accumulated_depth)
    g.accumulated_depth = finite_values(*accumulated_depth, "grad_accumulated_depth", {h, w});
  return g;
}

// The gradients as arrays shaped like the scene's; `k` the SH coefficients per channel.
nb::dict gradients_dict(SceneGradients&& g, size_t k) {
  const size_t n = g.opacity_logits.size();
  nb::dict out;
  out["positions"] = owned_array(std::move(g.positions), {n, 3});
  out["log_scales"] = owned_array(std::move(g.log_scales), {n, 3});
  out["rotations"] = owned_array(std::move(g.rotations), {n, 4});
  out["opacity_logits"] = owned_array(std::move(g.opacity_logits), {n});
  out["sh"] = owned_array(std::move(g.sh), {n, k, 3});
  out["means2d"] = owned_array(std::move(g.means2d), {n, 2});
  out["means2d_abs"] = owned_array(std::move(g.means2d_abs), {n, 2});
  out["unformed"] = g.unformed;
  return out;
}

const char* kGradientArguments =
    "grad_rgb (H, W, 3), grad_alpha (H, W), grad_expected_depth (H, W) (of the image's depth, "
    "sum w z / sum w) and grad_accumulated_depth (H, W) (of sum w z) are dL/d(each output); None: the loss "
    "did not read it. Returns a dict of dL/d(each scene array): positions (N, 3), log_scales (N, 3), "
    "rotations (N, 4), opacity_logits (N,), sh (N, K, 3), and the screen's means2d (N, 2) and means2d_abs "
    "(N, 2) (gsplat's means2d gradient and absgrad), with 'unformed': the drawn Gaussians whose gradient "
    "was not finite, set to zero. Raises tilesplat.NotDifferentiable (a NotImplementedError) for what the "
    "backward does not cover: a camera model other than the pinhole, a compositor other than 'sorted', an "
    "accuracy mode, relighting, a host's depth, a lens, a shutter or a region.";

}  // namespace

void bind_gradients(nb::module_& m, nb::class_<RendererHandle>& renderer) {
  nb::exception<NotDifferentiable>(m, "NotDifferentiable", PyExc_NotImplementedError);
  renderer.def(
      "backward",
      [](RendererHandle& self, const Camera& camera, const OptionalInput& grad_rgb,
         const OptionalInput& grad_alpha, const OptionalInput& grad_expected_depth,
         const OptionalInput& grad_accumulated_depth, const RenderSettings* base_settings,
         const nb::kwargs& overrides) {
        const RenderSettings settings = settings_with(base_settings, overrides, "backward()");
        const FrameGradients g =
            frame_gradients(camera, grad_rgb, grad_alpha, grad_expected_depth, grad_accumulated_depth);
        SceneGradients out;
        {
          nb::gil_scoped_release release;
          out = self.renderer->backward(camera, settings, g);
        }
        const size_t n = out.opacity_logits.size();
        const size_t coefficients = n == 0 ? 1 : out.sh.size() / (3 * n);
        return gradients_dict(std::move(out), coefficients);
      },
      "camera"_a, "grad_rgb"_a = nb::none(), "grad_alpha"_a = nb::none(),
      "grad_expected_depth"_a = nb::none(), "grad_accumulated_depth"_a = nb::none(),
      "settings"_a = nb::none(), "overrides"_a,
      (std::string(
           "The gradient of a loss through render(camera, settings) of the scene set_scene uploaded "
           "(Renderer::backward, docs/gradients.md), on the device; settings and keywords as render(). ") +
       kGradientArguments)
          .c_str());
  m.def(
      "reference_backward",
      [](const Camera& camera, const GaussianScene& scene, const OptionalInput& grad_rgb,
         const OptionalInput& grad_alpha, const OptionalInput& grad_expected_depth,
         const OptionalInput& grad_accumulated_depth, const RenderSettings* base_settings,
         const nb::kwargs& overrides) {
        const RenderSettings settings = settings_with(base_settings, overrides, "reference_backward()");
        const FrameGradients g =
            frame_gradients(camera, grad_rgb, grad_alpha, grad_expected_depth, grad_accumulated_depth);
        SceneGradients out;
        {
          nb::gil_scoped_release release;
          out = reference_backward(scene, camera, settings, g);
        }
        return gradients_dict(std::move(out), size_t(scene.sh_coefficients()));
      },
      "camera"_a, "scene"_a, "grad_rgb"_a = nb::none(), "grad_alpha"_a = nb::none(),
      "grad_expected_depth"_a = nb::none(), "grad_accumulated_depth"_a = nb::none(),
      "settings"_a = nb::none(), "overrides"_a,
      (std::string("The same gradient through the float64 reference (render_reference), the ground truth "
                   "Renderer.backward is tested against. Slow. ") +
       kGradientArguments)
          .c_str());
}

}  // namespace tilesplat::python
