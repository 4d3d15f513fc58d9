#include "passes/raster_composite_pass.h"

#include <bit>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

#include "passes/frame_counters.h"
#include "passes/tile_coverage.h"
#include "shader_io.h"
#include "vulkan/barriers.h"
#include "vulkan/vk_check.h"

namespace tilesplat {

namespace {
using shader_io::RasterHostSurfacesPush;
using shader_io::RasterMeshArgsPush;
using shader_io::RasterPush;
using shader_io::RasterResolvePush;

// Float attachments: the blend runs in float32, as the tile compositor's sums do.
constexpr VkFormat kColourFormat = VK_FORMAT_R32G32B32A32_SFLOAT;  // (sum of w rgb, 1 - T)
constexpr VkFormat kHalfColourFormat = VK_FORMAT_R16G16B16A16_SFLOAT;  // the same, with fp16-blend
constexpr VkFormat kCountFormat = VK_FORMAT_R32_SFLOAT;            // exact for counts below 2^24
constexpr VkFormat kHostSurfacesFormat = VK_FORMAT_D32_SFLOAT;     // view depths times 2^-64
constexpr VkImageUsageFlags kAttachmentUsage =
    VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
constexpr uint32_t kQuadVertices = 4;  // a triangle strip

VkBufferImageCopy whole_image(const vk::Image& image) {
  VkBufferImageCopy region{};
  region.imageSubresource = {image.aspect(), 0, 0, 1};
  region.imageExtent = {image.width(), image.height(), 1};
  return region;
}

void copy_to_buffer(VkCommandBuffer cmd, const vk::Image& image, const vk::Buffer& buffer) {
  const VkBufferImageCopy region = whole_image(image);
  vkCmdCopyImageToBuffer(cmd, image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer.handle(), 1,
                         &region);
}

// The buffer into the depth image, whose old contents are not needed, once the previous frame's depth
// tests are done with it; the render pass then reads it from TRANSFER_DST_OPTIMAL (its dependency
// waits for this copy).
void copy_to_depth_image(VkCommandBuffer cmd, const vk::Buffer& buffer, const vk::Image& image) {
  vk::transition(cmd, {image.handle(), image.aspect(), VK_IMAGE_LAYOUT_UNDEFINED,
                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT});
  const VkBufferImageCopy region = whole_image(image);
  vkCmdCopyBufferToImage(cmd, buffer.handle(), image.handle(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                         &region);
}

}  // namespace

bool raster_stage_is_mesh(const vk::Context& ctx) {
  const char* env = std::getenv("TILESPLAT_RASTER_STAGE");
  const std::string stage = env ? env : "";
  // llvmpipe runs the mesh stage slower than the instanced vertex stage (Mesa 25, 500k playbot at 1080p:
  // 1244-1316 against 807-815 ms, interleaved; docs/compositors.md): there the vertex stage.
  if (stage.empty()) return ctx.features().mesh_shader && !ctx.is_cpu_device();
  if (stage == "vertex") return false;
  if (stage != "mesh")
    throw std::invalid_argument("TILESPLAT_RASTER_STAGE must be vertex or mesh, got '" + stage + "'");
  if (!ctx.features().mesh_shader)
    throw std::runtime_error(
        ctx.device_name() +
        ": TILESPLAT_RASTER_STAGE=mesh, and this device has no VK_EXT_mesh_shader (or the "
        "renderer did not make it)");
  return true;
}

RasterCompositePass::RasterCompositePass(vk::Context& ctx) : ctx_(ctx) {}

void RasterCompositePass::check_device(const Shape& shape) const {
  const Attachments& a = shape.attachments;
  auto fail = [&](const std::string& why) { throw std::runtime_error(ctx_.device_name() + ": " + why); };
  if (!ctx_.features().graphics_queue)
    fail(
        "the raster compositor draws, and this device's queue has no graphics support: use the sorted "
        "compositor");
  const VkFormatFeatureFlags attachment = VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT |
                                          VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT |
                                          VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
  for (VkFormat format : {kColourFormat, kCountFormat})
    if (!vk::format_supports(ctx_, format, attachment))
      fail(std::string("the raster compositor blends into ") +
           (format == kColourFormat ? "R32G32B32A32_SFLOAT" : "R32_SFLOAT") +
           " attachments, which this device cannot: use the sorted compositor");
  if (a.half_colour && !vk::format_supports(ctx_, kHalfColourFormat, attachment))
    fail("fp16-blend blends into an R16G16B16A16_SFLOAT attachment, which this device cannot: leave it out");
  // The counts are added where the colour is blended under: two blend states in one pipeline.
  if (a.write_count && !ctx_.features().independent_blend)
    fail(
        "the raster compositor's splat counts need the independentBlend feature, which this device (or "
        "the host that made it) has not enabled: render without splat counts");
  // The depth out is kept by a MIN blend beside the colour's, from fragments that read the colour.
  if (a.surface_depth && !ctx_.features().independent_blend)
    fail(
        "the raster compositor's depth out (HostDepth::write_depth) needs the independentBlend feature, "
        "which this device (or the host that made it) has not enabled: use the sorted compositor");
  if (a.surface_depth && !ctx_.features().rasterization_order_colour)
    fail(
        "the raster compositor's depth out (HostDepth::write_depth) reads each pixel's running alpha in the "
        "fragment stage, which needs VK_EXT_rasterization_order_attachment_access "
        "(rasterizationOrderColorAttachmentAccess), not on this device or not enabled by the host that "
        "made it: use the sorted compositor");
  if (a.host_depth && !vk::format_supports(ctx_, kHostSurfacesFormat,
                                           VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT |
                                               VK_FORMAT_FEATURE_TRANSFER_DST_BIT))
    fail(
        "the raster compositor tests a host's depth in a D32_SFLOAT attachment, which this device cannot "
        "make: use the sorted compositor");
}

void RasterCompositePass::release_framebuffer() {
  if (targets_.framebuffer) vkDestroyFramebuffer(ctx_.device(), targets_.framebuffer, nullptr);
  targets_.framebuffer = VK_NULL_HANDLE;
}

void RasterCompositePass::prepare(const Shape& shape) {
  Targets& t = targets_;
  if (t.colour && t.shape == shape) return;  // checked and sized when this shape first came
  check_device(shape);
  if (!draw_args_) {
    mesh_ = raster_stage_is_mesh(ctx_);
    if (mesh_) mesh_args_ = vk::ComputePipeline(ctx_, "raster_mesh_args", sizeof(RasterMeshArgsPush));
    resolve_ = vk::ComputePipeline(ctx_, "raster_resolve", sizeof(RasterResolvePush));
    host_surfaces_ = vk::ComputePipeline(ctx_, "raster_host_surfaces", sizeof(RasterHostSurfacesPush));
    draw_args_ =
        vk::Buffer(ctx_, sizeof(VkDrawIndirectCommand), vk::MemoryUse::Device, "raster draw arguments");
  }
  release_framebuffer();
  t = {};
  const uint32_t width = shape.width, height = shape.height;
  const Attachments& a = shape.attachments;
  const VkDeviceSize pixels = VkDeviceSize(width) * height;
  // The depth out's fragments read the colour as an input attachment.
  t.colour = vk::Image(ctx_, a.half_colour ? kHalfColourFormat : kColourFormat, width, height,
                       kAttachmentUsage | (a.surface_depth ? VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT : 0),
                       "raster colour");
  if (a.half_colour)
    t.half_colour_copy = vk::Buffer(ctx_, pixels * 8, vk::MemoryUse::Device, "raster colour (half, copy)");
  if (a.write_depth) {
    t.depth_sums = vk::Image(ctx_, kColourFormat, width, height, kAttachmentUsage, "raster depth sums");
    t.depth_sums_copy = vk::Buffer(ctx_, pixels * 16, vk::MemoryUse::Device, "raster depth sums (copy)");
  }
  if (a.write_count)
    t.count = vk::Image(ctx_, kCountFormat, width, height, kAttachmentUsage, "raster counts");
  if (a.surface_depth)
    t.surface = vk::Image(ctx_, kCountFormat, width, height, kAttachmentUsage, "raster depth out");
  if (a.host_depth) {
    t.host_surfaces = vk::Image(ctx_, kHostSurfacesFormat, width, height,
                                VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                                "raster host surfaces");
    t.host_surfaces_input =
        vk::Buffer(ctx_, pixels * 4, vk::MemoryUse::Device, "raster host surfaces (input)");
  }
  t.shape = shape;
}

vk::GraphicsPipeline& RasterCompositePass::pipeline(const Variant& v) {
  const Attachments& a = v.attachments;
  return pipelines_.get(v, [&] {
    vk::GraphicsPipelineDesc desc;
    if (v.mesh)
      desc.mesh_shader = "raster_quads";
    else
      desc.vertex_shader = "raster_quad";
    desc.fragment_shader = a.surface_depth ? "raster_blend_surface" : "raster_blend";
    desc.push_constant_bytes = sizeof(RasterPush);
    desc.spec = {{0, std::bit_cast<uint32_t>(coverage_alpha_inv(v.cutoffs.alpha))},
                 {1, std::bit_cast<uint32_t>(v.cutoffs.alpha)},
                 {2, std::bit_cast<uint32_t>(v.cutoffs.max_alpha)},
                 {3, a.host_depth ? 1u : 0u}};
    // Without the counts every blend state is the same, as a device without independentBlend requires.
    desc.attachments = {{a.half_colour ? kHalfColourFormat : kColourFormat, vk::Blend::kUnder, true},
                        {kColourFormat, vk::Blend::kUnder, a.write_depth},
                        {kCountFormat, a.write_count ? vk::Blend::kAdd : vk::Blend::kUnder, a.write_count}};
    if (a.surface_depth) {
      desc.attachments.push_back({kCountFormat, vk::Blend::kMin, true});
      desc.input_attachment = 0;  // the colour, whose alpha is 1 - T
    }
    if (a.host_depth) desc.depth_test = vk::DepthTest{kHostSurfacesFormat, VK_COMPARE_OP_LESS};
    return vk::GraphicsPipeline(ctx_, desc);
  });
}

void RasterCompositePass::record(VkCommandBuffer cmd, const RasterInputs& in) {
  Targets& t = targets_;
  const Shape shape{in.out.width,
                    in.out.height,
                    {.write_depth = in.write_depth,
                     .write_count = in.write_count,
                     .host_depth = in.host.view_depth != nullptr,
                     .surface_depth = in.host.surface_depth != nullptr,
                     .half_colour = in.half_colour}};
  if (!t.colour || !(t.shape == shape))
    throw std::logic_error("RasterCompositePass::record before prepare() for this frame's shape");
  const Attachments& a = shape.attachments;
  // The transmittance cut-off does not apply: one pipeline whatever it is.
  const Variant variant{mesh_, shape.attachments, {in.cutoffs.alpha, 0.0f, in.cutoffs.max_alpha}};
  vk::GraphicsPipeline& drawing = pipeline(variant);
  if (!t.framebuffer) {
    std::vector<VkImageView> views = {t.colour.view()};
    if (a.write_depth) views.push_back(t.depth_sums.view());
    if (a.write_count) views.push_back(t.count.view());
    if (a.surface_depth) views.push_back(t.surface.view());
    if (a.host_depth) views.push_back(t.host_surfaces.view());
    VkFramebufferCreateInfo info{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    info.renderPass = drawing.render_pass();  // compatible with every variant of this shape
    info.attachmentCount = uint32_t(views.size());
    info.pAttachments = views.data();
    info.width = shape.width;
    info.height = shape.height;
    info.layers = 1;
    TS_VK_CHECK(vkCreateFramebuffer(ctx_.device(), &info, nullptr, &t.framebuffer));
  }
  const uint32_t pixels = shape.width * shape.height;
  if (a.host_depth) {
    const RasterHostSurfacesPush surfaces{in.host.view_depth->address(), t.host_surfaces_input.address(),
                                          pixels};
    host_surfaces_.bind(cmd, surfaces);
    host_surfaces_.dispatch(cmd, vk::div_ceil(pixels, 256));
    vk::barrier(cmd);
    copy_to_depth_image(cmd, t.host_surfaces_input, t.host_surfaces);
  }

  // The draw's arguments from the projection's visible count (the depth sort put those splats first):
  // a workgroup per RASTER_MESH_SPLATS of them, or 4 vertices and an instance per splat.
  if (mesh_) {
    const RasterMeshArgsPush args{in.counters.address(), draw_args_.address(),
                                  ctx_.limits().max_mesh_workgroup_count_x};
    mesh_args_.bind(cmd, args);
    mesh_args_.dispatch(cmd, 1);
  } else {
    vkCmdFillBuffer(cmd, draw_args_.handle(), offsetof(VkDrawIndirectCommand, vertexCount), 4, kQuadVertices);
    vkCmdFillBuffer(cmd, draw_args_.handle(), offsetof(VkDrawIndirectCommand, firstVertex), 8, 0);
    const VkBufferCopy visible{offsetof(FrameCounters, visible),
                               offsetof(VkDrawIndirectCommand, instanceCount), sizeof(uint32_t)};
    vkCmdCopyBuffer(cmd, in.counters.handle(), draw_args_.handle(), 1, &visible);
  }

  // Zero: no colour, T = 1, no depth, no splats; +inf: no depth out yet (a host's depth is loaded).
  std::vector<VkClearValue> clears(1 + (a.write_depth ? 1 : 0) + (a.write_count ? 1 : 0));
  if (a.surface_depth) {
    VkClearValue none{};
    none.color.float32[0] = std::numeric_limits<float>::infinity();
    clears.push_back(none);
  }
  VkRenderPassBeginInfo begin{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  begin.renderPass = drawing.render_pass();
  begin.framebuffer = t.framebuffer;
  begin.renderArea = {{0, 0}, {shape.width, shape.height}};
  begin.clearValueCount = uint32_t(clears.size());
  begin.pClearValues = clears.data();
  vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
  RasterPush push{};
  push.splats = in.splats.address();
  push.depth_order = in.depth_order.address();
  push.counters = in.counters.address();
  push.width = shape.width;
  push.height = shape.height;
  push.first_tile = in.out.first_tile;
  push.surface_alpha = in.host.surface_alpha;
  drawing.bind(cmd, push, shape.width, shape.height);
  if (a.surface_depth) drawing.bind_input_attachment(cmd, t.colour.view());
  if (mesh_)
    ctx_.cmd_draw_mesh_tasks_indirect()(cmd, draw_args_.handle(), 0, 1,
                                        sizeof(VkDrawMeshTasksIndirectCommandEXT));
  else
    vkCmdDrawIndirect(cmd, draw_args_.handle(), 0, 1, sizeof(VkDrawIndirectCommand));
  vkCmdEndRenderPass(cmd);

  // The attachments into the outputs, then the resolve in place.
  copy_to_buffer(cmd, t.colour, a.half_colour ? t.half_colour_copy : in.out.rgba);
  if (a.write_depth) copy_to_buffer(cmd, t.depth_sums, t.depth_sums_copy);
  if (a.write_count) copy_to_buffer(cmd, t.count, in.out.count);
  if (a.surface_depth) copy_to_buffer(cmd, t.surface, *in.host.surface_depth);
  vk::barrier(cmd);
  RasterResolvePush resolve{};
  resolve.rgba = in.out.rgba.address();
  resolve.depth_sums = a.write_depth ? t.depth_sums_copy.address() : in.out.rgba.address();
  resolve.out_depth = a.write_depth ? in.out.depth.address() : in.out.rgba.address();
  resolve.count = a.write_count ? in.out.count.address() : in.out.rgba.address();
  resolve.surface = a.surface_depth ? in.host.surface_depth->address() : in.out.rgba.address();
  resolve.half_rgba = a.half_colour ? t.half_colour_copy.address() : in.out.rgba.address();
  resolve.background = {in.background[0], in.background[1], in.background[2], 0.0f};
  resolve.pixels = pixels;
  resolve.write_depth = a.write_depth ? 1 : 0;
  resolve.write_count = a.write_count ? 1 : 0;
  resolve.write_surface = a.surface_depth ? 1 : 0;
  resolve.half_colour = a.half_colour ? 1 : 0;
  resolve_.bind(cmd, resolve);
  resolve_.dispatch(cmd, vk::div_ceil(pixels, 256));
  vk::barrier(cmd);
}

uint64_t RasterCompositePass::device_bytes() const {
  const Targets& t = targets_;
  return t.colour.bytes() + t.depth_sums.bytes() + t.count.bytes() + t.surface.bytes() +
         t.host_surfaces.bytes() + t.depth_sums_copy.size() + t.half_colour_copy.size() +
         t.host_surfaces_input.size() + draw_args_.size();
}

}  // namespace tilesplat
