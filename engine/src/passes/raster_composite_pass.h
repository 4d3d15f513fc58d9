// The raster compositor (Compositor::kRaster): the depth-sorted splats drawn as quads through the
// graphics pipeline and blended front to back by the fixed-function blend ("under": the colour
// attachment's alpha is 1 - T), then resolved into the frame's output buffers as the tile compositor
// writes them. raster_quad.vert (or, on a GPU with VK_EXT_mesh_shader, raster_quads.mesh) expands each
// splat around its alpha >= cut-off ellipse, raster_blend.frag evaluates it with the tile compositor's
// expression, raster_resolve.comp puts the background under it and turns the depth sums and counts into
// the outputs. A host's depth out reads the running alpha in the fragment stage (raster_blend_surface,
// through rasterization-order attachment access).
//
// It has no transmittance early-out (the blend cannot skip a fragment by what the pixel holds) and no
// tile rectangles (a splat reaches every pixel where its alpha passes the cut-off): the reference's
// raster rule (render_reference with Compositor::kRaster), against which it is tested.
#pragma once

#include <array>
#include <compare>
#include <cstdint>
#include <vector>

#include "passes/composite_pass.h"
#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"
#include "vulkan/graphics_pipeline.h"
#include "vulkan/image.h"
#include "vulkan/pipeline_variants.h"

namespace tilesplat {

// What the raster compositor draws: CompositeInputs' splats and outputs, the Gaussians' depth order in
// place of the tile lists, and the frame counters (the visible count is the draw's instance count).
struct RasterInputs {
  const vk::Buffer& splats;       // ProjectedBuffers::splats
  const vk::Buffer& depth_order;  // record indices front to back, the visible ones first
  const vk::Buffer& counters;     // FrameCounters
  OutputBuffers& out;
  std::array<float, 3> background = {0, 0, 0};
  bool write_depth = true;
  bool write_count = true;
  CompositeCutoffs cutoffs;  // alpha and max_alpha; the transmittance cut-off does not apply
  // A host's surfaces (FrameResources::host_surface): view_depth, as view depths per pixel (+inf where
  // none), is the depth attachment, which hides the splats behind them (null: no depth test);
  // surface_depth, when not null, receives the splats' depth out as the tile compositor writes it (the
  // depth at which a pixel's alpha first reaches surface_alpha, 0 where it never does).
  CompositePass::HostSurface host;
  bool half_colour = false;  // fp16-blend (AccuracyModes::fp16_blend): an RGBA16F colour attachment
};

// Which stage draws the quads: the mesh stage where a GPU has VK_EXT_mesh_shader (each splat's record
// read once, 32 splats a workgroup), else the vertex stage (four vertices an instance), which CPU drivers
// run faster. TILESPLAT_RASTER_STAGE=vertex or mesh chooses, so that the tests hold both to the same
// images; mesh on a device without it throws std::runtime_error naming the device.
bool raster_stage_is_mesh(const vk::Context& ctx);

class RasterCompositePass {
 public:
  // Makes nothing yet: a renderer that never draws with the raster compositor needs no graphics support.
  explicit RasterCompositePass(vk::Context& ctx);
  ~RasterCompositePass() { release_framebuffer(); }
  RasterCompositePass(const RasterCompositePass&) = delete;
  RasterCompositePass& operator=(const RasterCompositePass&) = delete;

  // Which attachments a frame draws into besides the colour, and the colour's format: its outputs and
  // whether a host's surfaces are tested. The frame's shape and its pipeline both follow from them.
  struct Attachments {
    bool write_depth = false, write_count = false;
    bool host_depth = false;     // the depth attachment holds a host's surfaces (HOST_DEPTH)
    bool surface_depth = false;  // a host's depth out: the fragment stage reads the colour as an input
                                 // attachment and writes the depth (raster_blend_surface)
    bool half_colour = false;    // fp16-blend: the colour attachment is RGBA16F
    auto operator<=>(const Attachments&) const = default;
  };
  // What a frame's attachments are: its size and which ones.
  struct Shape {
    uint32_t width = 0, height = 0;
    Attachments attachments;
    bool operator==(const Shape&) const = default;
  };
  // Sizes the attachments for a frame (outside any command buffer). Throws std::runtime_error naming
  // the device when it cannot draw, blend or test what the frame asks.
  void prepare(const Shape& shape);
  void record(VkCommandBuffer cmd, const RasterInputs& in);
  uint64_t device_bytes() const;

 private:
  // A pipeline of the pass: its stage, its attachments and its cut-offs.
  struct Variant {
    bool mesh = false;  // the mesh stage draws the quads (raster_quads.mesh), else the vertex stage
    Attachments attachments;
    CompositeCutoffs cutoffs;
    auto operator<=>(const Variant&) const = default;
  };
  vk::GraphicsPipeline& pipeline(const Variant& variant);
  void check_device(const Shape& shape) const;

  vk::Context& ctx_;
  vk::PipelineVariants<Variant, vk::GraphicsPipeline> pipelines_;
  vk::ComputePipeline resolve_;
  // VkDrawIndirectCommand (4 vertices, the visible splats as instances) or, for the mesh stage,
  // VkDrawMeshTasksIndirectCommandEXT.
  vk::Buffer draw_args_;
  vk::ComputePipeline host_surfaces_;
  vk::ComputePipeline mesh_args_;  // the mesh-stage draw's workgroup counts (raster_mesh_args.comp)
  bool mesh_ = false;              // raster_stage_is_mesh(), decided on the first raster frame
  // The attachments of the current shape and their framebuffer (for the render pass of that shape:
  // every Variant of it has a compatible one).
  struct Targets {
    Shape shape;
    vk::Image colour, depth_sums, count, surface, host_surfaces;
    vk::Buffer depth_sums_copy;      // the depth sums copied out for the resolve
    vk::Buffer half_colour_copy;     // fp16-blend: the RGBA16F colour copied out for the resolve
    vk::Buffer host_surfaces_input;  // the host's scaled view depths, copied into host_surfaces
    VkFramebuffer framebuffer = VK_NULL_HANDLE;
  } targets_;
  void release_framebuffer();
};

}  // namespace tilesplat
