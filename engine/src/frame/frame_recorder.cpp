#include "frame/frame_recorder.h"

#include <algorithm>
#include <cstddef>

#include "host_images.h"
#include "passes/frame_counters.h"

namespace tilesplat {

FrameRecorder::FrameRecorder(vk::Context& ctx, vk::GpuTimer& timer)
    : ctx_(ctx),
      timer_(timer),
      projection_(ctx),
      depth_quantize_(ctx),
      prefix_sum_(ctx),
      key_emission_(ctx),
      tile_ranges_(ctx),
      composite_(ctx),
      composite_resort_(ctx),
      stochastic_composite_(ctx),
      raster_composite_(ctx),
      host_depth_(ctx),
      pack_colour_(ctx),
      sample_accumulate_(ctx) {}

void FrameRecorder::set_frame_inputs(const Camera& camera, const Lighting& lighting, double near_plane,
                                     const TileGrid& tiles, SceneBuffers& scene) {
  projection_.set_lighting(lighting, scene);  // validates the lights; uploads normals on first use
  projection_.set_camera(camera, near_plane, tiles);
}

uint32_t FrameRecorder::chunks_for(Compositor compositor, uint64_t longest_tile_list) const {
  return compositor == Compositor::kStochastic ? stochastic_composite_.chunks_for(longest_tile_list)
                                               : composite_.chunks_for(longest_tile_list);
}

void FrameRecorder::prepare(const FramePlan& plan, FrameResources& resources, SortStrategy& sorter) {
  resources.prepare_frame(plan, plan.composite_state);
  if (plan.compositor == Compositor::kRaster)
    raster_composite_.prepare({plan.tiles.width,
                               plan.tiles.height,
                               {.write_depth = plan.outputs.depth,
                                .write_count = plan.outputs.splat_count,
                                .host_depth = plan.host.from_memory || plan.host.from_image,
                                .surface_depth = plan.host.write_depth,
                                .half_colour = plan.outputs.half_colour}});
  if (!plan.build_lists) return;
  projection_.prepare(resources.scene, plan.projection);
  // The depth sort's buffers hold the projected records (more than this frame's after a larger part).
  sorter.reserve(std::max(resources.projected.records, resources.keys.capacity));
}

struct FrameRecorder::Recording {
  vk::CommandStream& stream;
  const FramePlan& plan;
  FrameResources& res;
  SortStrategy& sorter;
  const ExternalDepthImage* depth_image;
  const vk::Buffer* depth_order = nullptr;  // the depth sort's result, for the prefix sum and key emission
};

void FrameRecorder::record(vk::CommandStream& stream, const FramePlan& plan, FrameResources& resources,
                           SortStrategy& sorter, const ExternalDepthImage* depth_image) {
  Recording r{stream, plan, resources, sorter, depth_image};
  timer_.begin_frame(stream.cmd());
  for (FramePass pass : plan.passes) {
    record_pass(r, pass);
    if (const char* name = timed_name(pass)) timer_.mark(stream.cmd(), name);
  }
}

void FrameRecorder::record_pass(Recording& r, FramePass pass) {
  FrameResources& res = r.res;
  const FramePlan& plan = r.plan;
  const uint32_t n = plan.splat_records;  // projected records: the Gaussians, or their seam copies too
  VkCommandBuffer cmd = r.stream.cmd();  // a host sort flushes the stream: each pass takes the current one
  switch (pass) {
    case FramePass::kHostDepthIn:
      record_host_depth_in(cmd, *r.depth_image, plan.host.convention, res);
      return;
    case FramePass::kClearCounters:
      vkCmdFillBuffer(cmd, res.counters.handle(), 0, VK_WHOLE_SIZE, 0);
      vkCmdFillBuffer(cmd, res.ranges.handle(), 0, VK_WHOLE_SIZE, 0);
      vkCmdFillBuffer(cmd, res.counters.handle(), kDepthSortOffset + offsetof(SortState, count),
                      sizeof(uint32_t), n);
      // The nearest visible depth is a minimum over the Gaussians: it starts at the largest value.
      vkCmdFillBuffer(cmd, res.counters.handle(), kDepthRangeOffset, sizeof(uint32_t), 0xffffffffu);
      // The big-splat key emission's dispatch is (listed splats, 1, 1).
      vkCmdFillBuffer(cmd, res.counters.handle(), kBigSplatsOffset + sizeof(uint32_t), 2 * sizeof(uint32_t),
                      1);
      vk::barrier(cmd);
      return;
    case FramePass::kResetLongestList:
      // The composite's chunk 0 raises the longest-list counter: it starts from zero again.
      vkCmdFillBuffer(cmd, res.counters.handle(), offsetof(FrameCounters, max_tile_pairs), sizeof(uint32_t),
                      0);
      vk::barrier(cmd);
      return;
    case FramePass::kProjection:
      projection_.record(cmd, res.scene, res.projected, res.counters.address(), plan.projection);
      vk::barrier(cmd);
      return;
    case FramePass::kDepthQuantize:
      depth_quantize_.record(cmd, res.projected, n, res.counters.address());
      vk::barrier(cmd);
      return;
    case FramePass::kDepthSort: {
      SortInput input{res.projected.depth_order, res.counters, kDepthSortOffset, plan.depth_key_bits, true};
      res.depth_order_in_alt = r.sorter.record(r.stream, input);
      r.depth_order =
          res.depth_order_in_alt ? &res.projected.depth_order.values_alt : &res.projected.depth_order.values;
      return;
    }
    case FramePass::kPrefixSum:
      // In depth order after a depth sort (each Gaussian's pairs then follow the nearer ones'), else
      // in index order.
      if (r.depth_order)
        prefix_sum_.record(cmd, res.projected.tile_counts.address(), res.projected.depth_offsets.address(), n,
                           res.counters.address(), r.depth_order->address());
      else
        prefix_sum_.record(cmd, res.projected.tile_counts.address(), res.projected.offsets.address(), n,
                           res.counters.address());
      return;
    case FramePass::kKeyEmission:
      key_emission_.record(cmd, res.projected, r.depth_order, res.keys, n, plan.tiles, res.counters,
                           plan.projection.square_tiles, plan.projection.alpha_inv);
      vk::barrier(cmd);
      return;
    case FramePass::kTileSort:
    case FramePass::kTileBinning: {
      // The pairs by tile id: 32-bit tile keys after a depth sort or for binning; 64-bit (tile, depth)
      // keys, the tile above bit 32, for a strategy that sorts those itself.
      const bool pairs = !plan.depth_first && pass == FramePass::kTileSort;
      SortInput input{res.keys, res.counters, kTileSortOffset,
                      pairs ? 32 + plan.tiles.tile_bits : plan.tiles.tile_bits, pairs};
      res.lists_in_alt = r.sorter.record(r.stream, input);
      return;
    }
    case FramePass::kTileRanges:
      tile_ranges_.record(cmd, res.lists_in_alt ? res.keys.keys_alt : res.keys.keys, res.keys.wide_keys,
                          res.ranges, res.counters, kRangesArgsOffset, plan.tiles.count);
      vk::barrier(cmd);
      return;
    case FramePass::kComposite:
    case FramePass::kResortComposite:
    case FramePass::kStochasticComposite:
      record_composite(r, pass);
      return;
    case FramePass::kRasterComposite: {
      // The depth order this frame's sort left, or the one a frame on reused lists finds.
      const vk::Buffer& order =
          res.depth_order_in_alt ? res.projected.depth_order.values_alt : res.projected.depth_order.values;
      const FrameOutputs& outputs = plan.outputs;
      raster_composite_.record(
          cmd, {.splats = res.projected.splats,
                .depth_order = order,
                .counters = res.counters,
                .out = res.outputs,
                .background = outputs.background,
                .write_depth = outputs.depth,
                .write_count = outputs.splat_count,
                .cutoffs = {outputs.alpha_cutoff, outputs.transmittance_cutoff, outputs.max_alpha},
                .host = res.host_surface(plan.host),
                .half_colour = outputs.half_colour});
      return;
    }
    case FramePass::kAccumulateSamples:
      vk::barrier(cmd);  // the composite's outputs (the raster composite's resolve) before the sums read them
      sample_accumulate_.record(cmd, res.outputs, res.sample_sums, res.counters,
                                {.samples_before = plan.sample_sums->before,
                                 .write_depth = plan.outputs.depth,
                                 .write_count = plan.outputs.splat_count,
                                 .opaque = plan.sample_sums->opaque});
      vk::barrier(cmd);
      return;
  }
}

void FrameRecorder::record_composite(Recording& r, FramePass pass) {
  FrameResources& res = r.res;
  const FrameOutputs& outputs = r.plan.outputs;
  const CompositeInputs inputs{
      .splats = res.projected.splats,
      .tile_lists = res.lists_in_alt ? res.keys.values_alt : res.keys.values,
      .ranges = res.ranges,
      .out = res.outputs,
      .background = outputs.background,
      .write_depth = outputs.depth,
      .write_count = outputs.splat_count,
      .cutoffs = {outputs.alpha_cutoff, outputs.transmittance_cutoff, outputs.max_alpha}};
  const VkDeviceAddress counters = res.counters.address();
  if (pass == FramePass::kStochasticComposite)
    stochastic_composite_.record(
        r.stream, inputs,
        {r.plan.stochastic_samples, r.plan.stochastic_seed, r.plan.stochastic_sampler,
         r.plan.stochastic_first_sample, r.plan.stochastic_accumulate},
        {r.plan.composite_chunks, res.composite_state, counters});
  else if (pass == FramePass::kResortComposite)
    composite_resort_.record(r.stream.cmd(), inputs, res.projected.ray_depth, r.plan.lists.camera,
                             r.plan.resort_window, counters);
  else
    composite_.record(r.stream.cmd(), inputs, {r.plan.composite_chunks, res.composite_state, counters},
                      res.host_surface(r.plan.host),
                      {r.plan.part.carries_in(), r.plan.part.carries_out(), r.plan.part.state_high()});
}

// The host's depth image into host_window_depth and, as view depths, into host_view_depth.
void FrameRecorder::record_host_depth_in(VkCommandBuffer cmd, const ExternalDepthImage& image,
                                         const DepthConvention& convention, FrameResources& res) {
  copy_image_to_buffer(cmd, image.image, depth_aspect(image), image.layout, res.host_window_depth,
                       image.width, image.height);
  vk::barrier(cmd);
  host_depth_.record_view_depths(cmd, convention, res.host_window_depth, res.host_view_depth, image.width,
                                 image.height);
  vk::barrier(cmd);
}

void FrameRecorder::record_copies_to_images(VkCommandBuffer cmd, const FramePlan& plan, FrameResources& res,
                                            const ExternalImage& target,
                                            const ExternalDepthImage* depth_image) {
  // The colour: as it is for RGBA32F, else packed into the image's texel format first (pack_colour.comp),
  // which counts the values it saturates from zero (a frame on reused lists clears no counters).
  const vk::Buffer* source = &res.outputs.rgba;
  vkCmdFillBuffer(cmd, res.counters.handle(), offsetof(FrameCounters, saturated), sizeof(uint32_t), 0);
  vk::barrier(cmd);
  if (target.format != VK_FORMAT_R32G32B32A32_SFLOAT) {
    const VkDeviceSize bytes =
        VkDeviceSize(target.width) * target.height * PackColourPass::texel_bytes(target.format);
    if (res.packed_colour.size() < bytes)
      res.packed_colour = vk::Buffer(ctx_, bytes, vk::MemoryUse::Device, "packed colour (render_to_image)");
    pack_colour_.record(cmd, target.format, res.outputs.rgba, res.packed_colour, res.counters.address(),
                        target.width, target.height);
    vk::barrier(cmd);  // the packing's writes before the copy's reads
    source = &res.packed_colour;
  }
  copy_buffer_to_image(cmd, *source, target.image, VK_IMAGE_ASPECT_COLOR_BIT, target.layout, target.width,
                       target.height);
  if (!depth_image || !plan.host.write_depth) return;
  // The splats' depth where they reached the threshold, and the host's own elsewhere, into the host's
  // depth image (after the frame that wrote host_surface_depth).
  host_depth_.record_window_depths(cmd, plan.host.convention, res.host_surface_depth,
                                   res.host_window_depth, depth_image->width, depth_image->height);
  vk::barrier(cmd);
  copy_buffer_to_image(cmd, res.host_window_depth, depth_image->image, depth_aspect(*depth_image),
                       depth_image->layout, depth_image->width, depth_image->height);
}

}  // namespace tilesplat
