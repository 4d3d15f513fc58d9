// ProjectionVariant: which projection a frame runs, a value of the frame's plan (frame/frame_plan.h),
// without the pass or any Vulkan type (passes/projection_pass.h records it).
#pragma once
#include <compare>
#include <cstdint>

#include "camera/camera_models.h"

namespace tilesplat {

// Which projection a frame runs: the accuracy modes it specializes for (AccuracyModes).
struct ProjectionVariant {
  int sh_degree = 0;         // evaluated degree: min(scene degree, cap)
  int stored_sh_degree = 0;  // the scene's
  bool sh_half = false;
  bool covariance_half = false;
  bool opacity_extent = false;
  bool square_tiles = false;
  float alpha_inv = 255.0f;
  uint32_t depth_key_bits = 32;
  bool distance_key = false;  // key by the centre's distance, not its z (AccuracyModes::SortDepth::kDistance)
  bool ray_depth = false;  // write ProjectedBuffers::ray_depth
  uint32_t dilation_tenths = 3;  // the antialiasing mode's low-pass filter, in 0.1 px^2
  bool compensate_opacity = false;
  bool lighting = false;      // relighting on (the lights themselves are data: ProjectionPass::set_lighting)
  bool file_normals = false;  // lit, with the scene's normal buffer (else every splat's shortest axis)
  uint32_t camera_model = 0;  // tilesplat::CameraModel: the pinhole's code alone unless another is asked for
  // Records per Gaussian (camera_models::seam_copies): Gaussian i's are i and scene count + i.
  uint32_t seam_copies() const { return camera_models::seam_copies(CameraModel(camera_model)); }
  auto operator<=>(const ProjectionVariant&) const = default;
};

}  // namespace tilesplat
