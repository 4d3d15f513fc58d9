#include "passes/raster_composite_pass.h"

#include <bit>
#include <stdexcept>
#include <string>

#include "passes/frame_counters.h"
#include "passes/tile_coverage.h"
#include "shader_io.h"
#include "vulkan/vk_check.h"

namespace tilesplat {

namespace {
using shader_io::RasterPush;
using shader_io::RasterResolvePush;

// Float attachments: the blend runs in float32, as the tile compositor's sums do.
constexpr VkFormat kColourFormat = VK_FORMAT_R32G32B32A32_SFLOAT;  // (sum of w rgb, 1 - T)
constexpr VkFormat kCountFormat = VK_FORMAT_R32_SFLOAT;            // exact for counts below 2^24
constexpr VkImageUsageFlags kAttachmentUsage =
    VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
constexpr uint32_t kQuadVertices = 4;  // a triangle strip

void copy_to_buffer(VkCommandBuffer cmd, const vk::Image& image, const vk::Buffer& buffer) {
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {image.width(), image.height(), 1};
  vkCmdCopyImageToBuffer(cmd, image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer.handle(), 1,
                         &region);
}

}  // namespace

RasterCompositePass::RasterCompositePass(vk::Context& ctx) : ctx_(ctx) {}

void RasterCompositePass::check_device() const {
  if (!ctx_.features().graphics_queue)
    throw std::runtime_error(
        ctx_.device_name() +
        ": the raster compositor draws, and this device's queue has no graphics support: "
        "use the sorted compositor");
  const VkFormatFeatureFlags attachment = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT |
                                          VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT |
                                          VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
  for (VkFormat format : {kColourFormat, kCountFormat})
    if (!vk::format_supports(ctx_, format, attachment))
      throw std::runtime_error(ctx_.device_name() + ": the raster compositor blends into " +
                               (format == kColourFormat ? "R32G32B32A32_SFLOAT" : "R32_SFLOAT") +
                               " attachments, which this device cannot: use the sorted compositor");
}

void RasterCompositePass::release_framebuffer() {
  if (targets_.framebuffer) vkDestroyFramebuffer(ctx_.device(), targets_.framebuffer, nullptr);
  targets_.framebuffer = VK_NULL_HANDLE;
}

void RasterCompositePass::prepare(uint32_t width, uint32_t height, bool write_depth, bool write_count) {
  // The counts are added where the colour is blended under: two blend states in one pipeline.
  if (write_count && !ctx_.features().independent_blend)
    throw std::runtime_error(
        ctx_.device_name() +
        ": the raster compositor's splat counts need the independentBlend feature, which "
        "this device (or the host that made it) has not enabled: render without splat "
        "counts");
  if (!draw_args_) {  // the first raster frame: the device must draw
    check_device();
    resolve_ = vk::ComputePipeline(ctx_, "raster_resolve", sizeof(RasterResolvePush));
    draw_args_ =
        vk::Buffer(ctx_, sizeof(VkDrawIndirectCommand), vk::MemoryUse::Device, "raster draw arguments");
  }
  Targets& t = targets_;
  if (t.colour && t.width == width && t.height == height && t.write_depth == write_depth &&
      t.write_count == write_count)
    return;
  release_framebuffer();
  t = {};
  t.colour = vk::Image(ctx_, kColourFormat, width, height, kAttachmentUsage, "raster colour");
  if (write_depth) {
    t.depth_sums = vk::Image(ctx_, kColourFormat, width, height, kAttachmentUsage, "raster depth sums");
    t.depth_sums_copy = vk::Buffer(ctx_, VkDeviceSize(width) * height * 16, vk::MemoryUse::Device,
                                   "raster depth sums (copy)");
  }
  if (write_count) t.count = vk::Image(ctx_, kCountFormat, width, height, kAttachmentUsage, "raster counts");
  t.width = width;
  t.height = height;
  t.write_depth = write_depth;
  t.write_count = write_count;
}

const vk::GraphicsPipeline& RasterCompositePass::pipeline(const Variant& v) {
  auto it = pipelines_.find(v);
  if (it != pipelines_.end()) return it->second;
  vk::GraphicsPipelineDesc desc;
  desc.vertex_shader = "raster_quad";
  desc.fragment_shader = "raster_blend";
  desc.push_constant_bytes = sizeof(RasterPush);
  desc.spec = {{0, std::bit_cast<uint32_t>(coverage_alpha_inv(v.cutoffs.alpha))},
               {1, std::bit_cast<uint32_t>(v.cutoffs.alpha)},
               {2, std::bit_cast<uint32_t>(v.cutoffs.max_alpha)}};
  desc.attachments = {{kColourFormat, vk::Blend::kUnder, true},
                      {kColourFormat, vk::Blend::kUnder, v.write_depth},
                      {kCountFormat, vk::Blend::kAdd, v.write_count}};
  return pipelines_.emplace(v, vk::GraphicsPipeline(ctx_, desc)).first->second;
}

void RasterCompositePass::record(VkCommandBuffer cmd, const RasterInputs& in) {
  Targets& t = targets_;
  if (!t.colour || t.width != in.out.width || t.height != in.out.height || t.write_depth != in.write_depth ||
      t.write_count != in.write_count)
    throw std::logic_error("RasterCompositePass::record before prepare() for this frame's size and outputs");
  // The transmittance cut-off does not apply: one pipeline whatever it is.
  const Variant variant{in.write_depth, in.write_count, {in.cutoffs.alpha, 0.0f, in.cutoffs.max_alpha}};
  const vk::GraphicsPipeline& drawing = pipeline(variant);
  if (!t.framebuffer) {
    std::vector<VkImageView> views = {t.colour.view()};
    if (t.write_depth) views.push_back(t.depth_sums.view());
    if (t.write_count) views.push_back(t.count.view());
    VkFramebufferCreateInfo info{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    info.renderPass = drawing.render_pass();  // compatible with every variant of these outputs
    info.attachmentCount = uint32_t(views.size());
    info.pAttachments = views.data();
    info.width = t.width;
    info.height = t.height;
    info.layers = 1;
    TS_VK_CHECK(vkCreateFramebuffer(ctx_.device(), &info, nullptr, &t.framebuffer));
  }

  // The draw's arguments: 4 vertices, one instance per visible splat (the projection's count; the
  // depth sort put them first), from the first instance.
  vkCmdFillBuffer(cmd, draw_args_.handle(), offsetof(VkDrawIndirectCommand, vertexCount), 4, kQuadVertices);
  vkCmdFillBuffer(cmd, draw_args_.handle(), offsetof(VkDrawIndirectCommand, firstVertex), 8, 0);
  const VkBufferCopy visible{offsetof(FrameCounters, visible), offsetof(VkDrawIndirectCommand, instanceCount),
                             sizeof(uint32_t)};
  vkCmdCopyBuffer(cmd, in.counters.handle(), draw_args_.handle(), 1, &visible);

  VkClearValue clears[3]{};  // all zero: no colour, T = 1, no depth, no splats
  VkRenderPassBeginInfo begin{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  begin.renderPass = drawing.render_pass();
  begin.framebuffer = t.framebuffer;
  begin.renderArea = {{0, 0}, {t.width, t.height}};
  begin.clearValueCount = 1 + (t.write_depth ? 1 : 0) + (t.write_count ? 1 : 0);
  begin.pClearValues = clears;
  vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
  RasterPush push{};
  push.splats = in.splats.address();
  push.depth_order = in.depth_order.address();
  push.width = t.width;
  push.height = t.height;
  drawing.bind(cmd, push, t.width, t.height);
  vkCmdDrawIndirect(cmd, draw_args_.handle(), 0, 1, sizeof(VkDrawIndirectCommand));
  vkCmdEndRenderPass(cmd);

  // The attachments into the outputs, then the resolve in place.
  copy_to_buffer(cmd, t.colour, in.out.rgba);
  if (t.write_depth) copy_to_buffer(cmd, t.depth_sums, t.depth_sums_copy);
  if (t.write_count) copy_to_buffer(cmd, t.count, in.out.count);
  vk::barrier(cmd);
  RasterResolvePush resolve{};
  resolve.rgba = in.out.rgba.address();
  resolve.depth_sums = t.write_depth ? t.depth_sums_copy.address() : in.out.rgba.address();
  resolve.out_depth = t.write_depth ? in.out.depth.address() : in.out.rgba.address();
  resolve.count = t.write_count ? in.out.count.address() : in.out.rgba.address();
  resolve.background = {in.background[0], in.background[1], in.background[2], 0.0f};
  resolve.pixels = t.width * t.height;
  resolve.write_depth = t.write_depth ? 1 : 0;
  resolve.write_count = t.write_count ? 1 : 0;
  resolve_.bind(cmd, resolve);
  resolve_.dispatch(cmd, vk::div_ceil(resolve.pixels, 256));
  vk::barrier(cmd);
}

uint64_t RasterCompositePass::device_bytes() const {
  return targets_.colour.bytes() + targets_.depth_sums.bytes() + targets_.count.bytes() +
         targets_.depth_sums_copy.size() + draw_args_.size();
}

}  // namespace tilesplat
