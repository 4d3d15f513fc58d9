#include "vulkan/context.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <vector>

#include "host_resources.h"
#include "vulkan/device_selection.h"
#include "vulkan/vk_check.h"

namespace tilesplat::vk {

const char* result_name(VkResult result) {
  switch (result) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER (no Vulkan driver installed?)";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_FORMAT_NOT_SUPPORTED: return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    default: return "VkResult error";
  }
}

namespace {

bool env_flag(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::string_view(v) != "0";
}

// A size in bytes from the environment, as "1048576", "512K", "64M" or "2G" (powers of 1024); 0 when unset.
// Throws std::runtime_error naming the variable for anything else.
uint64_t env_bytes(const char* name) {
  const char* v = std::getenv(name);
  if (!v || !*v) return 0;
  const std::string_view text(v);
  size_t digits = 0;
  uint64_t value = 0;
  bool too_large = false;
  for (; digits < text.size() && std::isdigit(static_cast<unsigned char>(text[digits])); ++digits) {
    if (value > (UINT64_MAX - 9) / 10) {
      too_large = true;
      break;
    }
    value = value * 10 + uint64_t(text[digits] - '0');
  }
  int shift = -1;
  if (digits == text.size()) shift = 0;
  if (digits + 1 == text.size()) {
    const char unit = char(std::toupper(static_cast<unsigned char>(text[digits])));
    shift = unit == 'K' ? 10 : unit == 'M' ? 20 : unit == 'G' ? 30 : unit == 'T' ? 40 : -1;
  }
  if (too_large || digits == 0 || shift < 0 || value == 0 || value > (UINT64_MAX >> shift))
    throw std::runtime_error(std::string(name) + "='" + std::string(text) +
                             "': expected a positive size in bytes, optionally with K, M, G or T");
  return value << shift;
}

bool has_extension(const std::vector<VkExtensionProperties>& available, std::string_view name) {
  return std::any_of(available.begin(), available.end(), [&](const VkExtensionProperties& e) {
    return std::string_view(e.extensionName) == name;
  });
}

// The bytes of memory the device's memory type for device buffers draws on. With VK_EXT_memory_budget,
// the budget the driver gives this process; without it, the heap's size, except on a CPU driver, whose
// device memory is the host's (Mesa 22's lavapipe reports a 2 GiB heap and allocates past it): there,
// the host's physical memory.
uint64_t device_memory(VkPhysicalDevice physical_device, bool cpu,
                       const std::vector<VkExtensionProperties>& available) {
  const bool has_budget = has_extension(available, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
  VkPhysicalDeviceMemoryBudgetPropertiesEXT budget{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_BUDGET_PROPERTIES_EXT};
  VkPhysicalDeviceMemoryProperties2 memory{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PROPERTIES_2};
  if (has_budget) memory.pNext = &budget;
  vkGetPhysicalDeviceMemoryProperties2(physical_device, &memory);
  const VkPhysicalDeviceMemoryProperties& properties = memory.memoryProperties;
  uint64_t largest = 0;  // the largest device-local heap (the one device buffers come from)
  for (uint32_t heap = 0; heap < properties.memoryHeapCount; ++heap) {
    if (!(properties.memoryHeaps[heap].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)) continue;
    const uint64_t bytes = has_budget && budget.heapBudget[heap] > 0 ? budget.heapBudget[heap]
                                                                     : properties.memoryHeaps[heap].size;
    largest = std::max(largest, bytes);
  }
  if (cpu && !has_budget) {
    largest = std::max(largest, detail::host_physical_memory());
  }
  return largest;
}

}  // namespace

Context::Context(const ContextOptions& options) {
  try {
    create_instance(options.validation || env_flag("TILESPLAT_VALIDATION"));
    std::string selector = options.device_selector;
    if (selector.empty())
      if (const char* env = std::getenv("TILESPLAT_DEVICE")) selector = env;
    pick_physical_device(selector);
    read_device_properties();
    queue_family_ = pick_queue_family();
    create_device();
    create_command_objects();
  } catch (...) {
    destroy();  // the destructor does not run for a constructor that throws
    throw;
  }
}

Context::Context(const ExternalVulkanDevice& borrowed) : owns_handles_(false) {
  keep_libraries_loaded_under_sanitizers();  // the host's instance loaded the driver and its layers
  if (!borrowed.instance || !borrowed.physical_device || !borrowed.device || !borrowed.queue)
    throw std::invalid_argument("borrowed Vulkan device: instance, physical device, device and queue are required");
  instance_ = borrowed.instance;
  physical_device_ = borrowed.physical_device;
  device_ = borrowed.device;
  queue_ = borrowed.queue;
  queue_family_ = borrowed.queue_family;
  try {
    read_device_properties();
    uint32_t family_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &family_count, nullptr);
    std::vector<VkQueueFamilyProperties> families(family_count);
    vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &family_count, families.data());
    if (queue_family_ >= family_count || !(families[queue_family_].queueFlags & VK_QUEUE_COMPUTE_BIT) ||
        families[queue_family_].timestampValidBits == 0)
      throw std::invalid_argument(device_name_ + ": borrowed queue family " + std::to_string(queue_family_) +
                                  " has no compute support with timestamps");
    limits_.timestamp_valid_bits = families[queue_family_].timestampValidBits;
    features_.graphics_queue = (families[queue_family_].queueFlags & VK_QUEUE_GRAPHICS_BIT) != 0;
    // The host enabled the device's features; shaderFloat64 only counts if it says so.
    features_.shader_float64 = features_.shader_float64 && borrowed.shader_float64_enabled;
    features_.independent_blend = features_.independent_blend && borrowed.independent_blend_enabled;
    features_.rasterization_order_colour =
        features_.rasterization_order_colour && borrowed.rasterization_order_attachment_access_enabled;
    create_command_objects();
  } catch (...) {
    destroy();
    throw;
  }
}

Context::~Context() { destroy(); }

void Context::destroy() {
  if (device_) {
    // A borrowed device may be busy with the host's own work: wait only for our submissions.
    if (owns_handles_) vkDeviceWaitIdle(device_);
    else if (fence_pending_)
      vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX);
    if (fence_) vkDestroyFence(device_, fence_, nullptr);
    if (command_pool_) vkDestroyCommandPool(device_, command_pool_, nullptr);
    fence_ = VK_NULL_HANDLE;
    command_pool_ = VK_NULL_HANDLE;
    if (owns_handles_) vkDestroyDevice(device_, nullptr);
    device_ = VK_NULL_HANDLE;
  }
  if (!owns_handles_) {
    instance_ = VK_NULL_HANDLE;
    return;
  }
  messenger_.reset();  // before its instance
  if (instance_) {
    vkDestroyInstance(instance_, nullptr);
    instance_ = VK_NULL_HANDLE;
  }
}

VKAPI_ATTR VkBool32 VKAPI_CALL Context::debug_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                       VkDebugUtilsMessageTypeFlagsEXT,
                                                       const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                       void* user) {
  auto* self = static_cast<Context*>(user);
  self->validation_messages_.fetch_add(1);
  const char* level = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
  std::fprintf(stderr, "tilesplat: vulkan validation %s: %s\n", level, data->pMessage);
  return VK_FALSE;
}

void Context::create_instance(bool validation) {
  instance_ = create_bare_instance(validation);
  if (validation) messenger_.emplace(instance_, &Context::debug_callback, this);
}

void Context::pick_physical_device(const std::string& selector) {
  physical_device_ = select_physical_device(instance_, selector);
}

void Context::read_device_properties() {
  VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
  subgroup.pNext = &driver;
  VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  props2.pNext = &subgroup;
  vkGetPhysicalDeviceProperties2(physical_device_, &props2);
  const VkPhysicalDeviceProperties& props = props2.properties;
  device_name_ = props.deviceName;
  is_cpu_ = props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  vendor_id_ = props.vendorID;
  driver_name_ = std::string(driver.driverName) + " " + driver.driverInfo;
  if (props.apiVersion < VK_API_VERSION_1_2)
    throw std::runtime_error(device_name_ + ": Vulkan 1.2 is required");

  const VkSubgroupFeatureFlags needed_ops =
      VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_BALLOT_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
  if (!(subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) ||
      (subgroup.supportedOperations & needed_ops) != needed_ops)
    throw std::runtime_error(device_name_ + ": compute subgroup basic/ballot/arithmetic operations are required");
  if (subgroup.subgroupSize < 4 || subgroup.subgroupSize > 128)
    throw std::runtime_error(device_name_ + ": unsupported subgroup size " + std::to_string(subgroup.subgroupSize));

  limits_.subgroup_size = subgroup.subgroupSize;
  limits_.max_storage_buffer_range = props.limits.maxStorageBufferRange;
  limits_.max_shared_memory = props.limits.maxComputeSharedMemorySize;
  limits_.max_workgroup_invocations = props.limits.maxComputeWorkGroupInvocations;
  limits_.max_workgroup_count_x = props.limits.maxComputeWorkGroupCount[0];
  limits_.max_image_dimension_2d = props.limits.maxImageDimension2D;
  limits_.timestamp_period_ns = props.limits.timestampPeriod;
  limits_.max_texel_buffer_elements = props.limits.maxTexelBufferElements;

  VkPhysicalDeviceMaintenance3Properties maint3{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  p2.pNext = &maint3;
  vkGetPhysicalDeviceProperties2(physical_device_, &p2);
  limits_.max_allocation_size = maint3.maxMemoryAllocationSize;
  uint32_t extension_count = 0;
  vkEnumerateDeviceExtensionProperties(physical_device_, nullptr, &extension_count, nullptr);
  std::vector<VkExtensionProperties> available(extension_count);
  vkEnumerateDeviceExtensionProperties(physical_device_, nullptr, &extension_count, available.data());
  limits_.device_memory = device_memory(physical_device_, is_cpu_, available);
  // A smaller device, for seeing and testing how frames split (docs/big-scenes.md): these only lower
  // the device's own limits.
  if (const uint64_t bytes = env_bytes("TILESPLAT_MAX_ALLOCATION"))
    limits_.max_allocation_size = std::min<uint64_t>(limits_.max_allocation_size, bytes);
  if (const uint64_t bytes = env_bytes("TILESPLAT_DEVICE_MEMORY"))
    limits_.device_memory = std::min(limits_.device_memory, bytes);

  VkPhysicalDeviceVulkan12Features has12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceRasterizationOrderAttachmentAccessFeaturesEXT has_order{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RASTERIZATION_ORDER_ATTACHMENT_ACCESS_FEATURES_EXT};
  VkPhysicalDeviceFeatures2 has{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  has.pNext = &has12;
  if (has_extension(available, VK_EXT_RASTERIZATION_ORDER_ATTACHMENT_ACCESS_EXTENSION_NAME))
    has12.pNext = &has_order;
  vkGetPhysicalDeviceFeatures2(physical_device_, &has);
  features_.rasterization_order_colour = has_order.rasterizationOrderColorAttachmentAccess == VK_TRUE;
  if (!has12.bufferDeviceAddress) throw std::runtime_error(device_name_ + ": bufferDeviceAddress is required");
  if (!has.features.shaderInt64) throw std::runtime_error(device_name_ + ": shaderInt64 is required");
  features_.shader_float64 = has.features.shaderFloat64 == VK_TRUE;
  features_.independent_blend = has.features.independentBlend == VK_TRUE;
  vkGetPhysicalDeviceMemoryProperties(physical_device_, &memory_properties_);
}

uint32_t Context::pick_queue_family() {
  uint32_t family_count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &family_count, nullptr);
  std::vector<VkQueueFamilyProperties> families(family_count);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &family_count, families.data());
  bool found = false;
  // A compute queue with timestamps; prefer one that also draws, which the raster compositor needs
  // (the engine's own device runs nothing beside the frame, so a compute-only queue would gain nothing).
  for (int pass = 0; pass < 2 && !found; ++pass) {
    for (uint32_t i = 0; i < family_count; ++i) {
      const auto& f = families[i];
      bool compute = f.queueFlags & VK_QUEUE_COMPUTE_BIT;
      bool graphics = f.queueFlags & VK_QUEUE_GRAPHICS_BIT;
      if (compute && f.timestampValidBits > 0 && (pass == 1 || graphics)) {
        queue_family_ = i;
        limits_.timestamp_valid_bits = f.timestampValidBits;
        features_.graphics_queue = graphics;
        found = true;
        break;
      }
    }
  }
  if (!found) throw std::runtime_error(device_name_ + ": no compute queue with timestamp support");
  return queue_family_;
}

void Context::create_device() {
  VkPhysicalDeviceVulkan12Features want12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  want12.bufferDeviceAddress = VK_TRUE;
  VkPhysicalDeviceFeatures2 want{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  want.pNext = &want12;
  want.features.shaderInt64 = VK_TRUE;
  want.features.shaderFloat64 = features_.shader_float64 ? VK_TRUE : VK_FALSE;
  want.features.independentBlend = features_.independent_blend ? VK_TRUE : VK_FALSE;

  float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue_info.queueFamilyIndex = queue_family_;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;
  // Push descriptors carry the texel-buffer views of the CPU-driver layouts (ComputePipeline).
  uint32_t extension_count = 0;
  vkEnumerateDeviceExtensionProperties(physical_device_, nullptr, &extension_count, nullptr);
  std::vector<VkExtensionProperties> available(extension_count);
  vkEnumerateDeviceExtensionProperties(physical_device_, nullptr, &extension_count, available.data());
  std::vector<const char*> extensions;
  const bool has_push_descriptor = has_extension(available, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
  const bool has_mesh_shader = has_extension(available, VK_EXT_MESH_SHADER_EXTENSION_NAME);
  if (has_push_descriptor) extensions.push_back(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
  // The features chained after want12, each when the device has it.
  void** next_feature = &want12.pNext;
  // A fragment reads what its pixel blended so far: the raster compositor's depth out.
  VkPhysicalDeviceRasterizationOrderAttachmentAccessFeaturesEXT want_order{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RASTERIZATION_ORDER_ATTACHMENT_ACCESS_FEATURES_EXT};
  if (features_.rasterization_order_colour) {
    extensions.push_back(VK_EXT_RASTERIZATION_ORDER_ATTACHMENT_ACCESS_EXTENSION_NAME);
    want_order.rasterizationOrderColorAttachmentAccess = VK_TRUE;
    *next_feature = &want_order;
    next_feature = &want_order.pNext;
  }
  // Mesh shaders draw the raster compositor's quads a workgroup of splats at a time; the mesh stage
  // alone (no task stage).
  VkPhysicalDeviceMeshShaderFeaturesEXT want_mesh{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT};
  if (has_mesh_shader) {
    VkPhysicalDeviceMeshShaderFeaturesEXT has_mesh{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT};
    VkPhysicalDeviceFeatures2 has{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    has.pNext = &has_mesh;
    vkGetPhysicalDeviceFeatures2(physical_device_, &has);
    VkPhysicalDeviceMeshShaderPropertiesEXT mesh_properties{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_PROPERTIES_EXT};
    VkPhysicalDeviceProperties2 properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    properties.pNext = &mesh_properties;
    vkGetPhysicalDeviceProperties2(physical_device_, &properties);
    // 32 splats a workgroup: 128 vertices and 64 triangles of 12 flat components a vertex.
    const bool fits = mesh_properties.maxMeshOutputVertices >= 128 &&
                      mesh_properties.maxMeshOutputPrimitives >= 64 &&
                      mesh_properties.maxMeshWorkGroupInvocations >= 32;
    if (has_mesh.meshShader && fits) {
      extensions.push_back(VK_EXT_MESH_SHADER_EXTENSION_NAME);
      want_mesh.meshShader = VK_TRUE;
      *next_feature = &want_mesh;
      next_feature = &want_mesh.pNext;
      limits_.max_mesh_workgroup_count_x = mesh_properties.maxMeshWorkGroupCount[0];
    }
  }

  // Float atomic adds sum the backward passes' gradients (composite_backward.comp); without them the
  // pass sums by compare-and-swap.
  VkPhysicalDeviceShaderAtomicFloatFeaturesEXT want_atomic_float{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT};
  if (has_extension(available, VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME)) {
    VkPhysicalDeviceShaderAtomicFloatFeaturesEXT has_atomic_float{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_FLOAT_FEATURES_EXT};
    VkPhysicalDeviceFeatures2 has{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    has.pNext = &has_atomic_float;
    vkGetPhysicalDeviceFeatures2(physical_device_, &has);
    if (has_atomic_float.shaderBufferFloat32AtomicAdd) {
      extensions.push_back(VK_EXT_SHADER_ATOMIC_FLOAT_EXTENSION_NAME);
      want_atomic_float.shaderBufferFloat32AtomicAdd = VK_TRUE;
      *next_feature = &want_atomic_float;
      next_feature = &want_atomic_float.pNext;
      features_.buffer_float32_atomic_add = true;
    }
  }

  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.pNext = &want;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue_info;
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  TS_VK_CHECK(vkCreateDevice(physical_device_, &info, nullptr, &device_));
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
  if (has_push_descriptor)
    cmd_push_descriptor_set_ = reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(
        vkGetDeviceProcAddr(device_, "vkCmdPushDescriptorSetKHR"));
  features_.push_descriptor = cmd_push_descriptor_set_ != nullptr;
  if (want_mesh.meshShader)
    cmd_draw_mesh_tasks_indirect_ = reinterpret_cast<PFN_vkCmdDrawMeshTasksIndirectEXT>(
        vkGetDeviceProcAddr(device_, "vkCmdDrawMeshTasksIndirectEXT"));
  features_.mesh_shader = cmd_draw_mesh_tasks_indirect_ != nullptr;
}

void Context::create_command_objects() {
  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT | VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pool.queueFamilyIndex = queue_family_;
  TS_VK_CHECK(vkCreateCommandPool(device_, &pool, nullptr, &command_pool_));
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  TS_VK_CHECK(vkCreateFence(device_, &fence, nullptr, &fence_));
}

uint32_t Context::find_memory_type(uint32_t type_bits, VkMemoryPropertyFlags required,
                                   VkMemoryPropertyFlags preferred) const {
  int fallback = -1;
  for (uint32_t i = 0; i < memory_properties_.memoryTypeCount; ++i) {
    if (!(type_bits & (1u << i))) continue;
    VkMemoryPropertyFlags flags = memory_properties_.memoryTypes[i].propertyFlags;
    if ((flags & required) != required) continue;
    if ((flags & preferred) == preferred) return i;
    if (fallback < 0) fallback = int(i);
  }
  if (fallback < 0) throw std::runtime_error(device_name_ + ": no suitable memory type");
  return uint32_t(fallback);
}

VkMemoryPropertyFlags Context::memory_type_flags(uint32_t type_index) const {
  return memory_properties_.memoryTypes[type_index].propertyFlags;
}

VkCommandBuffer Context::begin_one_time() {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = command_pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  TS_VK_CHECK(vkAllocateCommandBuffers(device_, &alloc, &cmd));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  TS_VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
  return cmd;
}

void Context::end_submit_wait(VkCommandBuffer cmd, const SubmitSync& sync) {
  struct FreeOnExit {
    Context* ctx;
    VkCommandBuffer cmd;
    ~FreeOnExit() { ctx->free_command_buffer(cmd); }
  } free_on_exit{this, cmd};
  TS_VK_CHECK(vkResetFences(device_, 1, &fence_));
  end_submit(cmd, sync, fence_);
  fence_pending_ = true;
  TS_VK_CHECK(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX));
  fence_pending_ = false;
}

void Context::end_submit(VkCommandBuffer cmd, const SubmitSync& sync, VkFence fence) {
  TS_VK_CHECK(vkEndCommandBuffer(cmd));
  const std::vector<VkPipelineStageFlags> all_commands(sync.wait.size(), VK_PIPELINE_STAGE_ALL_COMMANDS_BIT);
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  submit.waitSemaphoreCount = uint32_t(sync.wait.size());
  submit.pWaitSemaphores = sync.wait.data();
  submit.pWaitDstStageMask = sync.wait_stages.empty() ? all_commands.data() : sync.wait_stages.data();
  submit.signalSemaphoreCount = uint32_t(sync.signal.size());
  submit.pSignalSemaphores = sync.signal.data();
  VkTimelineSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  if (!sync.wait_values.empty() || !sync.signal_values.empty()) {
    timeline.waitSemaphoreValueCount = uint32_t(sync.wait_values.size());
    timeline.pWaitSemaphoreValues = sync.wait_values.data();
    timeline.signalSemaphoreValueCount = uint32_t(sync.signal_values.size());
    timeline.pSignalSemaphoreValues = sync.signal_values.data();
    submit.pNext = &timeline;
  }
  TS_VK_CHECK(vkQueueSubmit(queue_, 1, &submit, fence));
}

void Context::free_command_buffer(VkCommandBuffer cmd) {
  vkFreeCommandBuffers(device_, command_pool_, 1, &cmd);
}

void Context::discard(VkCommandBuffer cmd) {
  vkEndCommandBuffer(cmd);
  vkFreeCommandBuffers(device_, command_pool_, 1, &cmd);
}

}  // namespace tilesplat::vk
