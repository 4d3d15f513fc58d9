// The steps of the float64 reference's frame that its forward (render_reference) and its backward
// (reference_backward) share: every Gaussian projected, the visible ones in depth order, binned into
// the tiles' lists, and one pixel's front-to-back blend (docs/rendering-math.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "tilesplat/camera.h"
#include "tilesplat/reference.h"
#include "tilesplat/render_settings.h"
#include "tilesplat/scene.h"

namespace tilesplat::reference {

// The blending rules the GPU's composite shares (docs/rendering-math.md); the cap on alpha is
// RenderSettings::max_alpha.
inline constexpr double kMinAlpha = 1.0 / 255.0;
inline constexpr double kMinTransmittance = 1e-4;

// Throws std::invalid_argument ("<caller>: ...") for an SH degree outside 0..3 or arrays whose sizes
// disagree.
void check_scene(const GaussianScene& scene, const char* caller = "render_reference");

// What every frame of the reference refuses before any work (render_reference, reference_backward): a camera,
// region, scene, host depth, near plane, alpha cap, lens or shutter or camera model it cannot draw. Throws
// std::invalid_argument.
void check_frame(const GaussianScene& scene, const Camera& camera, const RenderSettings& settings,
                 const char* caller);

// Every Gaussian projected: one record each, two for the equirectangular camera (its seam copies, records
// n..2n - 1), with what each record sorts by, as the projection keys it (projection.comp's sort_depth):
// the view depth (a fisheye's or panorama's distance), or in radial sorting the pinhole's and OpenCV
// camera's distance.
struct ProjectedRecords {
  std::vector<ProjectedGaussian> records;
  std::vector<float> sort_depth;
};
ProjectedRecords project_records(const GaussianScene& scene, const Camera& camera,
                                 const RenderSettings& settings);

// The visible records front to back by the float32 depth the GPU sorts on, ties by record index.
std::vector<uint32_t> depth_order(const ProjectedRecords& projected);

// What the blending loop needs of a visible Gaussian, packed densely in front-to-back order.
struct Splat {
  double mean[2];
  double conic[3];
  double opacity;
  double color[3];
  double depth;
};
// The records of `order`, in its order.
std::vector<Splat> splats_in_order(const ProjectedRecords& projected, const std::vector<uint32_t>& order);

// The splats (indices into `order`) of each tile, front to back: a counting sort, whose filling in
// front-to-back order keeps every list sorted. The raster rule lists a splat wherever its alpha can pass
// the cut-off (its alpha ellipse's box), the others where the projection's tile rectangle says.
struct TileLists {
  int grid_x = 0, grid_y = 0;
  std::vector<size_t> offsets;  // tile t's splats are splats[offsets[t], offsets[t + 1])
  std::vector<uint32_t> splats;
};
TileLists bin_into_tiles(std::vector<ProjectedGaussian>& projected, const std::vector<uint32_t>& order,
                         const Camera& camera, bool raster);

// What every pixel's blend follows: the frame's rules and the host's surfaces.
struct BlendRules {
  double max_alpha = 0;
  bool raster = false;  // the raster rule: no early-out
  // A host's surfaces, as view depths: a splat blends only in front of them (RenderSettings::host).
  std::vector<float> host_z;
  bool surface_out = false;  // RenderImage::host_depth: the depth at which 1 - T reaches surface_alpha
  double surface_alpha = 0;
};

// One pixel's front-to-back blend (docs/rendering-math.md): its sums as its splats come.
struct PixelBlend {
  double pixel_x = 0, pixel_y = 0;
  float surface_z = 0;  // the host's surface at this pixel (with host depth)
  double transmittance = 1.0;
  double color[3] = {0, 0, 0};
  double depth_sum = 0, weight_sum = 0;
  double surface = 0;  // the depth at which 1 - T reached the host's threshold; 0: never
  uint32_t blended = 0;

  // The splat's alpha at this pixel, or -1 where it is skipped.
  double alpha_at(const Splat& splat, const BlendRules& rules) const;
  // Blends the splat; false once the pixel is done (this splat not blended).
  bool blend(const Splat& splat, double alpha, const BlendRules& rules);
};

}  // namespace tilesplat::reference
