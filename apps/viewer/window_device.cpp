#include "window_device.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace tilesplat::viewer {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return text;
}

std::string device_name(VkPhysicalDevice device) {
  VkPhysicalDeviceProperties properties;
  vkGetPhysicalDeviceProperties(device, &properties);
  return properties.deviceName;
}

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

int type_rank(VkPhysicalDevice device) {
  VkPhysicalDeviceProperties properties;
  vkGetPhysicalDeviceProperties(device, &properties);
  switch (properties.deviceType) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    default: return 3;
  }
}

}  // namespace

DebugMessenger::DebugMessenger(VkInstance instance, const VkDebugUtilsMessengerCreateInfoEXT& info)
    : instance_(instance) {
  auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
  if (!create_messenger) throw std::runtime_error("vkCreateDebugUtilsMessengerEXT is unavailable");
  vk::check(create_messenger(instance, &info, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
}

DebugMessenger::~DebugMessenger() {
  auto destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
  if (destroy_messenger) destroy_messenger(instance_, messenger_, nullptr);
}

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

std::string WindowDevice::name() const { return device_name(physical_device_); }

void WindowDevice::create_instance(bool validation) {
  uint32_t glfw_count = 0;
  const char** glfw_extensions = glfwGetRequiredInstanceExtensions(&glfw_count);
  if (!glfw_extensions)
    throw std::runtime_error("Vulkan cannot present to this window system (no surface extensions)");
  std::vector<const char*> extensions(glfw_extensions, glfw_extensions + glfw_count);
  std::vector<const char*> layers;
  if (validation) {
    uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> available(count);
    vkEnumerateInstanceLayerProperties(&count, available.data());
    const auto is_validation = [](const VkLayerProperties& layer) {
      return std::strcmp(layer.layerName, kValidationLayer) == 0;
    };
    if (std::none_of(available.begin(), available.end(), is_validation))
      throw std::runtime_error(std::string("validation requested but ") + kValidationLayer +
                               " is not installed (Debian: vulkan-validationlayers)");
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "tilesplat-viewer";
  app.pEngineName = "tilesplat";
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  info.enabledLayerCount = uint32_t(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  vk::check(vkCreateInstance(&info, nullptr, instance_.receive()), "vkCreateInstance");
  if (!validation) return;

  VkDebugUtilsMessengerCreateInfoEXT messenger{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messenger.pfnUserCallback = &WindowDevice::on_validation_message;
  messenger.pUserData = this;
  messenger_.emplace(instance_.get(), messenger);
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

// The selector means what --device means to the other apps (an index in the loader's order, or part
// of the name), but the device must also present to this window, which a headless renderer never asks.
void WindowDevice::pick_physical_device(const std::string& device_selector) {
  std::string selector = device_selector;
  if (selector.empty())
    if (const char* env = std::getenv("TILESPLAT_DEVICE")) selector = env;
  uint32_t count = 0;
  vk::check(vkEnumeratePhysicalDevices(instance_.get(), &count, nullptr), "vkEnumeratePhysicalDevices");
  std::vector<VkPhysicalDevice> devices(count);
  vk::check(vkEnumeratePhysicalDevices(instance_.get(), &count, devices.data()),
            "vkEnumeratePhysicalDevices");
  if (devices.empty())
    throw std::runtime_error("no Vulkan device found (install a driver, e.g. Debian's mesa-vulkan-drivers)");

  const bool numeric = !selector.empty() && std::all_of(selector.begin(), selector.end(),
                                                        [](unsigned char c) { return std::isdigit(c); });
  std::string names, rejected;
  for (size_t i = 0; i < devices.size(); ++i) {
    const std::string name = device_name(devices[i]);
    names += (i ? ", " : "") + std::to_string(i) + ": " + name;
    const bool selected = selector.empty() || (numeric ? selector == std::to_string(i)
                                                       : lower(name).find(lower(selector)) != std::string::npos);
    if (!selected) continue;
    uint32_t family = 0;
    const std::string why = why_unsuitable(devices[i], surface_.get(), family);
    if (!why.empty()) {
      rejected += (rejected.empty() ? "" : "; ") + name + ": " + why;
      continue;
    }
    // A selector takes its first match that fits, as in the other apps; no selector, the best kind.
    if (!physical_device_ || (selector.empty() && type_rank(devices[i]) < type_rank(physical_device_))) {
      physical_device_ = devices[i];
      queue_family_ = family;
    }
  }
  if (physical_device_) return;
  if (rejected.empty())
    throw std::runtime_error("no Vulkan device matches '" + selector + "' (--device or TILESPLAT_DEVICE; devices: " +
                             names + ")");
  throw std::runtime_error("no Vulkan device can render to the window (" + rejected + ")");
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
