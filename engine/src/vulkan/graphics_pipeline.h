// A graphics pipeline of two embedded shaders (a vertex or mesh stage and a fragment stage) drawing into
// colour attachments, with the render pass it draws in: the raster compositor's. Like ComputePipeline, the
// shaders take everything through push constants (buffer device addresses and scalars) and draw no
// vertex buffers; a fragment stage that reads a colour attachment in rasterization order also takes it as
// an input attachment (set 0, binding 0). The render pass clears its attachments and leaves them ready to
// be copied out.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "vulkan/compute_pipeline.h"
#include "vulkan/context.h"

namespace tilesplat::vk {

// How a fragment's output meets what the attachment holds.
enum class Blend {
  kUnder,  // front to back: dst += src * (1 - dst alpha), the attachment's alpha being 1 - T
  kAdd,    // dst += src
  kMin,    // dst = min(dst, src)
};

// A colour attachment at the fragment output location of its index; an unused one keeps its
// location (the fragment stage's writes there go nowhere) and has no image.
struct ColourAttachment {
  VkFormat format = VK_FORMAT_UNDEFINED;
  Blend blend = Blend::kUnder;
  bool used = true;
};

// A depth attachment the draw tests against and never writes: its contents come in by a transfer
// (TRANSFER_DST_OPTIMAL when the render pass begins) and are not kept.
struct DepthTest {
  VkFormat format = VK_FORMAT_D32_SFLOAT;
  VkCompareOp compare = VK_COMPARE_OP_LESS;
};

struct GraphicsPipelineDesc {
  std::string vertex_shader;
  std::string mesh_shader;  // instead of the vertex stage (VK_EXT_mesh_shader): drawn with mesh tasks
  std::string fragment_shader;
  uint32_t push_constant_bytes = 0;  // seen by both stages
  std::vector<SpecConstant> spec;    // given to both stages (each uses the ids it declares)
  std::vector<ColourAttachment> attachments;
  std::optional<DepthTest> depth_test;  // after the used colour attachments in a framebuffer
  // The colour attachment (an index into `attachments`) that the fragment stage also reads, as the
  // subpassInput at set 0, binding 0, input_attachment_index 0: what the earlier fragments at its pixel
  // left there, in rasterization order (VK_EXT_rasterization_order_attachment_access, no barriers).
  std::optional<uint32_t> input_attachment;
  VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP;
};

class GraphicsPipeline {
 public:
  GraphicsPipeline() = default;
  GraphicsPipeline(Context& ctx, const GraphicsPipelineDesc& desc);
  ~GraphicsPipeline() { reset(); }
  GraphicsPipeline(GraphicsPipeline&& other) noexcept { *this = std::move(other); }
  GraphicsPipeline& operator=(GraphicsPipeline&& other) noexcept;
  GraphicsPipeline(const GraphicsPipeline&) = delete;
  GraphicsPipeline& operator=(const GraphicsPipeline&) = delete;
  void reset();

  // Clears the used colour attachments to zero; they end in TRANSFER_SRC_OPTIMAL, their writes visible
  // to transfers. A framebuffer for it holds the used colour attachments' views in order, then the
  // depth attachment's.
  VkRenderPass render_pass() const { return render_pass_; }
  // Binds the pipeline, its push constants and a viewport and scissor of the whole framebuffer.
  template <typename PushConstants>
  void bind(VkCommandBuffer cmd, const PushConstants& pc, uint32_t width, uint32_t height) const {
    static_assert(sizeof(PushConstants) <= 128, "push constants beyond the portable 128-byte minimum");
    bind_raw(cmd, &pc, uint32_t(sizeof(PushConstants)), width, height);
  }
  void bind_raw(VkCommandBuffer cmd, const void* data, uint32_t size, uint32_t width, uint32_t height) const;
  // For a pipeline with an input attachment, after bind(): the view of the framebuffer's image for it.
  // A new view rewrites the pipeline's descriptor set, so no command buffer that bound the old one may
  // still be pending or recording.
  void bind_input_attachment(VkCommandBuffer cmd, VkImageView view);

 private:
  void create_render_pass(const GraphicsPipelineDesc& desc);
  void create_input_set();
  Context* ctx_ = nullptr;
  VkRenderPass render_pass_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  // The input attachment's descriptor set (set 0), when the fragment stage reads one.
  VkDescriptorSetLayout input_layout_ = VK_NULL_HANDLE;
  VkDescriptorPool input_pool_ = VK_NULL_HANDLE;
  VkDescriptorSet input_set_ = VK_NULL_HANDLE;
  VkImageView input_view_ = VK_NULL_HANDLE;  // what input_set_ holds
  VkShaderStageFlags stages_ = 0;  // the two stages, which see the push constants
  uint32_t push_constant_bytes_ = 0;
  std::string name_;
};

}  // namespace tilesplat::vk
