/// @file
/// Gradients: how a loss on a rendered frame changes with the scene that was rendered (docs/gradients.md).
/// A caller renders, computes dL/d(each output pixel) from its loss, and asks for dL/d(each Gaussian's
/// parameter), as a trainer does in every step.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/export.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/scene.h"

namespace tilesplat {

/// dL/d(each output of a frame): what a loss says about the frame it saw, pixel-major over the camera's
/// whole image like RenderImage. An empty channel has no gradient (the loss did not read it); a filled
/// one has exactly one value per pixel (three for rgb), all finite.
struct FrameGradients {
  /// dL/dR, dL/dG, dL/dB of RenderImage::rgba's colour: C = sum_i c_i alpha_i T_i + T background.
  std::vector<float> rgb;
  /// dL/dA of RenderImage::rgba's alpha, A = 1 - T.
  std::vector<float> alpha;
  /// dL/d(RenderImage::depth): the expected depth sum_i w_i z_i / sum_i w_i (w_i = alpha_i T_i; 0 where
  /// nothing blended), gsplat's "ED".
  std::vector<float> expected_depth;
  /// dL/d(sum_i w_i z_i): the accumulated depth, gsplat's "D" (not an output of RenderImage; its value is
  /// the expected depth times alpha).
  std::vector<float> accumulated_depth;
};

/// dL/d(each parameter of each Gaussian), laid out as GaussianScene's arrays, plus what densification
/// strategies read of the screen (gsplat's means2d gradient and absgrad). Gaussians the frame did not
/// draw have zero gradients.
struct SceneGradients {
  std::vector<float> positions;       ///< 3N
  std::vector<float> log_scales;      ///< 3N
  std::vector<float> rotations;       ///< 4N, with respect to the stored (unnormalized) quaternion
  std::vector<float> opacity_logits;  ///< N
  std::vector<float> sh;              ///< N * K * 3, as GaussianScene::sh
  /// 2N: dL/d(the projected mean in pixels, x y), summed over the pixels the splat was blended into.
  std::vector<float> means2d;
  /// 2N: the same sum of each pixel's |dL/dx| and |dL/dy| (gsplat's absgrad).
  std::vector<float> means2d_abs;
  /// Drawn Gaussians whose gradient could not be formed (a non-finite value): theirs are set to zero,
  /// never a NaN or inf, and counted here.
  uint64_t unformed = 0;
};

/// What a backward pass does not cover (a camera model, a compositor, an accuracy mode, an effect): the
/// frame renders, but its gradient is not defined or not implemented. Thrown before any work, naming it.
class TILESPLAT_API NotDifferentiable : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

/// Throws NotDifferentiable naming the first thing of this frame that `caller`'s backward does not cover:
/// a camera model other than the pinhole, a compositor other than kSorted, an accuracy mode other than
/// the reference, relighting, a host's depth, depth of field, motion blur, accumulated samples, or a
/// region of the image.
TILESPLAT_API void check_differentiable(const Camera& camera, const RenderSettings& settings,
                                        const std::string& caller);

/// The gradient of a loss through the float64 reference (render_reference): the frame rendered again,
/// each pixel's blended splats walked back to front, and each splat's screen-space gradient carried
/// through its projection (the EWA Jacobian, the dilation, the antialiased compensation, the SH colour)
/// by exact forward-mode differentiation of the reference's own formulas. The ground truth the GPU's
/// backward is measured against. The cut-offs (alpha below 1/255, T below 1e-4, the alpha cap) are held
/// where the forward put them: a capped alpha passes no gradient, as in the 3DGS trainer and gsplat.
/// Throws NotDifferentiable (check_differentiable), std::invalid_argument for a bad scene, camera or
/// setting (as render_reference) or gradients of the wrong size or not finite (naming the channel).
TILESPLAT_API SceneGradients reference_backward(const GaussianScene& scene, const Camera& camera,
                                                const RenderSettings& settings,
                                                const FrameGradients& gradients);

}  // namespace tilesplat
