// A host application that owns the Vulkan objects: it creates the instance, device, queue, a colour
// image and a depth buffer, lends them to tilesplat (tilesplat/vulkan_interop.h), which renders a view
// into the image, depth-tested against the depth buffer and writing the splats' depth into it, then
// copies the image back and saves it as EXR. Here the host has drawn no meshes (its depth buffer is
// cleared to the far plane), so the image is the plain render, and the splats' depth is what a mesh
// drawn next would be tested against.
//
//   vulkan_host SCENE CAMERAS.json VIEW WIDTH HEIGHT OUT.exr
#include <tilesplat/camera.h>
#include <tilesplat/image.h>
#include <tilesplat/scene.h>
#include <tilesplat/vulkan_interop.h>

#include <array>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

void check(VkResult result, const char* what) {
  if (result != VK_SUCCESS)
    throw std::runtime_error(std::string(what) + " failed: VkResult " + std::to_string(result));
}

// The host's Vulkan: what a real application has already made for its own rendering.
struct Host {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t family = 0;
  bool float64 = false;

  Host() {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "tilesplat vulkan_host example";
    app.apiVersion = VK_API_VERSION_1_2;
    VkInstanceCreateInfo instance_info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    instance_info.pApplicationInfo = &app;
    check(vkCreateInstance(&instance_info, nullptr, &instance), "vkCreateInstance");

    uint32_t count = 0;
    check(vkEnumeratePhysicalDevices(instance, &count, nullptr), "vkEnumeratePhysicalDevices");
    if (count == 0) throw std::runtime_error("no Vulkan device");
    std::vector<VkPhysicalDevice> devices(count);
    check(vkEnumeratePhysicalDevices(instance, &count, devices.data()), "vkEnumeratePhysicalDevices");
    physical = devices.front();
    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, nullptr);
    std::vector<VkQueueFamilyProperties> properties(families);
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, properties.data());
    for (family = 0; family < families; ++family)
      if (properties[family].queueFlags & VK_QUEUE_COMPUTE_BIT) break;
    if (family == families) throw std::runtime_error("no compute queue");

    // What tilesplat needs of the device (vulkan_interop.h): Vulkan 1.2, buffer device addresses and
    // 64-bit integers; 64-bit floats where the device has them.
    VkPhysicalDeviceFeatures2 available{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    vkGetPhysicalDeviceFeatures2(physical, &available);
    float64 = available.features.shaderFloat64 == VK_TRUE;
    VkPhysicalDeviceVulkan12Features features12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    features12.bufferDeviceAddress = VK_TRUE;
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    features.pNext = &features12;
    features.features.shaderInt64 = VK_TRUE;
    features.features.shaderFloat64 = available.features.shaderFloat64;
    const float priority = 1;
    VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queue_info.queueFamilyIndex = family;
    queue_info.queueCount = 1;
    queue_info.pQueuePriorities = &priority;
    VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    device_info.pNext = &features;
    device_info.queueCreateInfoCount = 1;
    device_info.pQueueCreateInfos = &queue_info;
    check(vkCreateDevice(physical, &device_info, nullptr, &device), "vkCreateDevice");
    vkGetDeviceQueue(device, family, 0, &queue);
  }
  ~Host() {
    if (device) vkDestroyDevice(device, nullptr);
    if (instance) vkDestroyInstance(instance, nullptr);
  }
  Host(const Host&) = delete;
  Host& operator=(const Host&) = delete;

  uint32_t memory_type(uint32_t allowed, VkMemoryPropertyFlags flags) const {
    VkPhysicalDeviceMemoryProperties memory;
    vkGetPhysicalDeviceMemoryProperties(physical, &memory);
    for (uint32_t i = 0; i < memory.memoryTypeCount; ++i)
      if ((allowed & (1u << i)) && (memory.memoryTypes[i].propertyFlags & flags) == flags) return i;
    throw std::runtime_error("no suitable memory type");
  }

  // Records commands into a one-time command buffer, submits them (after `wait`, if given) and waits.
  template <typename Record>
  void run_once(Record&& record, VkSemaphore wait = VK_NULL_HANDLE) const {
    VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool_info.queueFamilyIndex = family;
    VkCommandPool pool = VK_NULL_HANDLE;
    check(vkCreateCommandPool(device, &pool_info, nullptr, &pool), "vkCreateCommandPool");
    VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    allocate.commandPool = pool;
    allocate.commandBufferCount = 1;
    VkCommandBuffer commands = VK_NULL_HANDLE;
    check(vkAllocateCommandBuffers(device, &allocate, &commands), "vkAllocateCommandBuffers");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check(vkBeginCommandBuffer(commands, &begin), "vkBeginCommandBuffer");
    record(commands);
    check(vkEndCommandBuffer(commands), "vkEndCommandBuffer");
    const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.waitSemaphoreCount = wait ? 1 : 0;
    submit.pWaitSemaphores = &wait;
    submit.pWaitDstStageMask = &wait_stage;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &commands;
    check(vkQueueSubmit(queue, 1, &submit, VK_NULL_HANDLE), "vkQueueSubmit");
    check(vkQueueWaitIdle(queue), "vkQueueWaitIdle");
    vkDestroyCommandPool(device, pool, nullptr);
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 7) {
    std::fprintf(stderr, "usage: %s SCENE CAMERAS.json VIEW WIDTH HEIGHT OUT.exr\n", argv[0]);
    return 2;
  }
  try {
    const tilesplat::GaussianScene scene = tilesplat::load_scene(argv[1]);
    const tilesplat::Camera camera =
        tilesplat::resize_camera(tilesplat::load_cameras_json(argv[2]).at(std::stoul(argv[3])).camera,
                                 std::stoi(argv[4]), std::stoi(argv[5]));
    const auto width = uint32_t(camera.width), height = uint32_t(camera.height);
    Host host;

    // The host's colour target (render_to_image also writes RGBA16F and RGBA8 UNORM/sRGB images).
    VkImageCreateInfo image_info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    image_info.imageType = VK_IMAGE_TYPE_2D;
    image_info.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    image_info.extent = {width, height, 1};
    image_info.mipLevels = 1;
    image_info.arrayLayers = 1;
    image_info.samples = VK_SAMPLE_COUNT_1_BIT;
    image_info.tiling = VK_IMAGE_TILING_OPTIMAL;
    image_info.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    VkImage image = VK_NULL_HANDLE;
    check(vkCreateImage(host.device, &image_info, nullptr, &image), "vkCreateImage");
    VkMemoryRequirements needs;
    vkGetImageMemoryRequirements(host.device, image, &needs);
    VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    allocate.allocationSize = needs.size;
    allocate.memoryTypeIndex = host.memory_type(needs.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VkDeviceMemory image_memory = VK_NULL_HANDLE;
    check(vkAllocateMemory(host.device, &allocate, nullptr, &image_memory), "vkAllocateMemory");
    check(vkBindImageMemory(host.device, image, image_memory, 0), "vkBindImageMemory");

    // The host's depth buffer, cleared to the far plane as before drawing its meshes; their projection
    // (Vulkan clip space, near 0.1, far 1000) says how it holds depth.
    image_info.format = VK_FORMAT_D32_SFLOAT;
    image_info.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                       VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    VkImage depth = VK_NULL_HANDLE;
    check(vkCreateImage(host.device, &image_info, nullptr, &depth), "vkCreateImage");
    vkGetImageMemoryRequirements(host.device, depth, &needs);
    allocate.allocationSize = needs.size;
    allocate.memoryTypeIndex = host.memory_type(needs.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VkDeviceMemory depth_memory = VK_NULL_HANDLE;
    check(vkAllocateMemory(host.device, &allocate, nullptr, &depth_memory), "vkAllocateMemory");
    check(vkBindImageMemory(host.device, depth, depth_memory, 0), "vkBindImageMemory");
    auto depth_layout = [&](VkCommandBuffer commands, VkImageLayout from, VkImageLayout to) {
      VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
      barrier.oldLayout = from;
      barrier.newLayout = to;
      barrier.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
      barrier.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
      barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      barrier.image = depth;
      barrier.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
      vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                           0, 0, nullptr, 0, nullptr, 1, &barrier);
    };
    host.run_once([&](VkCommandBuffer commands) {
      depth_layout(commands, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
      const VkClearDepthStencilValue far_plane{1.0f, 0};
      const VkImageSubresourceRange range{VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
      vkCmdClearDepthStencilImage(commands, depth, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &far_plane, 1,
                                  &range);
      depth_layout(commands, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                   VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
    });
    constexpr double kNear = 0.1, kFar = 1000;
    std::array<double, 16> projection{};  // column-major; only its depth rows matter here
    projection[0] = projection[5] = 1;
    projection[10] = kFar / (kNear - kFar);
    projection[11] = -1;
    projection[14] = kFar * kNear / (kNear - kFar);

    // Signalled by the renderer's frame; the host's next submission waits for it.
    VkSemaphoreCreateInfo semaphore_info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore splats_drawn = VK_NULL_HANDLE;
    check(vkCreateSemaphore(host.device, &semaphore_info, nullptr, &splats_drawn), "vkCreateSemaphore");
    {
      // The renderer borrows the host's handles and never destroys them.
      const auto renderer = tilesplat::create_renderer(
          {host.instance, host.physical, host.device, host.queue, host.family, host.float64});
      renderer->set_scene(scene);
      // Splats behind the host's depth do not blend; where their alpha reaches 0.5 their depth is written
      // into the depth buffer. An UNDEFINED colour image is left in GENERAL layout; an image in any other
      // layout (the depth buffer's included) stays in it.
      tilesplat::RenderSettings settings;
      settings.host = tilesplat::HostDepth{tilesplat::DepthConvention::from_projection(projection),
                                           {},
                                           /*write_depth=*/true,
                                           /*alpha_threshold=*/0.5f};
      // Submitted without waiting: the call returns while the frame runs and signals splats_drawn once
      // both images are written (the host could record its next work meanwhile). Destroying the renderer
      // waits for the frame.
      const tilesplat::ExternalDepthImage depth_image{depth, width, height, VK_FORMAT_D32_SFLOAT,
                                                      VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
      const VkSemaphore signals[] = {splats_drawn};
      tilesplat::render_to_image(
          *renderer, camera, settings,
          {image, width, height, VK_FORMAT_R32G32B32A32_SFLOAT, VK_IMAGE_LAYOUT_UNDEFINED}, &depth_image,
          tilesplat::HostFrameSync{{}, {}, {}, signals, {}});
    }

    // The host reads its image back (in an application it would sample or blend it instead).
    const VkDeviceSize bytes = VkDeviceSize(width) * height * 4 * sizeof(float);
    VkBufferCreateInfo buffer_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    buffer_info.size = bytes;
    buffer_info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkBuffer readback = VK_NULL_HANDLE;
    check(vkCreateBuffer(host.device, &buffer_info, nullptr, &readback), "vkCreateBuffer");
    vkGetBufferMemoryRequirements(host.device, readback, &needs);
    allocate.allocationSize = needs.size;
    allocate.memoryTypeIndex = host.memory_type(
        needs.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    VkDeviceMemory readback_memory = VK_NULL_HANDLE;
    check(vkAllocateMemory(host.device, &allocate, nullptr, &readback_memory), "vkAllocateMemory");
    check(vkBindBufferMemory(host.device, readback, readback_memory, 0), "vkBindBufferMemory");
    host.run_once(
        [&](VkCommandBuffer commands) {
          VkImageMemoryBarrier to_source{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
          to_source.oldLayout = VK_IMAGE_LAYOUT_GENERAL;
          to_source.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
          to_source.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
          to_source.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
          to_source.srcQueueFamilyIndex = to_source.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
          to_source.image = image;
          to_source.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
          vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                               0, 0, nullptr, 0, nullptr, 1, &to_source);
          VkBufferImageCopy region{};
          region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
          region.imageExtent = {width, height, 1};
          vkCmdCopyImageToBuffer(commands, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback, 1, &region);
        },
        splats_drawn);
    vkDestroySemaphore(host.device, splats_drawn, nullptr);
    tilesplat::RenderImage result;
    result.width = camera.width;
    result.height = camera.height;
    result.rgba.resize(size_t(width) * height * 4);
    void* mapped = nullptr;
    check(vkMapMemory(host.device, readback_memory, 0, bytes, 0, &mapped), "vkMapMemory");
    std::memcpy(result.rgba.data(), mapped, bytes);
    vkUnmapMemory(host.device, readback_memory);
    tilesplat::write_exr(argv[6], result);

    // The depth buffer now holds the splats' depth where they are dense, for the meshes drawn next.
    host.run_once([&](VkCommandBuffer commands) {
      depth_layout(commands, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                   VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
      VkBufferImageCopy region{};
      region.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
      region.imageExtent = {width, height, 1};
      vkCmdCopyImageToBuffer(commands, depth, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback, 1, &region);
    });
    std::vector<float> depth_values(size_t(width) * height);
    check(vkMapMemory(host.device, readback_memory, 0, bytes, 0, &mapped), "vkMapMemory");
    std::memcpy(depth_values.data(), mapped, depth_values.size() * sizeof(float));
    vkUnmapMemory(host.device, readback_memory);
    size_t covered = 0;
    for (const float value : depth_values) covered += value < 1.0f ? 1u : 0u;

    vkDestroyBuffer(host.device, readback, nullptr);
    vkFreeMemory(host.device, readback_memory, nullptr);
    vkDestroyImage(host.device, image, nullptr);
    vkFreeMemory(host.device, image_memory, nullptr);
    vkDestroyImage(host.device, depth, nullptr);
    vkFreeMemory(host.device, depth_memory, nullptr);
    std::printf(
        "rendered %ux%u into the host's image -> %s; the splats wrote their depth at %zu of %zu pixels\n",
        width, height, argv[6], covered, depth_values.size());
  } catch (const std::exception& error) {
    std::fprintf(stderr, "vulkan_host: %s\n", error.what());
    return 1;
  }
  return 0;
}
