// Records a FramePlan into a command stream: each FramePass is one pass object's record(), timed
// under its name, in the plan's order. Owns the passes (their pipelines) and how many dispatches each
// composite takes, which later frames keep once a scene needed more.
#pragma once

#include <cstdint>

#include "frame/frame_plan.h"
#include "frame/frame_resources.h"
#include "passes/composite_pass.h"
#include "passes/composite_resort_pass.h"
#include "passes/depth_quantize_pass.h"
#include "passes/host_depth_pass.h"
#include "passes/key_emission_pass.h"
#include "passes/pack_colour_pass.h"
#include "passes/prefix_sum_pass.h"
#include "passes/projection_pass.h"
#include "passes/raster_composite_pass.h"
#include "passes/sample_accumulate_pass.h"
#include "passes/stochastic_composite_pass.h"
#include "passes/tile_ranges_pass.h"
#include "sort/sort_strategy.h"
#include "tilesplat/vulkan_interop.h"
#include "vulkan/command_stream.h"
#include "vulkan/gpu_timer.h"

namespace tilesplat {

class FrameRecorder {
 public:
  FrameRecorder(vk::Context& ctx, vk::GpuTimer& timer);

  // Writes what the projection reads from the host: the lights (validating them; uploading the
  // scene's normals on its first lit frame) and the camera with its near plane. Outside any command
  // buffer; not needed for a frame on reused lists, whose camera and lights are those in the buffers.
  void set_frame_inputs(const Camera& camera, const Lighting& lighting, double near_plane,
                        const TileGrid& tiles, SceneBuffers& scene);
  // Sizes the buffers, attachments and scratch the plan's passes use (the outputs it asks for). Outside
  // any command buffer, before record(). The recorder reads the plan and the resources, never the settings:
  // what it needs of them, plan_frame wrote into the plan.
  void prepare(const FramePlan& plan, FrameResources& resources, SortStrategy& sorter);
  // Records the plan's passes (the GPU timer's frame begins with them).
  void record(vk::CommandStream& stream, const FramePlan& plan, FrameResources& resources,
              SortStrategy& sorter, const ExternalDepthImage* depth_image);
  // What the host sees of a frame (render_to_image): its colour in the target's format and, with a
  // depth image and HostDepth::write_depth, the splats' depth.
  void record_copies_to_images(VkCommandBuffer cmd, const FramePlan& plan, FrameResources& resources,
                               const ExternalImage& target, const ExternalDepthImage* depth_image);

  // Dispatches per composite for this compositor (CompositePass::Chunks), as the last frame left it: what
  // the next plan takes (FrameContext::composite_chunks); and how many a tile list of this length needs.
  uint32_t& composite_chunks(Compositor compositor) {
    return compositor == Compositor::kStochastic ? stochastic_chunks_ : sorted_chunks_;
  }
  uint32_t chunks_for(Compositor compositor, uint64_t longest_tile_list) const;
  // The longest tile list per-pixel re-sorting can hold on this device.
  uint32_t max_resort_splats() const { return composite_resort_.max_tile_splats(); }
  uint64_t device_bytes() const { return prefix_sum_.device_bytes() + raster_composite_.device_bytes(); }

 private:
  struct Recording;  // the state one record() call carries from pass to pass
  void record_pass(Recording& r, FramePass pass);
  void record_host_depth_in(VkCommandBuffer cmd, const ExternalDepthImage& image,
                            const DepthConvention& convention, FrameResources& resources);
  void record_composite(Recording& r, FramePass pass);

  vk::Context& ctx_;
  vk::GpuTimer& timer_;
  ProjectionPass projection_;
  DepthQuantizePass depth_quantize_;
  PrefixSumPass prefix_sum_;
  KeyEmissionPass key_emission_;
  TileRangesPass tile_ranges_;
  CompositePass composite_;
  CompositeResortPass composite_resort_;
  StochasticCompositePass stochastic_composite_;
  RasterCompositePass raster_composite_;
  HostDepthPass host_depth_;    // render_to_image with a depth image
  PackColourPass pack_colour_;  // render_to_image into a colour image of another format than RGBA32
  SampleAccumulatePass sample_accumulate_;  // RenderSettings::accumulate_samplesF
  uint32_t sorted_chunks_ = 1;
  uint32_t stochastic_chunks_ = 1;
};

}  // namespace tilesplat
