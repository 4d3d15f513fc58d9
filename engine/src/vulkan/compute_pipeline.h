// A compute pipeline built from one embedded shader. Shaders take their inputs through push
// constants (buffer device addresses and scalars). The CPU-driver layouts of a few passes also read
// and write texel buffers (see texel_buffers_wanted): those views go in with push descriptors, set 0
// binding i, so there are still no descriptor sets to manage.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>
#include <vector>

#include "vulkan/context.h"

namespace tilesplat::vk {

struct SpecConstant {
  uint32_t id;
  uint32_t value;
};

class ComputePipeline {
 public:
  ComputePipeline() = default;
  // texel_bindings: the descriptor type of set 0 binding i (VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER or
  // _STORAGE_TEXEL_BUFFER); needs Context::features().push_descriptor.
  ComputePipeline(Context& ctx, const std::string& shader, uint32_t push_constant_bytes,
                  const std::vector<SpecConstant>& spec = {},
                  const std::vector<VkDescriptorType>& texel_bindings = {});
  ~ComputePipeline() { reset(); }
  ComputePipeline(ComputePipeline&& other) noexcept { *this = std::move(other); }
  ComputePipeline& operator=(ComputePipeline&& other) noexcept;
  ComputePipeline(const ComputePipeline&) = delete;
  ComputePipeline& operator=(const ComputePipeline&) = delete;
  void reset();

  template <typename PushConstants>
  void bind(VkCommandBuffer cmd, const PushConstants& pc) const {
    static_assert(sizeof(PushConstants) <= 128, "push constants beyond the portable 128-byte minimum");
    bind_raw(cmd, &pc, uint32_t(sizeof(PushConstants)));
  }
  void bind_raw(VkCommandBuffer cmd, const void* data, uint32_t size) const;
  void dispatch(VkCommandBuffer cmd, uint32_t groups_x, uint32_t groups_y = 1, uint32_t groups_z = 1) const;
  void dispatch_indirect(VkCommandBuffer cmd, VkBuffer args, VkDeviceSize offset) const;
  // Points binding i at views[i], one view per texel binding; after bind().
  void push_texel_views(VkCommandBuffer cmd, const std::vector<VkBufferView>& views) const;

 private:
  Context* ctx_ = nullptr;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  std::vector<VkDescriptorType> texel_bindings_;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  uint32_t push_constant_bytes_ = 0;
  std::string name_;
};

// Makes every earlier compute/transfer write visible to every later compute/transfer/indirect read.
// The passes form a strict chain, so one full barrier between them is both correct and cheap.
void barrier(VkCommandBuffer cmd);

// Whether the CPU-driver layouts read and write through texel buffers: llvmpipe before Mesa 25 turns
// a load or store at a per-invocation buffer address into a loop over the SIMD lanes, one per
// component, while texel fetches and image stores are SIMD gathers and scatters (docs/benchmarks.md,
// "Where the time goes on the CPU driver"). Mesa 25's llvmpipe compiles those accesses well, and there
// the address layouts are faster (1080p 500k frame 318 against 374 ms; "Mesa 22 against Mesa 25").
// So: a CPU device with push descriptors, unless it is Mesa 25 or later; TILESPLAT_TEXEL_BUFFERS=0 or 1
// overrides it, so that the tests hold both layouts to the same images.
bool texel_buffers_wanted(const Context& ctx);
// The Mesa major version in a driver description ("llvmpipe Mesa 25.0.7 (LLVM 15.0.6)" -> 25), 0 when
// it names none.
int mesa_major_version(const std::string& driver_name);

// A pass's texel views, all of them or none: empty when any is VK_NULL_HANDLE (a buffer with more texels
// than the device allows, Buffer::texel_view), and the pass then takes its address variant.
std::vector<VkBufferView> complete_views(std::vector<VkBufferView> views);

inline uint32_t div_ceil(uint64_t a, uint64_t b) { return uint32_t((a + b - 1) / b); }

}  // namespace tilesplat::vk
