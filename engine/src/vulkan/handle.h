// Vulkan handles that release themselves. A `Unique` handle keeps the parent it was made from (its device,
// or a surface's instance) and destroys itself with the call made for it, once: when it goes out of scope, is
// reset, or is assigned another; a move passes that duty on. Buffer, Image, the pipelines and the Context
// have more to them and are classes of their own; these are the plain handles a host-side layer makes by
// the dozen (semaphores, fences, pools, render passes, swapchains), so that no one releases them by hand.
#pragma once

#include <vulkan/vulkan.h>

#include <span>
#include <utility>

#include "vulkan/vk_check.h"

namespace tilesplat::vk {

// A handle made from `Parent` and destroyed by Destroy(parent, handle, nullptr).
template <typename Parent, typename Handle, void (*Destroy)(Parent, Handle, const VkAllocationCallbacks*)>
class Unique {
 public:
  Unique() = default;
  Unique(Parent parent, Handle handle) : parent_(parent), handle_(handle) {}
  ~Unique() { reset(); }
  Unique(Unique&& other) noexcept
      : parent_(other.parent_), handle_(std::exchange(other.handle_, Handle(VK_NULL_HANDLE))) {}
  Unique& operator=(Unique&& other) noexcept {
    if (this != &other) {
      reset();
      parent_ = other.parent_;
      handle_ = std::exchange(other.handle_, Handle(VK_NULL_HANDLE));
    }
    return *this;
  }
  Unique(const Unique&) = delete;
  Unique& operator=(const Unique&) = delete;

  void reset() {
    if (handle_ != VK_NULL_HANDLE) Destroy(parent_, std::exchange(handle_, Handle(VK_NULL_HANDLE)), nullptr);
  }
  // Where a create call writes the new handle (after releasing the one held):
  //   check(vkCreateFence(device, &info, nullptr, fence.receive(device)), "vkCreateFence");
  Handle* receive(Parent parent) {
    reset();
    parent_ = parent;
    return &handle_;
  }
  Handle get() const { return handle_; }
  const Handle* address() const { return &handle_; }  // an array of one, for a submit or present info
  explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }

 private:
  Parent parent_ = VK_NULL_HANDLE;
  Handle handle_ = VK_NULL_HANDLE;
};

// A handle with no parent (an instance, a device), destroyed by Destroy(handle, nullptr).
template <typename Handle, void (*Destroy)(Handle, const VkAllocationCallbacks*)>
class UniqueRoot {
 public:
  UniqueRoot() = default;
  explicit UniqueRoot(Handle handle) : handle_(handle) {}
  ~UniqueRoot() { reset(); }
  UniqueRoot(UniqueRoot&& other) noexcept : handle_(std::exchange(other.handle_, Handle(VK_NULL_HANDLE))) {}
  UniqueRoot& operator=(UniqueRoot&& other) noexcept {
    if (this != &other) {
      reset();
      handle_ = std::exchange(other.handle_, Handle(VK_NULL_HANDLE));
    }
    return *this;
  }
  UniqueRoot(const UniqueRoot&) = delete;
  UniqueRoot& operator=(const UniqueRoot&) = delete;

  void reset() {
    if (handle_ != VK_NULL_HANDLE) Destroy(std::exchange(handle_, Handle(VK_NULL_HANDLE)), nullptr);
  }
  Handle* receive() {
    reset();
    return &handle_;
  }
  Handle get() const { return handle_; }
  explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }

 private:
  Handle handle_ = VK_NULL_HANDLE;
};

using UniqueInstance = UniqueRoot<VkInstance, vkDestroyInstance>;
using UniqueDevice = UniqueRoot<VkDevice, vkDestroyDevice>;
using UniqueSurface = Unique<VkInstance, VkSurfaceKHR, vkDestroySurfaceKHR>;
using UniqueSwapchain = Unique<VkDevice, VkSwapchainKHR, vkDestroySwapchainKHR>;
using UniqueSemaphore = Unique<VkDevice, VkSemaphore, vkDestroySemaphore>;
using UniqueFence = Unique<VkDevice, VkFence, vkDestroyFence>;
using UniqueCommandPool = Unique<VkDevice, VkCommandPool, vkDestroyCommandPool>;
using UniqueRenderPass = Unique<VkDevice, VkRenderPass, vkDestroyRenderPass>;
using UniqueFramebuffer = Unique<VkDevice, VkFramebuffer, vkDestroyFramebuffer>;
using UniqueSampler = Unique<VkDevice, VkSampler, vkDestroySampler>;
using UniqueDescriptorSetLayout = Unique<VkDevice, VkDescriptorSetLayout, vkDestroyDescriptorSetLayout>;
using UniqueDescriptorPool = Unique<VkDevice, VkDescriptorPool, vkDestroyDescriptorPool>;
using UniquePipelineLayout = Unique<VkDevice, VkPipelineLayout, vkDestroyPipelineLayout>;
using UniquePipeline = Unique<VkDevice, VkPipeline, vkDestroyPipeline>;
using UniqueShaderModule = Unique<VkDevice, VkShaderModule, vkDestroyShaderModule>;

// The instance's debug messenger (VK_EXT_debug_utils), made and destroyed through the functions the
// instance gives for them: `callback` hears the validation layer's warnings and errors of every type.
class DebugMessenger {
 public:
  DebugMessenger(VkInstance instance, PFN_vkDebugUtilsMessengerCallbackEXT callback, void* user)
      : instance_(instance) {
    VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    info.pfnUserCallback = callback;
    info.pUserData = user;
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    if (!create)
      throw VulkanError("vkCreateDebugUtilsMessengerEXT (unavailable)", VK_ERROR_EXTENSION_NOT_PRESENT);
    check(create(instance, &info, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
  }
  ~DebugMessenger() {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  DebugMessenger(const DebugMessenger&) = delete;
  DebugMessenger& operator=(const DebugMessenger&) = delete;

 private:
  VkInstance instance_;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
};

inline UniqueSemaphore make_semaphore(VkDevice device) {
  const VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  UniqueSemaphore made;
  check(vkCreateSemaphore(device, &info, nullptr, made.receive(device)), "vkCreateSemaphore");
  return made;
}

inline UniqueFence make_fence(VkDevice device) {
  const VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  UniqueFence made;
  check(vkCreateFence(device, &info, nullptr, made.receive(device)), "vkCreateFence");
  return made;
}

// A pool whose command buffers are reset one by one (each recorded anew every frame).
inline UniqueCommandPool make_command_pool(VkDevice device, uint32_t queue_family) {
  VkCommandPoolCreateInfo info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  info.queueFamilyIndex = queue_family;
  UniqueCommandPool made;
  check(vkCreateCommandPool(device, &info, nullptr, made.receive(device)), "vkCreateCommandPool");
  return made;
}

// A primary command buffer from `pool`; it is freed with the pool.
inline VkCommandBuffer allocate_command_buffer(VkDevice device, VkCommandPool pool) {
  VkCommandBufferAllocateInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  info.commandPool = pool;
  info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  info.commandBufferCount = 1;
  VkCommandBuffer made = VK_NULL_HANDLE;
  check(vkAllocateCommandBuffers(device, &info, &made), "vkAllocateCommandBuffers");
  return made;
}

inline UniqueShaderModule make_shader_module(VkDevice device, std::span<const uint32_t> spirv) {
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = spirv.size_bytes();
  info.pCode = spirv.data();
  UniqueShaderModule made;
  check(vkCreateShaderModule(device, &info, nullptr, made.receive(device)), "vkCreateShaderModule");
  return made;
}

}  // namespace tilesplat::vk
