// A compute pipeline built from one embedded shader. Shaders take all their inputs through push
// constants (buffer device addresses and scalars), so there are no descriptor sets to manage.
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
  ComputePipeline(Context& ctx, const std::string& shader, uint32_t push_constant_bytes,
                  const std::vector<SpecConstant>& spec = {});
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

 private:
  Context* ctx_ = nullptr;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  uint32_t push_constant_bytes_ = 0;
  std::string name_;
};

// Makes every earlier compute/transfer write visible to every later compute/transfer/indirect read.
// The passes form a strict chain, so one full barrier between them is both correct and cheap.
void barrier(VkCommandBuffer cmd);

inline uint32_t div_ceil(uint64_t a, uint64_t b) { return uint32_t((a + b - 1) / b); }

}  // namespace tilesplat::vk
