// The checks of RenderSettings values that the GPU frame (plan_frame) and the float64 reference share,
// so that both refuse the same values in the same words.
#pragma once

#include "tilesplat/render_settings.h"

namespace tilesplat {

// RenderSettings::near_plane: positive and finite. Throws std::invalid_argument.
void check_near_plane(double near_plane);
// RenderSettings::max_alpha: finite, above accuracy.alpha_cutoff and below 1. Throws std::invalid_argument.
void check_max_alpha(const RenderSettings& settings);
// RenderSettings::lens, where a frame through it can be made (Renderer::render, render_reference): a valid
// lens (validate(ThinLens)), a valid camera, and no host depth. Throws std::invalid_argument.
void check_lens(const RenderSettings& settings, const Camera& camera);
// RenderSettings::shutter, where a frame through it can be made: a valid shutter (validate(Shutter)), an
// end camera of the camera's size, and no host depth. Throws std::invalid_argument.
void check_shutter(const RenderSettings& settings, const Camera& camera);
// What a camera model rules out (camera_draws): the per-pixel re-sorting (its rays are the pinhole's) needs
// CameraModel::kPinhole, radial sorting a camera centre. Throws std::invalid_argument.
void check_camera_model(const RenderSettings& settings, const Camera& camera);
// RenderSettings::region: whole, or within the camera's image (validate(PixelRegion)), and not with a host's
// depth, which is the whole image's. Throws std::invalid_argument.
void check_region(const RenderSettings& settings, const Camera& camera);
// A single pinhole frame (the frame plan, render_to_image): RenderSettings::lens and shutter must be valid
// and off.
void check_single_frame(const RenderSettings& settings);
// RenderSettings::accumulate_samples with an enabled lens or shutter: each enabled one as check_lens and
// check_shutter want it, with SamplePattern::kSobol. Throws std::invalid_argument.
void check_accumulated_samples(const RenderSettings& settings, const Camera& camera);

}  // namespace tilesplat
