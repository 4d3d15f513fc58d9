#include "mesh_layer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

namespace tilesplat::viewer {

namespace shaders {
std::span<const uint32_t> find(std::string_view name);  // generated: the viewer's embedded SPIR-V
}

namespace {

constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr VkFormat kSplatFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
// Unlit colours, linear light (flat_colour.frag encodes them): each box face its own, and the grid one the
// splats hardly ever produce.
constexpr float kBoxColours[6][3] = {{0.80f, 0.30f, 0.08f}, {0.70f, 0.25f, 0.06f}, {0.90f, 0.45f, 0.10f},
                                     {0.55f, 0.20f, 0.05f}, {0.85f, 0.38f, 0.09f}, {0.62f, 0.22f, 0.05f}};
constexpr float kGridColour[3] = {0.0f, 1.0f, 1.0f};
constexpr int kGridLines = 21;  // each way

vk::UniqueShaderModule make_module(VkDevice vk, const char* name) {
  const std::span<const uint32_t> words = shaders::find(name);
  if (words.empty()) throw std::logic_error(std::string("viewer shader not embedded: ") + name);
  return vk::make_shader_module(vk, words);
}

}  // namespace

// A constructor that throws runs no destructor of its own, but its members' do: whatever was made so far
// releases itself.
MeshLayer::MeshLayer(const WindowDevice& device, const Bounds& bounds, uint32_t width, uint32_t height)
    : device_(device), vk_(device.device()), width_(width), height_(height) {
  const double radius = std::max(bounds.radius, 1e-3);
  near_ = 0.01 * radius;
  far_ = 100.0 * radius;
  vk::Context& context = device.context();
  if (!vk::format_supports(context, kDepthFormat,
                           VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT |
                               VK_FORMAT_FEATURE_TRANSFER_SRC_BIT | VK_FORMAT_FEATURE_TRANSFER_DST_BIT))
    throw std::runtime_error(device.name() +
                             ": D32_SFLOAT depth buffers are not supported (run with --no-mesh)");
  if (!vk::format_supports(context, kPictureFormat,
                           VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT | VK_FORMAT_FEATURE_BLIT_SRC_BIT))
    throw std::runtime_error(device.name() +
                             ": R16G16B16A16_SFLOAT cannot be blended into and blitted (run with "
                             "--no-mesh)");
  picture_ =
      vk::Image(context, kPictureFormat, width_, height_,
                VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "the mesh's picture");
  depth_ = vk::Image(context, kDepthFormat, width_, height_,
                     VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                         VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                     "the mesh's depth");
  splats_ = vk::Image(context, kSplatFormat, width_, height_,
                      VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT, "the splats over black");
  build_geometry(bounds);
  create_render_passes();
  create_pipelines();
  command_pool_ = vk::make_command_pool(vk_, device.queue_family());
  box_commands_ = vk::allocate_command_buffer(vk_, command_pool_.get());
  grid_commands_ = vk::allocate_command_buffer(vk_, command_pool_.get());
  box_drawn_ = vk::make_semaphore(vk_);
  splats_drawn_ = vk::make_semaphore(vk_);
  box_fence_ = vk::make_fence(vk_);
  grid_fence_ = vk::make_fence(vk_);
}

MeshLayer::~MeshLayer() {
  for (auto [fence, pending] :
       {std::pair{box_fence_.get(), box_pending_}, std::pair{grid_fence_.get(), grid_pending_}})
    if (pending) vkWaitForFences(vk_, 1, &fence, VK_TRUE, std::numeric_limits<uint64_t>::max());
}

// A cube at the scene's centre, a third of its radius across each way (the scene runs through it),
// and a square grid through the centre, level in the viewer's world (up is -y), three radii across.
void MeshLayer::build_geometry(const Bounds& bounds) {
  const float c[3] = {float(bounds.center[0]), float(bounds.center[1]), float(bounds.center[2])};
  const float h = float(std::max(bounds.radius, 1e-3) / 3.0);
  std::vector<Vertex> vertices;
  // Faces by the axis they face (+x, -x, +y, -y, +z, -z), two triangles each.
  for (int face = 0; face < 6; ++face) {
    const int axis = face / 2;
    const float sign = face % 2 == 0 ? 1.0f : -1.0f;
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    Vertex quad[4];
    for (int k = 0; k < 4; ++k) {
      float p[3];
      p[axis] = c[axis] + sign * h;
      p[u] = c[u] + corners[k][0] * h;
      p[v] = c[v] + corners[k][1] * h;
      quad[k] = {{p[0], p[1], p[2]}, {kBoxColours[face][0], kBoxColours[face][1], kBoxColours[face][2]}};
    }
    for (int k : {0, 1, 2, 0, 2, 3}) vertices.push_back(quad[k]);
  }
  box_vertices_ = uint32_t(vertices.size());
  const float extent = 9.0f * h;  // 1.5 radii each side
  for (int i = 0; i < kGridLines; ++i) {
    const float t = -extent + 2.0f * extent * float(i) / float(kGridLines - 1);
    const Vertex ends[4] = {
        {{c[0] + t, c[1], c[2] - extent}, {kGridColour[0], kGridColour[1], kGridColour[2]}},
        {{c[0] + t, c[1], c[2] + extent}, {kGridColour[0], kGridColour[1], kGridColour[2]}},
        {{c[0] - extent, c[1], c[2] + t}, {kGridColour[0], kGridColour[1], kGridColour[2]}},
        {{c[0] + extent, c[1], c[2] + t}, {kGridColour[0], kGridColour[1], kGridColour[2]}}};
    vertices.insert(vertices.end(), ends, ends + 4);
  }
  grid_vertices_ = uint32_t(vertices.size()) - box_vertices_;

  // Host-visible (Upload), so the vertices are written where the device reads them.
  const VkDeviceSize bytes = vertices.size() * sizeof(Vertex);
  vertices_ = vk::Buffer(device_.context(), bytes, vk::MemoryUse::Upload, "the mesh's vertices",
                         VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  std::memcpy(vertices_.mapped(), vertices.data(), bytes);
}

void MeshLayer::create_render_passes() {
  // The box's pass clears both; the second keeps them. The depth is handed to render_to_image (and
  // back) in DEPTH_STENCIL_ATTACHMENT_OPTIMAL, where the host keeps it.
  for (const bool first : {true, false}) {
    VkAttachmentDescription attachments[2]{};
    attachments[0].format = kPictureFormat;
    attachments[0].samples = VK_SAMPLE_COUNT_1_BIT;
    attachments[0].loadOp = first ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
    attachments[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    attachments[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    attachments[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    attachments[0].initialLayout =
        first ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    attachments[0].finalLayout = first ? VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL : kPictureLayout;
    attachments[1] = attachments[0];
    attachments[1].format = kDepthFormat;
    attachments[1].initialLayout =
        first ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    attachments[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    const VkAttachmentReference colour{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    const VkAttachmentReference depth{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkSubpassDescription subpass{};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    subpass.colorAttachmentCount = 1;
    subpass.pColorAttachments = &colour;
    subpass.pDepthStencilAttachment = &depth;
    // Everything before (the renderer's transfers into the depth buffer, the last blit's reads of the
    // picture) before the pass; the pass's writes before everything after.
    VkSubpassDependency dependencies[2]{};
    dependencies[0].srcSubpass = VK_SUBPASS_EXTERNAL;
    dependencies[0].dstSubpass = 0;
    dependencies[0].srcStageMask = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    dependencies[0].dstStageMask = VK_PIPELINE_STAGE_ALL_GRAPHICS_BIT;
    dependencies[0].srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    dependencies[0].dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    dependencies[1].srcSubpass = 0;
    dependencies[1].dstSubpass = VK_SUBPASS_EXTERNAL;
    dependencies[1].srcStageMask = VK_PIPELINE_STAGE_ALL_GRAPHICS_BIT;
    dependencies[1].dstStageMask = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    dependencies[1].srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    dependencies[1].dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    info.attachmentCount = 2;
    info.pAttachments = attachments;
    info.subpassCount = 1;
    info.pSubpasses = &subpass;
    info.dependencyCount = 2;
    info.pDependencies = dependencies;
    vk::check(vkCreateRenderPass(vk_, &info, nullptr, (first ? box_pass_ : over_pass_).receive(vk_)),
              "vkCreateRenderPass");
  }
  const VkImageView views[] = {picture_.view(), depth_.view()};
  VkFramebufferCreateInfo framebuffer{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  framebuffer.renderPass = box_pass_.get();  // compatible with over_pass_: same formats, one subpass
  framebuffer.attachmentCount = 2;
  framebuffer.pAttachments = views;
  framebuffer.width = width_;
  framebuffer.height = height_;
  framebuffer.layers = 1;
  vk::check(vkCreateFramebuffer(vk_, &framebuffer, nullptr, framebuffer_.receive(vk_)),
            "vkCreateFramebuffer");
}

vk::UniquePipeline MeshLayer::make_pipeline(VkShaderModule vertex, VkShaderModule fragment,
                                            VkPrimitiveTopology topology, bool mesh, VkRenderPass pass) {
  VkPipelineShaderStageCreateInfo stages[2]{};
  stages[0].sType = stages[1].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = vertex;
  stages[0].pName = "main";
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = fragment;
  stages[1].pName = "main";
  const VkVertexInputBindingDescription binding{0, sizeof(Vertex), VK_VERTEX_INPUT_RATE_VERTEX};
  const VkVertexInputAttributeDescription attributes[2] = {
      {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
      {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, colour)}};
  VkPipelineVertexInputStateCreateInfo input{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  if (mesh) {
    input.vertexBindingDescriptionCount = 1;
    input.pVertexBindingDescriptions = &binding;
    input.vertexAttributeDescriptionCount = 2;
    input.pVertexAttributeDescriptions = attributes;
  }
  VkPipelineInputAssemblyStateCreateInfo assembly{
      VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  assembly.topology = topology;
  const VkViewport viewport{0, 0, float(width_), float(height_), 0, 1};
  const VkRect2D scissor{{0, 0}, {width_, height_}};
  VkPipelineViewportStateCreateInfo viewport_state{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  viewport_state.viewportCount = 1;
  viewport_state.pViewports = &viewport;
  viewport_state.scissorCount = 1;
  viewport_state.pScissors = &scissor;
  VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = VK_CULL_MODE_NONE;
  raster.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo multisample{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo depth{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  depth.depthTestEnable = mesh ? VK_TRUE : VK_FALSE;
  depth.depthWriteEnable = mesh ? VK_TRUE : VK_FALSE;
  depth.depthCompareOp = VK_COMPARE_OP_LESS;
  VkPipelineColorBlendAttachmentState blend{};
  blend.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT |
                         VK_COLOR_COMPONENT_A_BIT;
  if (!mesh) {  // premultiplied "over": src + (1 - src.a) * dst, colour and alpha alike
    blend.blendEnable = VK_TRUE;
    blend.srcColorBlendFactor = blend.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    blend.dstColorBlendFactor = blend.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    blend.colorBlendOp = blend.alphaBlendOp = VK_BLEND_OP_ADD;
  }
  VkPipelineColorBlendStateCreateInfo blend_state{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  blend_state.attachmentCount = 1;
  blend_state.pAttachments = &blend;
  VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  info.stageCount = 2;
  info.pStages = stages;
  info.pVertexInputState = &input;
  info.pInputAssemblyState = &assembly;
  info.pViewportState = &viewport_state;
  info.pRasterizationState = &raster;
  info.pMultisampleState = &multisample;
  info.pDepthStencilState = &depth;
  info.pColorBlendState = &blend_state;
  info.layout = (mesh ? mesh_layout_ : over_layout_).get();
  info.renderPass = pass;
  vk::UniquePipeline pipeline;
  vk::check(vkCreateGraphicsPipelines(vk_, VK_NULL_HANDLE, 1, &info, nullptr, pipeline.receive(vk_)),
            "vkCreateGraphicsPipelines");
  return pipeline;
}

void MeshLayer::create_pipelines() {
  VkSamplerCreateInfo sampler{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  sampler.magFilter = sampler.minFilter = VK_FILTER_NEAREST;
  sampler.addressModeU = sampler.addressModeV = sampler.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  vk::check(vkCreateSampler(vk_, &sampler, nullptr, sampler_.receive(vk_)), "vkCreateSampler");
  VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1,
                                       VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo set_layout{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_layout.bindingCount = 1;
  set_layout.pBindings = &binding;
  vk::check(vkCreateDescriptorSetLayout(vk_, &set_layout, nullptr, set_layout_.receive(vk_)),
            "vkCreateDescriptorSetLayout");
  const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1};
  VkDescriptorPoolCreateInfo pool{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool.maxSets = 1;
  pool.poolSizeCount = 1;
  pool.pPoolSizes = &size;
  vk::check(vkCreateDescriptorPool(vk_, &pool, nullptr, descriptor_pool_.receive(vk_)),
            "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo allocate{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  allocate.descriptorPool = descriptor_pool_.get();
  allocate.descriptorSetCount = 1;
  allocate.pSetLayouts = set_layout_.address();
  vk::check(vkAllocateDescriptorSets(vk_, &allocate, &splats_set_), "vkAllocateDescriptorSets");
  const VkDescriptorImageInfo image{sampler_.get(), splats_.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  write.dstSet = splats_set_;
  write.descriptorCount = 1;
  write.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  write.pImageInfo = &image;
  vkUpdateDescriptorSets(vk_, 1, &write, 0, nullptr);

  const VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT, 0, 16 * sizeof(float)};
  VkPipelineLayoutCreateInfo layout{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout.pushConstantRangeCount = 1;
  layout.pPushConstantRanges = &push;
  vk::check(vkCreatePipelineLayout(vk_, &layout, nullptr, mesh_layout_.receive(vk_)),
            "vkCreatePipelineLayout");
  layout = {VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout.setLayoutCount = 1;
  layout.pSetLayouts = set_layout_.address();
  vk::check(vkCreatePipelineLayout(vk_, &layout, nullptr, over_layout_.receive(vk_)),
            "vkCreatePipelineLayout");

  // The modules are needed only while the pipelines are made.
  const vk::UniqueShaderModule transform = make_module(vk_, "mesh_transform");
  const vk::UniqueShaderModule flat = make_module(vk_, "flat_colour");
  const vk::UniqueShaderModule fullscreen = make_module(vk_, "fullscreen_triangle");
  const vk::UniqueShaderModule over = make_module(vk_, "splats_over");
  box_pipeline_ =
      make_pipeline(transform.get(), flat.get(), VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST, true, box_pass_.get());
  grid_pipeline_ =
      make_pipeline(transform.get(), flat.get(), VK_PRIMITIVE_TOPOLOGY_LINE_LIST, true, over_pass_.get());
  over_pipeline_ = make_pipeline(fullscreen.get(), over.get(), VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST, false,
                                 over_pass_.get());
}

std::array<double, 16> MeshLayer::view_matrix(const Camera& camera) {
  // x_cam = R (x - p): column-major [R | -R p].
  const auto& r = camera.rotation;
  const auto& p = camera.position;
  std::array<double, 16> m{};
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) m[size_t(col * 4 + row)] = r[size_t(row * 3 + col)];
    m[size_t(12 + row)] =
        -(r[size_t(row * 3)] * p[0] + r[size_t(row * 3 + 1)] * p[1] + r[size_t(row * 3 + 2)] * p[2]);
  }
  m[15] = 1;
  return m;
}

std::array<double, 16> MeshLayer::projection(const Camera& camera) const {
  // The camera looks down +z (OpenCV axes) and Vulkan's NDC y runs down the image, as its rows do:
  // clip = (2 fx / W x + (2 cx / W - 1) z, 2 fy / H y + (2 cy / H - 1) z, A z + B, z), with window depth
  // A + B / z = 0 at the near plane and 1 at the far one.
  const double w = camera.width, h = camera.height;
  std::array<double, 16> m{};
  m[0] = 2 * camera.fx / w;
  m[8] = 2 * camera.cx / w - 1;
  m[5] = 2 * camera.fy / h;
  m[9] = 2 * camera.cy / h - 1;
  m[10] = far_ / (far_ - near_);
  m[14] = -far_ * near_ / (far_ - near_);
  m[11] = 1;
  return m;
}

void MeshLayer::begin(VkCommandBuffer cmd) {
  vk::check(vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vk::check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
}

void MeshLayer::wait_for(VkFence fence, bool& pending) {
  if (!pending) return;
  vk::check(vkWaitForFences(vk_, 1, &fence, VK_TRUE, std::numeric_limits<uint64_t>::max()),
            "vkWaitForFences");
  pending = false;
}

void MeshLayer::submit(VkCommandBuffer cmd, VkSemaphore wait, VkSemaphore signal, VkFence fence) {
  vk::check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  if (fence) vk::check(vkResetFences(vk_, 1, &fence), "vkResetFences");
  const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
  VkSubmitInfo info{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  info.waitSemaphoreCount = wait ? 1 : 0;
  info.pWaitSemaphores = &wait;
  info.pWaitDstStageMask = &wait_stage;
  info.commandBufferCount = 1;
  info.pCommandBuffers = &cmd;
  info.signalSemaphoreCount = signal ? 1 : 0;
  info.pSignalSemaphores = &signal;
  vk::check(vkQueueSubmit(device_.queue(), 1, &info, fence), "vkQueueSubmit (mesh)");
}

bool MeshLayer::depth_testable(const RenderSettings& settings) {
  return settings.compositor != Compositor::kStochastic && settings.accuracy.resort_window == 0;
}

bool MeshLayer::writes_depth_out(const RenderSettings& settings) const {
  return depth_testable(settings) && (settings.compositor != Compositor::kRaster ||
                                      (device_.external().independent_blend_enabled &&
                                       device_.external().rasterization_order_attachment_access_enabled));
}

void MeshLayer::draw(Renderer& renderer, const Camera& camera, const RenderSettings& settings,
                     bool depth_out) {
  if (uint32_t(camera.width) != width_ || uint32_t(camera.height) != height_)
    throw std::logic_error("MeshLayer::draw: the camera is not the layer's size");
  // Per-pixel re-sorting and the stochastic compositor cannot depth-test against a host's surfaces: in
  // those modes the splats are drawn over the background alone, without the mesh.
  const bool mesh = depth_testable(settings);
  // The previous frame's command buffers are free again (the renderer waits for its own frame).
  wait_for(box_fence_.get(), box_pending_);
  wait_for(grid_fence_.get(), grid_pending_);
  const std::array<double, 16> projection_matrix = projection(camera);
  const std::array<double, 16> view = view_matrix(camera);
  float clip_from_world[16];
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) {
      double sum = 0;
      for (int k = 0; k < 4; ++k) sum += projection_matrix[size_t(k * 4 + row)] * view[size_t(col * 4 + k)];
      clip_from_world[col * 4 + row] = float(sum);
    }
  const VkDeviceSize offset = 0;
  VkRenderPassBeginInfo pass{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  pass.framebuffer = framebuffer_.get();
  pass.renderArea = {{0, 0}, {width_, height_}};

  // 1. The box, into a cleared picture (the scene's background) and depth buffer.
  begin(box_commands_);
  VkClearValue clears[2];
  clears[0].color = {{settings.background[0], settings.background[1], settings.background[2], 1.0f}};
  clears[1].depthStencil = {1.0f, 0};
  pass.renderPass = box_pass_.get();
  pass.clearValueCount = 2;
  pass.pClearValues = clears;
  vkCmdBeginRenderPass(box_commands_, &pass, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdBindPipeline(box_commands_, VK_PIPELINE_BIND_POINT_GRAPHICS, box_pipeline_.get());
  vkCmdPushConstants(box_commands_, mesh_layout_.get(), VK_SHADER_STAGE_VERTEX_BIT, 0,
                     sizeof(clip_from_world), clip_from_world);
  const VkBuffer vertex_buffer = vertices_.handle();
  vkCmdBindVertexBuffers(box_commands_, 0, 1, &vertex_buffer, &offset);
  if (mesh) vkCmdDraw(box_commands_, box_vertices_, 1, 0, 0);
  vkCmdEndRenderPass(box_commands_);
  submit(box_commands_, VK_NULL_HANDLE, box_drawn_.get(), box_fence_.get());
  box_pending_ = true;

  // 2. The splats, cut by the box's depth and writing theirs where they reach alpha 0.5, over black
  // (the background is the picture's), submitted between the box and the grid without waiting.
  RenderSettings splat_settings = settings;
  splat_settings.background = {0, 0, 0};
  if (mesh)
    splat_settings.host = HostDepth{DepthConvention::from_projection(projection_matrix),
                                    {},
                                    depth_out && writes_depth_out(settings),
                                    0.5f};
  const ExternalImage target{splats_.handle(), width_, height_, kSplatFormat, VK_IMAGE_LAYOUT_UNDEFINED};
  const ExternalDepthImage depth{depth_.handle(), width_, height_, kDepthFormat,
                                 VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  const VkSemaphore waits[] = {box_drawn_.get()};
  const VkSemaphore signals[] = {splats_drawn_.get()};
  try {
    render_to_image(renderer, camera, splat_settings, target, mesh ? &depth : nullptr,
                    HostFrameSync{waits, {}, {}, signals, {}});
  } catch (...) {
    // Nothing will wait for the box's semaphore now: an empty batch does, so that the next frame may
    // signal it again.
    const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    VkSubmitInfo consume{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    consume.waitSemaphoreCount = 1;
    consume.pWaitSemaphores = box_drawn_.address();
    consume.pWaitDstStageMask = &stage;
    vkQueueSubmit(device_.queue(), 1, &consume, VK_NULL_HANDLE);
    throw;
  }

  // 3. The splats over the box (premultiplied), then the grid, depth-tested against the splats' depth.
  begin(grid_commands_);
  // From GENERAL, where render_to_image leaves an image handed over UNDEFINED.
  vk::transition(grid_commands_, {splats_.handle(), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                                  VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_MEMORY_WRITE_BIT,
                                  VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                                  VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT});
  pass.renderPass = over_pass_.get();
  pass.clearValueCount = 0;
  pass.pClearValues = nullptr;
  vkCmdBeginRenderPass(grid_commands_, &pass, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdBindPipeline(grid_commands_, VK_PIPELINE_BIND_POINT_GRAPHICS, over_pipeline_.get());
  vkCmdBindDescriptorSets(grid_commands_, VK_PIPELINE_BIND_POINT_GRAPHICS, over_layout_.get(), 0, 1,
                          &splats_set_, 0, nullptr);
  vkCmdDraw(grid_commands_, 3, 1, 0, 0);
  vkCmdBindPipeline(grid_commands_, VK_PIPELINE_BIND_POINT_GRAPHICS, grid_pipeline_.get());
  vkCmdPushConstants(grid_commands_, mesh_layout_.get(), VK_SHADER_STAGE_VERTEX_BIT, 0,
                     sizeof(clip_from_world), clip_from_world);
  vkCmdBindVertexBuffers(grid_commands_, 0, 1, &vertex_buffer, &offset);
  if (mesh) vkCmdDraw(grid_commands_, grid_vertices_, 1, box_vertices_, 0);
  vkCmdEndRenderPass(grid_commands_);
  submit(grid_commands_, splats_drawn_.get(), VK_NULL_HANDLE, grid_fence_.get());
  grid_pending_ = true;
}

}  // namespace tilesplat::viewer
