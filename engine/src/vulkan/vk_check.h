// Turns a failed Vulkan call into an exception that says which call failed and why.
#pragma once

#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>

namespace tilesplat::vk {

const char* result_name(VkResult result);

class VulkanError : public std::runtime_error {
 public:
  VulkanError(const char* call, VkResult result)
      : std::runtime_error(std::string(call) + " failed: " + result_name(result)), result_(result) {}
  VkResult result() const { return result_; }

 private:
  VkResult result_;
};

// Throws VulkanError naming `what` ("vkCreateFence", or a call with its purpose) unless `result` is
// VK_SUCCESS: for calls whose text alone would not say which of several failed.
inline void check(VkResult result, const char* what) {
  if (result != VK_SUCCESS) throw VulkanError(what, result);
}

}  // namespace tilesplat::vk

#define TS_VK_CHECK(call)                                                  \
  do {                                                                     \
    VkResult ts_vk_result_ = (call);                                       \
    if (ts_vk_result_ != VK_SUCCESS) throw ::tilesplat::vk::VulkanError(#call, ts_vk_result_); \
  } while (0)
