// The viewer's Vulkan device: an instance with the extensions GLFW needs to present, the window's
// surface, and a device with one queue that both runs the renderer's compute work and presents.
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "tilesplat/vulkan_interop.h"
#include "vulkan/context.h"
#include "vulkan/handle.h"

struct GLFWwindow;

namespace tilesplat::viewer {

class WindowDevice {
 public:
  // validation: VK_LAYER_KHRONOS_validation with a messenger that prints and counts its messages,
  // the renderer's included (it borrows this instance). device_selector: as --device, a device
  // index or part of its name; empty = the first discrete GPU that can present, else any device
  // that can. Throws std::runtime_error saying why no device fits.
  WindowDevice(GLFWwindow* window, bool validation, const std::string& device_selector);
  // Waits for the device to be idle; the handles then release themselves, the device's last.
  ~WindowDevice();
  WindowDevice(const WindowDevice&) = delete;
  WindowDevice& operator=(const WindowDevice&) = delete;

  // What create_renderer borrows; the handles outlive the renderer.
  ExternalVulkanDevice external() const;

  VkPhysicalDevice physical_device() const { return physical_device_; }
  VkDevice device() const { return device_.get(); }
  VkQueue queue() const { return queue_; }
  uint32_t queue_family() const { return queue_family_; }
  VkSurfaceKHR surface() const { return surface_.get(); }
  std::string name() const;
  // The engine's Vulkan layer on this device (borrowed, as the renderer's is): the viewer's images and
  // buffers, memory types and one-time submissions go through it.
  vk::Context& context() const { return *context_; }

  bool validation() const { return messenger_.has_value(); }
  uint64_t validation_messages() const { return validation_messages_.load(); }

 private:
  void create_instance(bool validation);
  void pick_physical_device(const std::string& selector);
  void create_device();

  static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                              VkDebugUtilsMessageTypeFlagsEXT types,
                                                              const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                              void* user);

  // Declared in the order they are made: they are destroyed in the reverse one.
  std::atomic<uint64_t> validation_messages_{0};
  vk::UniqueInstance instance_;
  std::optional<vk::DebugMessenger> messenger_;  // with validation only
  vk::UniqueSurface surface_;
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  vk::UniqueDevice device_;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  bool shader_float64_ = false;
  bool independent_blend_ = false;
  bool rasterization_order_ = false;  // VK_EXT_rasterization_order_attachment_access, enabled
  std::unique_ptr<vk::Context> context_;
};

}  // namespace tilesplat::viewer
