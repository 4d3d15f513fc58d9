// The viewer's Vulkan device: an instance with the extensions GLFW needs to present, the window's
// surface, and a device with one queue that both runs the renderer's compute work and presents.
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

#include "tilesplat/vulkan_interop.h"

struct GLFWwindow;

namespace tilesplat::viewer {

// Throws std::runtime_error "WHAT failed: VK_ERROR_..." unless the result is VK_SUCCESS.
void vk_check(VkResult result, const char* what);

class WindowDevice {
 public:
  // validation: VK_LAYER_KHRONOS_validation with a messenger that prints and counts its messages,
  // the renderer's included (it borrows this instance). device_selector: as --device, a device
  // index or part of its name; empty = the first discrete GPU that can present, else any device
  // that can. Throws std::runtime_error saying why no device fits.
  WindowDevice(GLFWwindow* window, bool validation, const std::string& device_selector);
  ~WindowDevice();
  WindowDevice(const WindowDevice&) = delete;
  WindowDevice& operator=(const WindowDevice&) = delete;

  // What create_renderer borrows; the handles outlive the renderer.
  ExternalVulkanDevice external() const;

  VkPhysicalDevice physical_device() const { return physical_device_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queue_family() const { return queue_family_; }
  VkSurfaceKHR surface() const { return surface_; }
  std::string name() const;

  // A memory type among `allowed` (VkMemoryRequirements::memoryTypeBits) with every `required` flag,
  // one that also has the `preferred` ones where there is one. Throws std::runtime_error naming `what`
  // when none has the required flags.
  uint32_t memory_type(uint32_t allowed, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred,
                       const char* what) const;
  // Records `record` into a one-time command buffer, submits it and waits for the queue to be idle.
  void submit_and_wait(const std::function<void(VkCommandBuffer)>& record) const;
  bool validation() const { return messenger_ != VK_NULL_HANDLE; }
  uint64_t validation_messages() const { return validation_messages_.load(); }

 private:
  void create_instance(bool validation);
  void pick_physical_device(const std::string& selector);
  void create_device();
  void destroy();

  static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                              VkDebugUtilsMessageTypeFlagsEXT types,
                                                              const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                              void* user);

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  bool shader_float64_ = false;
  bool independent_blend_ = false;
  bool rasterization_order_ = false;  // VK_EXT_rasterization_order_attachment_access, enabled
  std::atomic<uint64_t> validation_messages_{0};
};

}  // namespace tilesplat::viewer
