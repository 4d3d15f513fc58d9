#include "vulkan/device_selection.h"

#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
#include <link.h>
#endif

#include <algorithm>
#include <cctype>
#include <cstring>
#include <stdexcept>

#include "vulkan/context.h"
#include "vulkan/vk_check.h"

namespace tilesplat::vk {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

// The 32 hex digits of a selector that names a device by UUID ("GPU-" prefix and dashes optional,
// any case), or "" when it is not a UUID.
std::string uuid_digits(const std::string& selector) {
  std::string text = lower(selector);
  if (text.rfind("gpu-", 0) == 0) text = text.substr(4);
  std::string digits;
  for (const char c : text) {
    if (c == '-') continue;
    if (!std::isxdigit(static_cast<unsigned char>(c))) return "";
    digits += c;
  }
  return digits.size() == 2 * VK_UUID_SIZE ? digits : "";
}

}  // namespace

std::vector<VkPhysicalDevice> enumerate_devices(VkInstance instance) {
  uint32_t count = 0;
  TS_VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  TS_VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
  return devices;
}

// Under AddressSanitizer only: every library loaded now (the Vulkan driver and layers among them) stays
// loaded for the life of the process. The Vulkan loader unloads the driver and the layers (dlclose) when an
// instance is destroyed, and what they keep in their globals until exit then looks leaked, from an unknown
// module that no suppression can name (lavapipe holds 128 bytes so). The loader's own sanitizer runs keep
// them loaded the same way (its LOADER_DISABLE_DYNAMIC_LIBRARY_UNLOADING); leaks of the engine's own are
// still found. Normal builds compile none of this.
void keep_libraries_loaded_under_sanitizers() {
#if defined(__SANITIZE_ADDRESS__)
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void*) {
        // RTLD_NOLOAD: only the library already loaded; RTLD_NODELETE: never unloaded after. The handle is
        // kept open, on purpose.
        if (info->dlpi_name != nullptr && info->dlpi_name[0] != '\0')
          dlopen(info->dlpi_name, RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE);
        return 0;
      },
      nullptr);
#endif
}

VkInstance create_bare_instance(bool validation, std::span<const char* const> extra_extensions,
                                const char* application) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = application;
  app.pEngineName = "tilesplat";
  app.apiVersion = VK_API_VERSION_1_2;
  std::vector<const char*> layers;
  std::vector<const char*> extensions(extra_extensions.begin(), extra_extensions.end());
  if (validation) {
    uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> available(count);
    vkEnumerateInstanceLayerProperties(&count, available.data());
    bool found = std::any_of(available.begin(), available.end(), [](const VkLayerProperties& p) {
      return std::strcmp(p.layerName, kValidationLayer) == 0;
    });
    if (!found)
      throw std::runtime_error(std::string("validation requested but ") + kValidationLayer +
                               " is not installed (Debian: vulkan-validationlayers)");
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  info.enabledLayerCount = uint32_t(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  VkInstance instance = VK_NULL_HANDLE;
  TS_VK_CHECK(vkCreateInstance(&info, nullptr, &instance));
  keep_libraries_loaded_under_sanitizers();  // the driver and the layers are loaded now
  return instance;
}

std::string physical_device_name(VkPhysicalDevice device) {
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(device, &props);
  return props.deviceName;
}

std::string physical_device_uuid(VkPhysicalDevice device) {
  VkPhysicalDeviceIDProperties id{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  props.pNext = &id;
  vkGetPhysicalDeviceProperties2(device, &props);
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string text;
  for (size_t i = 0; i < VK_UUID_SIZE; ++i) {
    if (i == 4 || i == 6 || i == 8 || i == 10) text += '-';
    text += kDigits[id.deviceUUID[i] >> 4];
    text += kDigits[id.deviceUUID[i] & 15];
  }
  return text;
}

namespace {

// The kind select_physical_device prefers without a selector: a discrete GPU, then an integrated one, then
// anything (lavapipe).
int kind_rank(VkPhysicalDevice device) {
  VkPhysicalDeviceProperties properties;
  vkGetPhysicalDeviceProperties(device, &properties);
  switch (properties.deviceType) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return 2;
    default:
      return 3;
  }
}

}  // namespace

VkPhysicalDevice select_physical_device(VkInstance instance, const std::string& selector,
                                        const DeviceFit& why_unfit, std::string_view purpose) {
  const std::vector<VkPhysicalDevice> devices = enumerate_devices(instance);
  if (devices.empty())
    throw std::runtime_error(
        "no Vulkan device found (install a driver, e.g. Debian's mesa-vulkan-drivers for lavapipe)");
  const bool numeric = !selector.empty() && std::all_of(selector.begin(), selector.end(),
                                                        [](unsigned char c) { return std::isdigit(c); });
  const std::string uuid = numeric || selector.empty() ? std::string() : uuid_digits(selector);
  VkPhysicalDevice chosen = VK_NULL_HANDLE;
  std::string names, unfit;
  for (size_t i = 0; i < devices.size(); ++i) {
    const std::string name = physical_device_name(devices[i]);
    const std::string device_uuid = physical_device_uuid(devices[i]);
    names += (i ? ", " : "") + std::to_string(i) + ": " + name + " (" + device_uuid + ")";
    const bool selected = selector.empty() ? true
                          : numeric        ? std::stoul(selector) == i
                          : !uuid.empty()  ? uuid_digits(device_uuid) == uuid
                                           : lower(name).find(lower(selector)) != std::string::npos;
    if (!selected || (chosen && !selector.empty())) continue;
    if (why_unfit) {
      const std::string why = why_unfit(devices[i]);
      if (!why.empty()) {
        unfit += (unfit.empty() ? "" : "; ") + name + ": " + why;
        continue;
      }
    }
    if (!chosen || kind_rank(devices[i]) < kind_rank(chosen)) chosen = devices[i];
  }
  if (chosen) return chosen;
  if (unfit.empty())
    throw std::runtime_error("no Vulkan device matches '" + selector + "' (devices: " + names + ")");
  throw std::runtime_error("no Vulkan device can " + std::string(purpose) + " (" + unfit + ")");
}

std::vector<std::string> Context::list_device_uuids() {
  VkInstance instance = create_bare_instance(false);
  std::vector<std::string> uuids;
  for (VkPhysicalDevice d : enumerate_devices(instance)) uuids.push_back(physical_device_uuid(d));
  vkDestroyInstance(instance, nullptr);
  return uuids;
}

std::vector<std::string> Context::list_devices() {
  VkInstance instance = create_bare_instance(false);
  std::vector<std::string> names;
  for (VkPhysicalDevice d : enumerate_devices(instance)) names.push_back(physical_device_name(d));
  vkDestroyInstance(instance, nullptr);
  return names;
}

}  // namespace tilesplat::vk
