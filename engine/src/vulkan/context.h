// The Vulkan instance, device and compute queue the engine runs on, and the limits it adapts to.
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tilesplat/vulkan_interop.h"
#include "vulkan/handle.h"

namespace tilesplat::vk {

struct ContextOptions {
  std::string device_selector;  // index, or substring of the device name; "" = best device
  bool validation = false;      // VK_LAYER_KHRONOS_validation; missing layer is an error
};

// The device properties the passes depend on.
struct DeviceLimits {
  uint32_t subgroup_size = 0;
  uint64_t max_storage_buffer_range = 0;
  uint32_t max_shared_memory = 0;
  uint32_t max_workgroup_invocations = 0;
  uint32_t max_workgroup_count_x = 0;
  uint32_t max_image_dimension_2d = 0;
  uint64_t max_allocation_size = 0;
  // The memory device buffers draw on: VK_EXT_memory_budget's budget, else the device-local heap (the
  // host's physical memory for a CPU driver without the extension). TILESPLAT_MAX_ALLOCATION and
  // TILESPLAT_DEVICE_MEMORY lower this and max_allocation_size.
  uint64_t device_memory = 0;
  uint32_t max_texel_buffer_elements = 0;
  double timestamp_period_ns = 0;
  uint32_t timestamp_valid_bits = 0;
  uint32_t max_mesh_workgroup_count_x = 0;  // VK_EXT_mesh_shader's, when DeviceFeatures::mesh_shader
};

// Optional features the engine uses when present.
struct DeviceFeatures {
  bool shader_float64 = false;  // exact float64 depth keys (else float32: rare order swaps)
  bool push_descriptor = false;  // VK_KHR_push_descriptor: texel-buffer layouts of the CPU-driver passes
  bool graphics_queue = false;   // the queue also draws: the raster compositor (Compositor::kRaster)
  bool independent_blend = false;  // attachments blended differently: the raster compositor's splat counts
  bool mesh_shader = false;  // VK_EXT_mesh_shader: the raster compositor's mesh stage (an engine-made device)
  // VK_EXT_rasterization_order_attachment_access's rasterizationOrderColorAttachmentAccess: a fragment
  // reads what the earlier fragments blended at its pixel; the raster compositor's depth out.
  bool rasterization_order_colour = false;
  // VK_EXT_shader_atomic_float's shaderBufferFloat32AtomicAdd (an engine-made device): the backward passes'
  // sums (else compare-and-swap loops).
  bool buffer_float32_atomic_add = false;
};

// Semaphores a submission waits for and signals besides its fence: a host's, around a frame that
// render_to_image submits without waiting (HostFrameSync). Values are for timeline semaphores.
struct SubmitSync {
  std::span<const VkSemaphore> wait;
  std::span<const VkPipelineStageFlags> wait_stages;  // one per wait semaphore, or empty: all commands
  std::span<const uint64_t> wait_values;              // one per wait semaphore, or empty: binary ones
  std::span<const VkSemaphore> signal;
  std::span<const uint64_t> signal_values;  // one per signal semaphore, or empty: binary ones
};

// Owns (or, for a host application, borrows) a VkInstance and VkDevice with one compute queue.
// Everything else in the engine goes through this object for Vulkan handles.
class Context {
 public:
  explicit Context(const ContextOptions& options);
  // Runs on a host application's device, borrowing its handles (see tilesplat/vulkan_interop.h).
  explicit Context(const ExternalVulkanDevice& borrowed);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physical_device() const { return physical_device_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queue_family() const { return queue_family_; }
  const DeviceLimits& limits() const { return limits_; }
  const DeviceFeatures& features() const { return features_; }
  const std::string& device_name() const { return device_name_; }
  const std::string& driver_name() const { return driver_name_; }
  // A CPU implementation (lavapipe, SwiftShader): passes pick CPU-friendly layouts.
  bool is_cpu_device() const { return is_cpu_; }
  uint32_t vendor_id() const { return vendor_id_; }  // VkPhysicalDeviceProperties::vendorID (PCI)
  // vkCmdPushDescriptorSetKHR when features().push_descriptor, else null.
  PFN_vkCmdPushDescriptorSetKHR cmd_push_descriptor_set() const { return cmd_push_descriptor_set_; }
  // vkCmdDrawMeshTasksIndirectEXT when features().mesh_shader, else null.
  PFN_vkCmdDrawMeshTasksIndirectEXT cmd_draw_mesh_tasks_indirect() const {
    return cmd_draw_mesh_tasks_indirect_;
  }

  // Index of a memory type with all `required` flags (and `preferred` ones when possible).
  uint32_t find_memory_type(uint32_t type_bits, VkMemoryPropertyFlags required,
                            VkMemoryPropertyFlags preferred = 0) const;
  VkMemoryPropertyFlags memory_type_flags(uint32_t type_index) const;

  // Records with `record` into a one-time command buffer, submits it and waits.
  template <typename Fn>
  void submit_and_wait(Fn&& record) {
    VkCommandBuffer cmd = begin_one_time();
    record(cmd);
    end_submit_wait(cmd);
  }
  VkCommandBuffer begin_one_time();
  // Ends, submits (waiting for `sync.wait` first) and waits for a command buffer, then frees it.
  void end_submit_wait(VkCommandBuffer cmd, const SubmitSync& sync = {});
  // Ends and submits a command buffer without waiting: `fence` (unsignalled) and `sync.signal` are
  // signalled when it completes. The caller frees it (free_command_buffer()) after the fence.
  void end_submit(VkCommandBuffer cmd, const SubmitSync& sync, VkFence fence);
  void free_command_buffer(VkCommandBuffer cmd);
  // Frees a command buffer from begin_one_time without submitting it.
  void discard(VkCommandBuffer cmd);

  uint64_t validation_messages() const { return validation_messages_.load(); }

  // Bytes the host has written into device buffers through vk::upload, over the context's life (the
  // renderer reports them per frame: FrameStats::uploaded_bytes).
  uint64_t uploaded_bytes() const { return uploaded_bytes_.load(); }
  void count_upload(uint64_t bytes) { uploaded_bytes_ += bytes; }

  static std::vector<std::string> list_devices();
  // The devices' UUIDs, 8-4-4-4-12 hex, in the order of list_devices().
  static std::vector<std::string> list_device_uuids();

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL debug_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                       VkDebugUtilsMessageTypeFlagsEXT types,
                                                       const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                       void* user);
  void create_instance(bool validation);
  void pick_physical_device(const std::string& selector);
  void read_device_properties();
  uint32_t pick_queue_family();
  void create_device();
  void create_command_objects();
  void destroy();

  bool owns_handles_ = true;  // false for a borrowed device: instance and device are the host's
  VkInstance instance_ = VK_NULL_HANDLE;
  std::optional<DebugMessenger> messenger_;  // with validation, on an instance of our own
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  bool fence_pending_ = false;  // submitted and not yet waited for (a wait that threw): destroy() waits
  VkPhysicalDeviceMemoryProperties memory_properties_{};
  DeviceLimits limits_;
  DeviceFeatures features_;
  std::string device_name_;
  std::string driver_name_;
  bool is_cpu_ = false;
  uint32_t vendor_id_ = 0;
  PFN_vkCmdPushDescriptorSetKHR cmd_push_descriptor_set_ = nullptr;
  PFN_vkCmdDrawMeshTasksIndirectEXT cmd_draw_mesh_tasks_indirect_ = nullptr;
  std::atomic<uint64_t> validation_messages_{0};
  std::atomic<uint64_t> uploaded_bytes_{0};
};

}  // namespace tilesplat::vk
