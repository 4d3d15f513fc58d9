// Which Vulkan device a context runs on: the instance tilesplat creates, the devices it enumerates,
// and the selector of RendererOptions::device (an index, part of a name, or a UUID).
#pragma once

#include <vulkan/vulkan.h>

#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tilesplat::vk {

inline constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

// Under AddressSanitizer only (a no-op otherwise): every library loaded now, the Vulkan driver and layers
// among them, stays loaded for the life of the process (device_selection.cpp says why). Called once an
// instance exists: by create_bare_instance, and by a context on a host's instance.
void keep_libraries_loaded_under_sanitizers();
// An instance of API 1.2; with `validation`, the Khronos layer and debug utils (throws when the layer
// is not installed). `extensions`: more instance extensions (a window's surface ones); `application`: the
// name the driver and the layers are told.
VkInstance create_bare_instance(bool validation, std::span<const char* const> extensions = {},
                                const char* application = "tilesplat");
std::vector<VkPhysicalDevice> enumerate_devices(VkInstance instance);
std::string physical_device_name(VkPhysicalDevice device);
// The device's UUID (VkPhysicalDeviceIDProperties::deviceUUID) as 8-4-4-4-12 lower-case hex. On
// NVIDIA it is the GPU UUID CUDA and nvidia-smi report (they print it after "GPU-").
std::string physical_device_uuid(VkPhysicalDevice device);
// Why a device cannot serve a caller with needs of its own (the viewer's: presenting to its window), or ""
// when it can.
using DeviceFit = std::function<std::string(VkPhysicalDevice)>;
// The device `selector` names: an index into enumerate_devices, a UUID ("GPU-" prefix and dashes
// optional), or part of a name (any case); empty: the first discrete GPU, else integrated, else any.
// With `why_unfit`, only a device it finds nothing against: a selector takes its first match that fits.
// Throws listing the devices when none matches, or when there is none; naming each match and why it does
// not fit when none fits ("no Vulkan device can `purpose` (...)").
VkPhysicalDevice select_physical_device(VkInstance instance, const std::string& selector,
                                        const DeviceFit& why_unfit = {}, std::string_view purpose = {});

}  // namespace tilesplat::vk
