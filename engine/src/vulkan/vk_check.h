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

}  // namespace tilesplat::vk

#define TS_VK_CHECK(call)                                                  \
  do {                                                                     \
    VkResult ts_vk_result_ = (call);                                       \
    if (ts_vk_result_ != VK_SUCCESS) throw ::tilesplat::vk::VulkanError(#call, ts_vk_result_); \
  } while (0)
