// Renderer::backward (tilesplat/renderer.h, docs/gradients.md): the forward frame, then its backward plan
// recorded by FrameBackward over what the forward left in the buffers.
#include <stdexcept>
#include <string>

#include "backward/backward_plan.h"
#include "backward/gradient_checks.h"
#include "renderer_impl.h"

namespace tilesplat {

SceneGradients Renderer::backward(const Camera& camera, const RenderSettings& settings,
                                  const FrameGradients& gradients) {
  const char* caller = "Renderer::backward";
  const RenderSettings frame_settings = impl_->settings_over_moving_copies(camera, settings);
  check_differentiable(camera, frame_settings, caller);
  validate(camera);
  check_frame_gradients(gradients, camera.width, camera.height, caller);
  if (impl_->image_bands(camera, frame_settings).size() > 1)
    throw std::runtime_error(std::string(caller) + ": the " + std::to_string(camera.width) + "x" +
                             std::to_string(camera.height) +
                             " image is larger than this device renders in one band; the backward takes one");

  // The forward's lists and records: in the buffers already after a render() of this camera and these
  // settings (with reuse_lists), else drawn now.
  impl_->wait_for_submitted_frame();
  FramePlan forward = impl_->plan_for(camera, frame_settings);
  if (forward.build_lists) {
    forward = impl_->render_frame(camera, frame_settings);
  } else {
    impl_->stats = {};
    impl_->stats.reused_sorted_lists = true;
  }
  // The backward walks each tile's list in one dispatch: a list the forward needed more dispatches for
  // (a CPU driver's loop limit, composite.comp) is beyond it.
  if (impl_->recorder.composite_chunks(Compositor::kSorted) > 1)
    throw std::runtime_error(std::string(caller) +
                             ": a tile lists more splats than one composite dispatch takes on this device (" +
                             impl_->ctx.device_name() + "); render a smaller or sparser view");
  if (!impl_->backward) impl_->backward = std::make_unique<FrameBackward>(impl_->ctx, impl_->timer);
  const BackwardPlan plan = plan_backward(forward, impl_->resources.scene_shape(0),
                                          impl_->ctx.features().buffer_float32_atomic_add);
  std::vector<PassTiming> passes;
  SceneGradients out =
      impl_->backward->run(plan, camera, frame_settings.near_plane, impl_->resources, gradients, passes);
  for (const PassTiming& pass : passes) {
    impl_->stats.passes.push_back(pass);
    impl_->stats.gpu_ms += pass.gpu_ms;
  }
  return out;
}

}  // namespace tilesplat
