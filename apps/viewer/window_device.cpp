#include "window_device.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "vulkan/device_selection.h"

namespace tilesplat::viewer {

namespace {

// Why `device` cannot run the renderer and present to `surface`, or "" when it can; then `family`
// is a queue family that computes, has timestamps (the renderer times its passes) and presents.
std::string why_unsuitable(VkPhysicalDevice device, VkSurfaceKHR surface, uint32_t& family) {
  VkPhysicalDeviceProperties properties;
  vkGetPhysicalDeviceProperties(device, &properties);
  if (properties.apiVersion < VK_API_VERSION_1_2) return "Vulkan 1.2 is required";
  VkPhysicalDeviceVulkan12Features has12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceFeatures2 has{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  has.pNext = &has12;
  vkGetPhysicalDeviceFeatures2(device, &has);
  if (!has12.bufferDeviceAddress || !has.features.shaderInt64) return "no bufferDeviceAddress or shaderInt64";

  uint32_t count = 0;
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
  if (std::none_of(extensions.begin(), extensions.end(), [](const VkExtensionProperties& e) {
        return std::strcmp(e.extensionName, VK_KHR_SWAPCHAIN_EXTENSION_NAME) == 0;
      }))
    return "no VK_KHR_swapchain";

  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  for (family = 0; family < count; ++family) {
    VkBool32 presents = VK_FALSE;
    vkGetPhysicalDeviceSurfaceSupportKHR(device, family, surface, &presents);
    if ((families[family].queueFlags & VK_QUEUE_COMPUTE_BIT) && families[family].timestampValidBits > 0 && presents)
      return "";
  }
  return "no queue family both computes and presents to the window";
}

}  // namespace

// A constructor that throws runs no destructor of its own, but its members' do: whatever was made so far
// releases itself.
WindowDevice::WindowDevice(GLFWwindow* window, bool validation, const std::string& device_selector) {
  create_instance(validation);
  vk::check(glfwCreateWindowSurface(instance_.get(), window, nullptr, surface_.receive(instance_.get())),
            "creating the window's Vulkan surface");
  pick_physical_device(device_selector);
  create_device();
  context_ = std::make_unique<vk::Context>(external());
}

WindowDevice::~WindowDevice() {
  if (device_) vkDeviceWaitIdle(device_.get());
}

ExternalVulkanDevice WindowDevice::external() const {
  return {instance_.get(), physical_device_, device_.get(),      queue_,
          queue_family_,   shader_float64_,  independent_blend_, rasterization_order_};
}

std::string WindowDevice::name() const {
  return vk::physical_device_name(physical_device_);
}

void WindowDevice::create_instance(bool validation) {
  uint32_t glfw_count = 0;
  const char** glfw_extensions = glfwGetRequiredInstanceExtensions(&glfw_count);
  if (!glfw_extensions)
    throw std::runtime_error("Vulkan cannot present to this window system (no surface extensions)");
  instance_ = vk::UniqueInstance(
      vk::create_bare_instance(validation, std::span(glfw_extensions, glfw_count), "tilesplat-viewer"));
  if (validation) messenger_.emplace(instance_.get(), &WindowDevice::on_validation_message, this);
}

VKAPI_ATTR VkBool32 VKAPI_CALL WindowDevice::on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                                   const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                                   void* user) {
  static_cast<WindowDevice*>(user)->validation_messages_.fetch_add(1);
  const char* level = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
  std::fprintf(stderr, "tilesplat-viewer: vulkan validation %s: %s\n", level, data->pMessage);
  return VK_FALSE;
}

// The selector means what --device means to the other apps (an index in the loader's order, a UUID, or
// part of the name), but the device must also present to this window, which a headless renderer never asks.
void WindowDevice::pick_physical_device(const std::string& device_selector) {
  std::string selector = device_selector;
  if (selector.empty())
    if (const char* env = std::getenv("TILESPLAT_DEVICE")) selector = env;
  const VkSurfaceKHR surface = surface_.get();
  physical_device_ = vk::select_physical_device(
      instance_.get(), selector,
      [surface](VkPhysicalDevice device) {
        uint32_t family = 0;
        return why_unsuitable(device, surface, family);
      },
      "render to the window");
  why_unsuitable(physical_device_, surface, queue_family_);  // "": the family that computes and presents
}

void WindowDevice::create_device() {
  VkPhysicalDeviceFeatures2 has{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  vkGetPhysicalDeviceFeatures2(physical_device_, &has);
  // shaderFloat64 makes the projection's geometry exact (vulkan_interop.h); it is optional.
  shader_float64_ = has.features.shaderFloat64 == VK_TRUE;
  // independentBlend lets the raster compositor count splats where it blends colours (a screenshot's
  // EXR has the counts); optional too.
  independent_blend_ = has.features.independentBlend == VK_TRUE;

  VkPhysicalDeviceVulkan12Features want12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  want12.bufferDeviceAddress = VK_TRUE;
  VkPhysicalDeviceFeatures2 want{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  want.pNext = &want12;
  want.features.shaderInt64 = VK_TRUE;
  want.features.shaderFloat64 = shader_float64_ ? VK_TRUE : VK_FALSE;
  want.features.independentBlend = independent_blend_ ? VK_TRUE : VK_FALSE;

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue_info.queueFamilyIndex = queue_family_;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;
  std::vector<const char*> extensions = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
  // Rasterization-order attachment access lets the raster compositor write the splats' depth out for
  // the mesh drawn after them; optional too.
  uint32_t extension_count = 0;
  vkEnumerateDeviceExtensionProperties(physical_device_, nullptr, &extension_count, nullptr);
  std::vector<VkExtensionProperties> available(extension_count);
  vkEnumerateDeviceExtensionProperties(physical_device_, nullptr, &extension_count, available.data());
  VkPhysicalDeviceRasterizationOrderAttachmentAccessFeaturesEXT order{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RASTERIZATION_ORDER_ATTACHMENT_ACCESS_FEATURES_EXT};
  for (const VkExtensionProperties& e : available)
    if (std::string_view(e.extensionName) == VK_EXT_RASTERIZATION_ORDER_ATTACHMENT_ACCESS_EXTENSION_NAME) {
      VkPhysicalDeviceFeatures2 has_order{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
      has_order.pNext = &order;
      vkGetPhysicalDeviceFeatures2(physical_device_, &has_order);
      rasterization_order_ = order.rasterizationOrderColorAttachmentAccess == VK_TRUE;
    }
  if (rasterization_order_) {
    extensions.push_back(VK_EXT_RASTERIZATION_ORDER_ATTACHMENT_ACCESS_EXTENSION_NAME);
    order = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RASTERIZATION_ORDER_ATTACHMENT_ACCESS_FEATURES_EXT};
    order.rasterizationOrderColorAttachmentAccess = VK_TRUE;
    want12.pNext = &order;
  }
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.pNext = &want;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue_info;
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  vk::check(vkCreateDevice(physical_device_, &info, nullptr, device_.receive()), "vkCreateDevice");
  vkGetDeviceQueue(device_.get(), queue_family_, 0, &queue_);
}

}  // namespace tilesplat::viewer
