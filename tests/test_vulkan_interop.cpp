// The renderer inside a host application's Vulkan: the test plays the host, creating its own
// instance (with the validation layer and its own messenger), device, queue and image.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "effects_report.h"
#include "test_support.h"
#include "tilesplat/lens.h"
#include "tilesplat/vulkan_interop.h"

namespace tilesplat {
namespace {

#define HOST_CHECK(call) ASSERT_EQ((call), VK_SUCCESS) << #call

// An IEEE half's bits as a float (infinities and NaN included).
float half_to_float(uint16_t h) {
  const int exponent = (h >> 10) & 0x1f, mantissa = h & 0x3ff;
  float magnitude = exponent == 0 ? std::ldexp(float(mantissa), -24) : std::ldexp(float(mantissa | 0x400), exponent - 25);
  if (exponent == 0x1f)
    magnitude = mantissa ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
  return (h & 0x8000) ? -magnitude : magnitude;
}

VKAPI_ATTR VkBool32 VKAPI_CALL count_messages(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                              VkDebugUtilsMessageTypeFlagsEXT,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  ++*static_cast<int*>(user);
  std::fprintf(stderr, "host validation: %s\n", data->pMessage);
  return VK_FALSE;
}

class HostApplication : public ::testing::Test {
 protected:
  void SetUp() override {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.apiVersion = VK_API_VERSION_1_2;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    const char* ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    ici.enabledLayerCount = 1;
    ici.ppEnabledLayerNames = &layer;
    ici.enabledExtensionCount = 1;
    ici.ppEnabledExtensionNames = &ext;
    HOST_CHECK(vkCreateInstance(&ici, nullptr, &instance));
    VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mci.messageSeverity =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mci.messageType =
        VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    mci.pfnUserCallback = count_messages;
    mci.pUserData = &messages;
    auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    HOST_CHECK(create_messenger(instance, &mci, nullptr, &messenger));

    uint32_t count = 1;
    VkResult r = vkEnumeratePhysicalDevices(instance, &count, &physical);
    ASSERT_TRUE(r == VK_SUCCESS || r == VK_INCOMPLETE);
    ASSERT_EQ(count, 1u);
    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, nullptr);
    std::vector<VkQueueFamilyProperties> props(families);
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, props.data());
    for (family = 0; family < families; ++family)
      if (props[family].queueFlags & VK_QUEUE_COMPUTE_BIT) break;
    ASSERT_LT(family, families);

    VkPhysicalDeviceFeatures2 has{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    vkGetPhysicalDeviceFeatures2(physical, &has);
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    f12.bufferDeviceAddress = VK_TRUE;
    f12.timelineSemaphore = VK_TRUE;  // the host's own choice; render_to_image takes timeline semaphores too
    VkPhysicalDeviceFeatures2 f{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    f.pNext = &f12;
    f.features.shaderInt64 = VK_TRUE;
    f.features.shaderFloat64 = has.features.shaderFloat64;
    float priority = 1;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    // What the raster compositor may use where the host says so (ExternalVulkanDevice): the blends of
    // its counts and depth out, and its fragments' reads of the running alpha.
    f.features.independentBlend = has.features.independentBlend;
    uint32_t extension_count = 0;
    vkEnumerateDeviceExtensionProperties(physical, nullptr, &extension_count, nullptr);
    std::vector<VkExtensionProperties> extensions(extension_count);
    vkEnumerateDeviceExtensionProperties(physical, nullptr, &extension_count, extensions.data());
    for (const VkExtensionProperties& e : extensions)
      rasterization_order =
          rasterization_order ||
          std::string_view(e.extensionName) == VK_EXT_RASTERIZATION_ORDER_ATTACHMENT_ACCESS_EXTENSION_NAME;
    VkPhysicalDeviceRasterizationOrderAttachmentAccessFeaturesEXT order{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RASTERIZATION_ORDER_ATTACHMENT_ACCESS_FEATURES_EXT};
    order.rasterizationOrderColorAttachmentAccess = VK_TRUE;
    const char* order_extension = VK_EXT_RASTERIZATION_ORDER_ATTACHMENT_ACCESS_EXTENSION_NAME;
    if (rasterization_order) f12.pNext = &order;
    independent_blend = has.features.independentBlend == VK_TRUE;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.pNext = &f;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.enabledExtensionCount = rasterization_order ? 1 : 0;
    dci.ppEnabledExtensionNames = &order_extension;
    HOST_CHECK(vkCreateDevice(physical, &dci, nullptr, &device));
    vkGetDeviceQueue(device, family, 0, &queue);
    float64 = has.features.shaderFloat64 == VK_TRUE;
  }

  void TearDown() override {
    if (device) release_host_objects();
    if (device) vkDestroyDevice(device, nullptr);
    if (messenger) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      destroy(instance, messenger, nullptr);
    }
    if (instance) vkDestroyInstance(instance, nullptr);
  }

  uint32_t memory_type(uint32_t bits, VkMemoryPropertyFlags flags) {
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(physical, &mp);
    for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
      if ((bits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & flags) == flags) return i;
    throw std::runtime_error("no memory type");
  }

  ExternalVulkanDevice external() const { return {instance, physical, device, queue, family, float64}; }

  // What a host keeps around to fill and read its images: device-local images, one host-visible
  // staging buffer, one command pool.
  struct Image {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
  };
  Image make_image(VkFormat format, VkImageUsageFlags usage, uint32_t width, uint32_t height) {
    VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = format;
    ici.extent = {width, height, 1};
    ici.mipLevels = ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = usage | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    Image made;
    EXPECT_EQ(vkCreateImage(device, &ici, nullptr, &made.image), VK_SUCCESS);
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, made.image, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memory_type(req.memoryTypeBits, 0);
    EXPECT_EQ(vkAllocateMemory(device, &mai, nullptr, &made.memory), VK_SUCCESS);
    EXPECT_EQ(vkBindImageMemory(device, made.image, made.memory, 0), VK_SUCCESS);
    images.push_back(made);
    return made;
  }
  // A host-visible buffer of `bytes`, staging_data at `staging_data`.
  void make_staging(VkDeviceSize bytes) {
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = bytes;
    bci.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    ASSERT_EQ(vkCreateBuffer(device, &bci, nullptr, &staging), VK_SUCCESS);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, staging, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memory_type(
        req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    ASSERT_EQ(vkAllocateMemory(device, &mai, nullptr, &staging_memory), VK_SUCCESS);
    ASSERT_EQ(vkBindBufferMemory(device, staging, staging_memory, 0), VK_SUCCESS);
    ASSERT_EQ(vkMapMemory(device, staging_memory, 0, bytes, 0, &staging_data), VK_SUCCESS);
  }
  // Records, submits and waits for one command buffer.
  VkCommandPool pool() {
    if (!command_pool) {
      VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
      pci.queueFamilyIndex = family;
      EXPECT_EQ(vkCreateCommandPool(device, &pci, nullptr, &command_pool), VK_SUCCESS);
    }
    return command_pool;
  }
  void submit(const std::function<void(VkCommandBuffer)>& record) {
    VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cai.commandPool = pool();
    cai.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    ASSERT_EQ(vkAllocateCommandBuffers(device, &cai, &cmd), VK_SUCCESS);
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    ASSERT_EQ(vkBeginCommandBuffer(cmd, &begin), VK_SUCCESS);
    record(cmd);
    ASSERT_EQ(vkEndCommandBuffer(cmd), VK_SUCCESS);
    VkSubmitInfo info{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    info.commandBufferCount = 1;
    info.pCommandBuffers = &cmd;
    ASSERT_EQ(vkQueueSubmit(queue, 1, &info, VK_NULL_HANDLE), VK_SUCCESS);
    ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
    vkFreeCommandBuffers(device, command_pool, 1, &cmd);
    free_pending_command_buffers();  // the queue is idle
  }
  void free_pending_command_buffers() {
    if (!pending_command_buffers.empty())
      vkFreeCommandBuffers(device, command_pool, uint32_t(pending_command_buffers.size()),
                           pending_command_buffers.data());
    pending_command_buffers.clear();
  }
  // A binary semaphore, or a timeline one starting at 0; destroyed with the host's other objects.
  VkSemaphore make_semaphore(bool timeline = false) {
    VkSemaphoreTypeCreateInfo type{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
    type.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
    VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    if (timeline) sci.pNext = &type;
    VkSemaphore semaphore = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateSemaphore(device, &sci, nullptr, &semaphore), VK_SUCCESS);
    semaphores.push_back(semaphore);
    return semaphore;
  }
  // Records and submits one command buffer that waits for and signals binary semaphores, without
  // waiting for it (the queue is drained by the next submit() or release_host_objects()).
  void submit_async(const std::function<void(VkCommandBuffer)>& record, VkSemaphore wait,
                    VkSemaphore signal) {
    VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cai.commandPool = pool();
    cai.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    ASSERT_EQ(vkAllocateCommandBuffers(device, &cai, &cmd), VK_SUCCESS);
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    ASSERT_EQ(vkBeginCommandBuffer(cmd, &begin), VK_SUCCESS);
    record(cmd);
    ASSERT_EQ(vkEndCommandBuffer(cmd), VK_SUCCESS);
    const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    VkSubmitInfo info{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    info.commandBufferCount = 1;
    info.pCommandBuffers = &cmd;
    info.waitSemaphoreCount = wait ? 1 : 0;
    info.pWaitSemaphores = &wait;
    info.pWaitDstStageMask = &stage;
    info.signalSemaphoreCount = signal ? 1 : 0;
    info.pSignalSemaphores = &signal;
    ASSERT_EQ(vkQueueSubmit(queue, 1, &info, VK_NULL_HANDLE), VK_SUCCESS);
    pending_command_buffers.push_back(cmd);
  }
  static void layout_barrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect,
                             VkImageLayout from, VkImageLayout to) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.oldLayout = from;
    b.newLayout = to;
    b.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspect, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0,
                         nullptr, 0, nullptr, 1, &b);
  }
  // Both images of a depth test as the host reads them back: the colour image (left GENERAL by a frame
  // that was handed it UNDEFINED) and the depth image (kept in DEPTH_STENCIL_ATTACHMENT_OPTIMAL).
  struct ColourAndDepth {
    std::vector<float> rgba, depth;
  };
  ColourAndDepth read_colour_and_depth(const Image& colour, const Image& depth, uint32_t width,
                                       uint32_t height) {
    ColourAndDepth read{std::vector<float>(size_t(width) * height * 4),
                        std::vector<float>(size_t(width) * height)};
    read_image(colour.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL, width, height);
    std::memcpy(read.rgba.data(), staging_data, read.rgba.size() * sizeof(float));
    read_image(depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
               width, height);
    std::memcpy(read.depth.data(), staging_data, read.depth.size() * sizeof(float));
    return read;
  }
  // The depth tests' host images: a colour image, and a D32 depth buffer into which the host "draws"
  // `wall` (ending in the layout a host keeps a depth buffer in); the staging buffer is left for reading
  // them back.
  struct ColourAndDepthImages {
    Image colour, depth;
  };
  ColourAndDepthImages draw_wall(const std::vector<float>& wall, uint32_t width, uint32_t height) {
    const ColourAndDepthImages made{
        make_image(VK_FORMAT_R32G32B32A32_SFLOAT, 0, width, height),
        make_image(VK_FORMAT_D32_SFLOAT, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, width, height)};
    make_staging(VkDeviceSize(width) * height * 16);
    std::memcpy(staging_data, wall.data(), wall.size() * sizeof(float));
    submit([&](VkCommandBuffer cmd) { record_draw_depth(cmd, made.depth.image, width, height); });
    return made;
  }
  // The depth tests' host: the bundled playbot from view 0 at width x height, and the wall it drew into
  // its depth buffer (the effects bench's plane, tilted through the scene) in the bench's convention.
  struct WallScene {
    GaussianScene scene;
    Camera camera;
    DepthConvention convention;
    std::vector<float> wall;
  };
  static WallScene wall_through_scene(uint32_t width, uint32_t height) {
    WallScene made;
    made.scene = load_scene(testing::bundled_playbot());
    made.camera = resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(0).camera,
                                int(width), int(height));
    made.convention = effects::bench_depth_convention();
    made.wall = effects::plane_through_scene(made.scene, made.camera, made.convention);
    return made;
  }
  // The host "draws" its depth: the staging buffer's floats into a D32 image, which ends in the layout a
  // host keeps a depth buffer in.
  void record_draw_depth(VkCommandBuffer cmd, VkImage depth, uint32_t width, uint32_t height) {
    layout_barrier(cmd, depth, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
    region.imageExtent = {width, height, 1};
    vkCmdCopyBufferToImage(cmd, staging, depth, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    layout_barrier(cmd, depth, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                   VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
  }
  // Copies an image (left in TRANSFER_SRC_OPTIMAL) into the staging buffer.
  void read_image(VkImage image, VkImageAspectFlags aspect, VkImageLayout layout, uint32_t width,
                  uint32_t height) {
    submit([&](VkCommandBuffer cmd) { record_read(cmd, image, aspect, layout, width, height, 0); });
  }
  // Records the copy of an image (left in TRANSFER_SRC_OPTIMAL) into the staging buffer at `offset`.
  void record_read(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout layout,
                   uint32_t width, uint32_t height, VkDeviceSize offset) {
    layout_barrier(cmd, image, aspect, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    VkBufferImageCopy region{};
    region.bufferOffset = offset;
    region.imageSubresource = {aspect, 0, 0, 1};
    region.imageExtent = {width, height, 1};
    vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging, 1, &region);
    VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0,
                         nullptr, 0, nullptr);
  }
  void release_host_objects() {
    vkQueueWaitIdle(queue);
    free_pending_command_buffers();
    for (VkSemaphore semaphore : semaphores) vkDestroySemaphore(device, semaphore, nullptr);
    semaphores.clear();
    if (staging_data) vkUnmapMemory(device, staging_memory);
    if (command_pool) vkDestroyCommandPool(device, command_pool, nullptr);
    if (staging) vkDestroyBuffer(device, staging, nullptr);
    if (staging_memory) vkFreeMemory(device, staging_memory, nullptr);
    for (const Image& image : images) {
      vkDestroyImage(device, image.image, nullptr);
      vkFreeMemory(device, image.memory, nullptr);
    }
    staging_data = nullptr;
    command_pool = VK_NULL_HANDLE;
    staging = VK_NULL_HANDLE;
    staging_memory = VK_NULL_HANDLE;
    images.clear();
  }
  VkBuffer staging = VK_NULL_HANDLE;
  VkDeviceMemory staging_memory = VK_NULL_HANDLE;
  void* staging_data = nullptr;
  VkCommandPool command_pool = VK_NULL_HANDLE;
  std::vector<Image> images;
  std::vector<VkSemaphore> semaphores;
  std::vector<VkCommandBuffer> pending_command_buffers;

  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t family = 0;
  bool float64 = false;
  // Enabled on the device where it has them; external() does not say so, as a host that did not would.
  bool independent_blend = false, rasterization_order = false;
  int messages = 0;
};

TEST_F(HostApplication, RendersOnTheHostDeviceIntoTheHostImage) {
  GaussianScene scene = load_scene(testing::bundled_playbot());
  Camera camera = resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(1).camera, 200, 120);
  RenderImage expected;
  {
    auto own = Renderer::create();
    own->set_scene(scene);
    expected = own->render(camera);
  }

  // The host's image and a host-visible buffer to read it back.
  VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ici.imageType = VK_IMAGE_TYPE_2D;
  ici.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  ici.extent = {200, 120, 1};
  ici.mipLevels = 1;
  ici.arrayLayers = 1;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  VkImage image = VK_NULL_HANDLE;
  HOST_CHECK(vkCreateImage(device, &ici, nullptr, &image));
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device, image, &req);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = memory_type(req.memoryTypeBits, 0);
  VkDeviceMemory image_memory = VK_NULL_HANDLE;
  HOST_CHECK(vkAllocateMemory(device, &mai, nullptr, &image_memory));
  HOST_CHECK(vkBindImageMemory(device, image, image_memory, 0));

  const VkDeviceSize bytes = 200 * 120 * 16;
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = bytes;
  bci.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  VkBuffer readback = VK_NULL_HANDLE;
  HOST_CHECK(vkCreateBuffer(device, &bci, nullptr, &readback));
  vkGetBufferMemoryRequirements(device, readback, &req);
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = memory_type(
      req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  VkDeviceMemory readback_memory = VK_NULL_HANDLE;
  HOST_CHECK(vkAllocateMemory(device, &mai, nullptr, &readback_memory));
  HOST_CHECK(vkBindBufferMemory(device, readback, readback_memory, 0));

  {
    auto renderer = create_renderer(external());
    renderer->set_scene(scene);
    ExternalImage target{image, 200, 120, VK_FORMAT_R32G32B32A32_SFLOAT, VK_IMAGE_LAYOUT_UNDEFINED};
    render_to_image(*renderer, camera, {}, target);
    EXPECT_GT(renderer->last_frame_stats().intersections, 0u);

    // Errors the host can make.
    ExternalImage wrong_size = target;
    wrong_size.width = 100;
    wrong_size.layout = VK_IMAGE_LAYOUT_GENERAL;
    EXPECT_THROW(render_to_image(*renderer, camera, {}, wrong_size), std::invalid_argument);
    ExternalImage wrong_format = target;
    wrong_format.format = VK_FORMAT_B8G8R8A8_UNORM;  // R8G8B8A8_UNORM is a supported target since issue 20
    EXPECT_THROW(render_to_image(*renderer, camera, {}, wrong_format), std::invalid_argument);

    // The same renderer also renders to host memory on the borrowed device.
    RenderImage via_buffers = renderer->render(camera);
    EXPECT_EQ(via_buffers.rgba, expected.rgba);
  }  // the renderer is gone; the host's device must still work

  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.queueFamilyIndex = family;
  VkCommandPool pool = VK_NULL_HANDLE;
  HOST_CHECK(vkCreateCommandPool(device, &pci, nullptr, &pool));
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = pool;
  cai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  HOST_CHECK(vkAllocateCommandBuffers(device, &cai, &cmd));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  HOST_CHECK(vkBeginCommandBuffer(cmd, &begin));
  VkImageMemoryBarrier to_src{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  to_src.oldLayout = VK_IMAGE_LAYOUT_GENERAL;  // an UNDEFINED image is left GENERAL
  to_src.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  to_src.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  to_src.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  to_src.srcQueueFamilyIndex = to_src.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  to_src.image = image;
  to_src.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                       0, nullptr, 1, &to_src);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {200, 120, 1};
  vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback, 1, &region);
  VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0,
                       nullptr, 0, nullptr);
  HOST_CHECK(vkEndCommandBuffer(cmd));
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  HOST_CHECK(vkQueueSubmit(queue, 1, &submit, VK_NULL_HANDLE));
  HOST_CHECK(vkQueueWaitIdle(queue));

  void* mapped = nullptr;
  HOST_CHECK(vkMapMemory(device, readback_memory, 0, bytes, 0, &mapped));
  std::vector<float> pixels(200 * 120 * 4);
  std::memcpy(pixels.data(), mapped, bytes);
  vkUnmapMemory(device, readback_memory);
  EXPECT_EQ(pixels, expected.rgba);

  vkDestroyCommandPool(device, pool, nullptr);
  vkDestroyBuffer(device, readback, nullptr);
  vkFreeMemory(device, readback_memory, nullptr);
  vkDestroyImage(device, image, nullptr);
  vkFreeMemory(device, image_memory, nullptr);
  EXPECT_EQ(messages, 0) << "validation messages on the host's instance";
}

// A host that drew a wall into its D32 depth buffer: the splats are cut by it, and their depth is
// written into the same buffer for what the host draws next.
TEST_F(HostApplication, DepthImageCutsTheSplatsAndReceivesTheirDepth) {
  constexpr uint32_t kWidth = 160, kHeight = 90;
  const auto [scene, camera, convention, wall] = wall_through_scene(kWidth, kHeight);

  const auto [colour, depth] = draw_wall(wall, kWidth, kHeight);

  RenderSettings settings;
  settings.host = HostDepth{convention, {}, true, 0.5f};
  RenderImage expected;
  {
    auto renderer = create_renderer(external());
    renderer->set_scene(scene);
    const ExternalImage target{colour.image, kWidth, kHeight, VK_FORMAT_R32G32B32A32_SFLOAT,
                               VK_IMAGE_LAYOUT_UNDEFINED};
    const ExternalDepthImage host_depth{depth.image, kWidth, kHeight, VK_FORMAT_D32_SFLOAT,
                                        VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    render_to_image(*renderer, camera, settings, target, host_depth);
    // What render() gives for the same wall in host memory.
    RenderSettings in_memory = settings;
    in_memory.host->depth = wall;
    expected = renderer->render(camera, in_memory);
    // Mistakes: no host settings, depth values given twice, an UNDEFINED depth image.
    EXPECT_THROW(render_to_image(*renderer, camera, {}, target, host_depth), std::invalid_argument);
    EXPECT_THROW(render_to_image(*renderer, camera, in_memory, target, host_depth), std::invalid_argument);
    ExternalDepthImage undefined = host_depth;
    undefined.layout = VK_IMAGE_LAYOUT_UNDEFINED;
    EXPECT_THROW(render_to_image(*renderer, camera, settings, target, undefined), std::invalid_argument);
    EXPECT_THROW(render_to_image(*renderer, camera, settings, target), std::invalid_argument);  // write_depth
  }

  // Read both images back as the host would.
  const auto [rgba, depth_after] = read_colour_and_depth(colour, depth, kWidth, kHeight);
  EXPECT_EQ(rgba, expected.rgba);
  EXPECT_EQ(depth_after, expected.host_depth);
  size_t nearer = 0;
  for (size_t i = 0; i < wall.size(); ++i) {
    EXPECT_LE(depth_after[i], wall[i]) << "pixel " << i;
    nearer += depth_after[i] < wall[i] ? 1u : 0u;
  }
  EXPECT_GT(nearer, wall.size() / 20) << "the splats wrote their depth at too few pixels to mean anything";

  release_host_objects();
  EXPECT_EQ(messages, 0) << "validation messages on the host's instance";
}

// The raster compositor on the host's device: the depth image, converted, is the draw's depth
// attachment; the image equals render()'s with the same surfaces in host memory. The host did not say
// it enabled independentBlend, which the raster's splat counts need: they are refused by name.
TEST_F(HostApplication, RasterCompositorTestsTheDepthImage) {
  constexpr uint32_t kWidth = 160, kHeight = 90;
  const auto [scene, camera, convention, wall] = wall_through_scene(kWidth, kHeight);
  const auto [colour, depth] = draw_wall(wall, kWidth, kHeight);

  RenderSettings settings;
  settings.compositor = Compositor::kRaster;
  settings.splat_count = false;
  settings.host = HostDepth{convention, {}, false, 0.5f};
  RenderImage expected, unhidden;
  {
    auto renderer = create_renderer(external());
    renderer->set_scene(scene);
    const ExternalImage target{colour.image, kWidth, kHeight, VK_FORMAT_R32G32B32A32_SFLOAT,
                               VK_IMAGE_LAYOUT_UNDEFINED};
    const ExternalDepthImage host_depth{depth.image, kWidth, kHeight, VK_FORMAT_D32_SFLOAT,
                                        VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    render_to_image(*renderer, camera, settings, target, host_depth);
    RenderSettings in_memory = settings;
    in_memory.host->depth = wall;
    expected = renderer->render(camera, in_memory);
    RenderSettings no_host = settings;
    no_host.host.reset();
    unhidden = renderer->render(camera, no_host);
    RenderSettings counted = in_memory;
    counted.splat_count = true;
    EXPECT_NE(testing::error_of<std::runtime_error>([&] {
                renderer->render(camera, counted);
              }).find("independentBlend"),
              std::string::npos);
  }
  const auto [rgba, depth_after] = read_colour_and_depth(colour, depth, kWidth, kHeight);
  EXPECT_EQ(rgba, expected.rgba);
  EXPECT_EQ(depth_after, wall);    // tested, never written
  EXPECT_NE(rgba, unhidden.rgba);  // the wall hides some of the scene

  release_host_objects();
  EXPECT_EQ(messages, 0) << "validation messages on the host's instance";
}

// The raster compositor's depth out on the host's device, into the host's depth image: the same as
// render()'s with the surfaces in host memory. It needs independentBlend and rasterization-order
// attachment access, which the host says it enabled; a host that did not say so is refused by name.
TEST_F(HostApplication, RasterCompositorWritesTheDepthOut) {
  constexpr uint32_t kWidth = 160, kHeight = 90;
  const auto [scene, camera, convention, wall] = wall_through_scene(kWidth, kHeight);
  const auto [colour, depth] = draw_wall(wall, kWidth, kHeight);
  ASSERT_TRUE(independent_blend && rasterization_order)
      << "lavapipe has independentBlend and VK_EXT_rasterization_order_attachment_access";

  RenderSettings settings;
  settings.compositor = Compositor::kRaster;
  settings.splat_count = false;
  settings.host = HostDepth{convention, {}, true, 0.5f};
  ExternalVulkanDevice without_order = external();
  without_order.independent_blend_enabled = true;
  ExternalVulkanDevice with_order = without_order;
  with_order.rasterization_order_attachment_access_enabled = true;
  RenderImage expected;
  {
    auto refused = create_renderer(without_order);
    refused->set_scene(scene);
    RenderSettings in_memory = settings;
    in_memory.host->depth = wall;
    EXPECT_NE(testing::error_of<std::runtime_error>([&] {
                refused->render(camera, in_memory);
              }).find("VK_EXT_rasterization_order_attachment_access"),
              std::string::npos);
    auto renderer = create_renderer(with_order);
    renderer->set_scene(scene);
    render_to_image(*renderer, camera, settings,
                    {colour.image, kWidth, kHeight, VK_FORMAT_R32G32B32A32_SFLOAT, VK_IMAGE_LAYOUT_UNDEFINED},
                    {depth.image, kWidth, kHeight, VK_FORMAT_D32_SFLOAT,
                     VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL});
    expected = renderer->render(camera, in_memory);
  }
  const auto [rgba, depth_after] = read_colour_and_depth(colour, depth, kWidth, kHeight);
  EXPECT_EQ(rgba, expected.rgba);
  EXPECT_EQ(depth_after, expected.host_depth);
  size_t splats = 0;
  for (size_t i = 0; i < wall.size(); ++i) splats += depth_after[i] != wall[i] ? 1 : 0;
  EXPECT_GT(splats, wall.size() / 10) << "the splats' depth out reaches the image";

  release_host_objects();
  EXPECT_EQ(messages, 0) << "validation messages on the host's instance";
}

// A depth image cannot be checked for NaNs on the host without reading it back: on the device a NaN
// means no surface at that pixel (every splat blends, as over a cleared infinite far plane), and the
// depth out keeps the NaN where the splats do not reach the threshold.
TEST_F(HostApplication, NanInTheDepthImageMeansNoSurface) {
  constexpr uint32_t kWidth = 160, kHeight = 90;
  auto [scene, camera, convention, wall] = wall_through_scene(kWidth, kHeight);
  std::vector<float> no_surface = wall;  // what the NaN rows mean, in host memory
  for (size_t i = 40 * kWidth; i < 50 * kWidth; ++i) {
    wall[i] = std::numeric_limits<float>::quiet_NaN();
    no_surface[i] = std::numeric_limits<float>::infinity();
  }
  const auto [colour, depth] = draw_wall(wall, kWidth, kHeight);

  RenderSettings settings;
  settings.host = HostDepth{convention, {}, true, 0.5f};
  auto renderer = create_renderer(external());
  renderer->set_scene(scene);
  render_to_image(
      *renderer, camera, settings,
      {colour.image, kWidth, kHeight, VK_FORMAT_R32G32B32A32_SFLOAT, VK_IMAGE_LAYOUT_UNDEFINED},
      {depth.image, kWidth, kHeight, VK_FORMAT_D32_SFLOAT, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL});
  RenderSettings in_memory = settings;
  in_memory.host->depth = no_surface;
  const RenderImage expected = renderer->render(camera, in_memory);

  const auto [rgba, depth_after] = read_colour_and_depth(colour, depth, kWidth, kHeight);
  EXPECT_EQ(rgba, expected.rgba);
  size_t kept_nan = 0;
  for (size_t i = 0; i < depth_after.size(); ++i) {
    if (std::isnan(wall[i]) && std::isinf(expected.host_depth[i])) {
      EXPECT_TRUE(std::isnan(depth_after[i])) << "pixel " << i;
      ++kept_nan;
    } else {
      EXPECT_EQ(depth_after[i], expected.host_depth[i]) << "pixel " << i;
    }
  }
  EXPECT_GT(kept_nan, 0u) << "no NaN pixel without splats: the test shows nothing of that case";
  renderer.reset();
  release_host_objects();
  EXPECT_EQ(messages, 0) << "validation messages on the host's instance";
}

// A device without float64 (here: the host says it did not enable it) converts the depth image in
// float32 (host_depth_fp32): within float rounding of the float64 conversion in host memory.
TEST_F(HostApplication, DepthImageConvertsInFloat32WithoutFloat64) {
  constexpr uint32_t kWidth = 160, kHeight = 90;
  const auto [scene, camera, convention, wall] = wall_through_scene(kWidth, kHeight);
  const auto [colour, depth] = draw_wall(wall, kWidth, kHeight);

  ExternalVulkanDevice without_float64 = external();
  without_float64.shader_float64_enabled = false;
  auto renderer = create_renderer(without_float64);
  renderer->set_scene(scene);
  RenderSettings settings;
  settings.host = HostDepth{convention, {}, true, 0.5f};
  render_to_image(
      *renderer, camera, settings,
      {colour.image, kWidth, kHeight, VK_FORMAT_R32G32B32A32_SFLOAT, VK_IMAGE_LAYOUT_UNDEFINED},
      {depth.image, kWidth, kHeight, VK_FORMAT_D32_SFLOAT, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL});
  RenderSettings in_memory = settings;
  in_memory.host->depth = wall;
  const RenderImage expected = renderer->render(camera, in_memory);

  const auto [rgba, depth_after] = read_colour_and_depth(colour, depth, kWidth, kHeight);
  // A splat whose depth lies within a float's rounding of the wall's may fall on the other side of it:
  // a few pixels may differ, by at most that splat's contribution.
  size_t differing = 0;
  double largest = 0, squares = 0;
  for (size_t i = 0; i < rgba.size(); ++i) {
    const double difference = std::abs(double(rgba[i]) - double(expected.rgba[i]));
    differing += difference > 0 ? 1u : 0u;
    largest = std::max(largest, difference);
    squares += difference * difference;
  }
  const double psnr = squares > 0 ? 10 * std::log10(double(rgba.size()) / squares) : INFINITY;
  std::printf("float32 conversion: %zu of %zu values differ, by at most %.3g; PSNR %.1f dB\n", differing,
              rgba.size(), largest, psnr);
  EXPECT_LE(differing, rgba.size() / 100);
  // In value too: a splat that changes sides lies within a float's rounding of the wall. Measured on
  // lavapipe: 8 values differ, by at most 5.8e-4, 107 dB over the image.
  EXPECT_LE(largest, 5e-3);
  EXPECT_GE(psnr, 90.0);
  size_t reached = 0;
  for (size_t i = 0; i < depth_after.size(); ++i) {
    EXPECT_NEAR(depth_after[i], expected.host_depth[i], 2e-6f * std::abs(expected.host_depth[i]) + 1e-7f)
        << "pixel " << i;
    reached += expected.host_depth[i] != wall[i] ? 1u : 0u;
  }
  EXPECT_GT(reached, depth_after.size() / 20);
  renderer.reset();
  release_host_objects();
  EXPECT_EQ(messages, 0) << "validation messages on the host's instance";
}

// Half-float and 8-bit colour images (UNORM and sRGB) hold the frame's RGBA rounded to their texels. The
// colours are sRGB-encoded display values already, so an _SRGB image gets the same bytes as a _UNORM one
// (docs/colour.md): encoding them again would wash out what a host samples.
TEST_F(HostApplication, RendersIntoHalfAndEightBitColourImages) {
  constexpr uint32_t kWidth = 96, kHeight = 64;
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const Camera camera =
      resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(2).camera, kWidth, kHeight);
  make_staging(VkDeviceSize(kWidth) * kHeight * 8);
  auto renderer = create_renderer(external());
  renderer->set_scene(scene);
  const std::vector<float> expected = renderer->render(camera).rgba;
  for (const VkFormat format :
       {VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R8G8B8A8_SRGB}) {
    const Image image = make_image(format, 0, kWidth, kHeight);
    render_to_image(*renderer, camera, {}, {image.image, kWidth, kHeight, format, VK_IMAGE_LAYOUT_UNDEFINED});
    read_image(image.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL, kWidth, kHeight);
    size_t off_by_one = 0;
    for (size_t i = 0; i < expected.size(); ++i) {
      const float value = expected[i];
      if (format == VK_FORMAT_R16G16B16A16_SFLOAT) {
        const float stored = half_to_float(static_cast<const uint16_t*>(staging_data)[i]);
        ASSERT_LE(std::abs(stored - value), std::max(std::abs(value) * 0x1p-11f, 0x1p-25f)) << "value " << i;
      } else {
        const double want = 255.0 * std::clamp(double(value), 0.0, 1.0);
        const int stored = static_cast<const uint8_t*>(staging_data)[i];
        ASSERT_LE(std::abs(stored - want), 0.5 + 1e-3) << "value " << i << " of format " << format;
        off_by_one += std::abs(stored - std::lround(want)) > 0 ? 1u : 0u;
      }
    }
    EXPECT_LE(off_by_one, expected.size() / 1000)
        << "format " << format;  // only ties may round the other way
  }
  EXPECT_THROW(
      render_to_image(*renderer, camera, {},
                      {images[0].image, kWidth, kHeight, VK_FORMAT_B8G8R8A8_UNORM, VK_IMAGE_LAYOUT_GENERAL}),
      std::invalid_argument);
  renderer.reset();
  release_host_objects();
  EXPECT_EQ(messages, 0) << "validation messages on the host's instance";
}

// A frame with colours far outside [0, 1] (a splat of SH DC 1e20 beside ordinary ones; finite in memory)
// copied into the host's images (issue 58): the half image holds the largest finite half (65,504) with the
// value's sign where the value passes half's range, never an infinity, and FrameStats::saturated counts
// those values; the 8-bit images clamp to [0, 1] as UNORM does; the float image is the frame itself.
TEST_F(HostApplication, HugeColoursSaturateInTheHostsHalfImageAndAreCounted) {
  constexpr uint32_t kWidth = 64, kHeight = 48;
  GaussianScene scene;
  for (int i = 0; i < 3; ++i) {
    const float dc = i == 1 ? 1e20f : 0.5f;
    scene.positions.insert(scene.positions.end(), {0.3f * float(i - 1), 0.0f, 3.0f + 0.03f * float(i)});
    scene.log_scales.insert(scene.log_scales.end(), {-1.5f, -1.5f, -1.5f});
    scene.rotations.insert(scene.rotations.end(), {1, 0, 0, 0});
    scene.opacity_logits.push_back(1.5f);
    scene.sh.insert(scene.sh.end(), {dc, dc, dc});
  }
  const Camera camera = testing::axis_camera(int(kWidth), int(kHeight), 60);
  make_staging(VkDeviceSize(kWidth) * kHeight * 16);
  auto renderer = create_renderer(external());
  renderer->set_scene(scene);
  const std::vector<float> expected = renderer->render(camera).rgba;
  size_t past_half = 0;
  for (const float value : expected) {
    ASSERT_TRUE(std::isfinite(value));
    past_half += std::abs(value) > 65504.0f;
  }
  ASSERT_GT(past_half, 0u) << "the case must pass half's range";
  for (const VkFormat format : {VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R8G8B8A8_UNORM,
                                VK_FORMAT_R32G32B32A32_SFLOAT}) {
    const Image image = make_image(format, 0, kWidth, kHeight);
    render_to_image(*renderer, camera, {}, {image.image, kWidth, kHeight, format, VK_IMAGE_LAYOUT_UNDEFINED});
    const SaturatedValues saturated = renderer->last_frame_stats().saturated;
    read_image(image.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL, kWidth, kHeight);
    for (size_t i = 0; i < expected.size(); ++i) {
      const float value = expected[i];
      if (format == VK_FORMAT_R16G16B16A16_SFLOAT) {
        const float stored = half_to_float(static_cast<const uint16_t*>(staging_data)[i]);
        ASSERT_TRUE(std::isfinite(stored)) << "value " << i << " (" << value << ")";
        if (std::abs(value) > 65504.0f)
          ASSERT_EQ(stored, std::copysign(65504.0f, value)) << "value " << i;
        else
          ASSERT_LE(std::abs(stored - value), std::max(std::abs(value) * 0x1p-11f, 0x1p-25f)) << "value " << i;
      } else if (format == VK_FORMAT_R8G8B8A8_UNORM) {
        const int stored = static_cast<const uint8_t*>(staging_data)[i];
        ASSERT_LE(std::abs(stored - 255.0 * std::clamp(double(value), 0.0, 1.0)), 0.5 + 1e-3) << "value " << i;
      } else {
        ASSERT_EQ(static_cast<const float*>(staging_data)[i], value) << "value " << i;
      }
    }
    const uint64_t want = format == VK_FORMAT_R16G16B16A16_SFLOAT ? past_half : 0;
    EXPECT_EQ(saturated.total(), want) << "format " << format << ": " << saturated.describe();
  }
  // A frame without waiting counts the same once it is waited for.
  const Image image = make_image(VK_FORMAT_R16G16B16A16_SFLOAT, 0, kWidth, kHeight);
  render_to_image(*renderer, camera, {},
                  {image.image, kWidth, kHeight, VK_FORMAT_R16G16B16A16_SFLOAT, VK_IMAGE_LAYOUT_UNDEFINED}, nullptr,
                  HostFrameSync{});
  wait_for_frame(*renderer);
  EXPECT_EQ(renderer->last_frame_stats().saturated.total(), past_half);
  renderer.reset();
  release_host_objects();
  EXPECT_EQ(messages, 0) << "validation messages on the host's instance";
}

// Depth of field a sample a frame, as a window shows a still view converging
// (RenderSettings::accumulate_samples): frames submitted without waiting (HostFrameSync), each adding one
// lens sample on the device, leave in the host's image the mean that render() makes of the same samples.
TEST_F(HostApplication, LensSamplesAccumulateFrameAfterFrameInTheHostsImage) {
  constexpr uint32_t kWidth = 96, kHeight = 64;
  constexpr int kSamples = 6;
  const GaussianScene scene = load_scene(testing::bundled_playbot());
  const Camera camera =
      resize_camera(load_cameras_json(testing::bundled_playbot_cameras()).at(2).camera, kWidth, kHeight);
  make_staging(VkDeviceSize(kWidth) * kHeight * 16);
  auto renderer = create_renderer(external());
  renderer->set_scene(scene);
  const Bounds bounds = compute_bounds(scene);
  const double focus = camera.to_camera({bounds.center[0], bounds.center[1], bounds.center[2]})[2];
  RenderSettings settings;
  settings.lens = {.aperture_diameter = 0.05 * focus,
                   .focus_distance = focus,
                   .samples = kSamples,
                   .pattern = SamplePattern::kSobol};
  const std::vector<float> expected = renderer->render(camera, settings).rgba;

  const Image image = make_image(VK_FORMAT_R32G32B32A32_SFLOAT, 0, kWidth, kHeight);
  const ExternalImage target{image.image, kWidth, kHeight, VK_FORMAT_R32G32B32A32_SFLOAT,
                             VK_IMAGE_LAYOUT_UNDEFINED};
  settings.accumulate_samples = true;
  for (int frame = 0; frame < kSamples; ++frame)
    render_to_image(*renderer, camera, settings, target, nullptr, HostFrameSync{});
  wait_for_frame(*renderer);
  EXPECT_EQ(renderer->last_frame_stats().accumulated_samples, uint32_t(kSamples));
  read_image(image.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL, kWidth, kHeight);
  std::vector<float> rgba(expected.size());
  std::memcpy(rgba.data(), staging_data, rgba.size() * sizeof(float));
  EXPECT_LE(testing::max_abs_difference(rgba, expected), 2e-5f);
  // The blocking form continues the same sums; any other frame ends them.
  render_to_image(*renderer, camera, settings, target);
  EXPECT_EQ(renderer->last_frame_stats().accumulated_samples, uint32_t(kSamples + 1));
  EXPECT_NE(rgba, renderer->render(camera).rgba);
  render_to_image(*renderer, camera, settings, target);
  EXPECT_EQ(renderer->last_frame_stats().accumulated_samples, 1u);
  renderer.reset();
  release_host_objects();
  EXPECT_EQ(messages, 0) << "validation messages on the host's instance";
}

// The splats inside the host's frame without a CPU stall: the host's submission that draws its depth
// signals `drawn`, the renderer's frame waits for it and signals `rendered`, and the host's read-back
// waits for that. Nothing waits on the CPU in between; the images equal the blocking path's to the bit.
TEST_F(HostApplication, FrameInsideTheHostsFrameWaitsForAndSignalsItsSemaphores) {
  constexpr uint32_t kWidth = 160, kHeight = 90;
  const auto [scene, camera, convention, wall] = wall_through_scene(kWidth, kHeight);
  const size_t pixels = size_t(kWidth) * kHeight;
  const VkDeviceSize colour_bytes = pixels * 16;

  const Image colour = make_image(VK_FORMAT_R32G32B32A32_SFLOAT, 0, kWidth, kHeight);
  const Image depth =
      make_image(VK_FORMAT_D32_SFLOAT, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, kWidth, kHeight);
  make_staging(colour_bytes + pixels * sizeof(float));
  std::memcpy(staging_data, wall.data(), pixels * sizeof(float));
  const VkSemaphore drawn = make_semaphore(), rendered = make_semaphore();
  submit_async([&](VkCommandBuffer cmd) { record_draw_depth(cmd, depth.image, kWidth, kHeight); },
               VK_NULL_HANDLE, drawn);

  RenderSettings settings;
  settings.host = HostDepth{convention, {}, true, 0.5f};
  auto renderer = create_renderer(external());
  renderer->set_scene(scene);
  const ExternalImage target{colour.image, kWidth, kHeight, VK_FORMAT_R32G32B32A32_SFLOAT,
                             VK_IMAGE_LAYOUT_UNDEFINED};
  const ExternalDepthImage host_depth{depth.image, kWidth, kHeight, VK_FORMAT_D32_SFLOAT,
                                      VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  const VkSemaphore waits[] = {drawn};
  const VkPipelineStageFlags wait_stages[] = {VK_PIPELINE_STAGE_TRANSFER_BIT};
  const VkSemaphore signals[] = {rendered};
  render_to_image(*renderer, camera, settings, target, &host_depth,
                  HostFrameSync{waits, wait_stages, {}, signals, {}});
  submit_async(
      [&](VkCommandBuffer cmd) {
        record_read(cmd, colour.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL, kWidth, kHeight,
                    0);
        record_read(cmd, depth.image, VK_IMAGE_ASPECT_DEPTH_BIT,
                    VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, kWidth, kHeight, colour_bytes);
      },
      rendered, VK_NULL_HANDLE);
  HOST_CHECK(vkQueueWaitIdle(queue));
  std::vector<float> rgba(pixels * 4), depth_after(pixels);
  std::memcpy(rgba.data(), staging_data, colour_bytes);
  std::memcpy(depth_after.data(), static_cast<const std::byte*>(staging_data) + colour_bytes,
              pixels * sizeof(float));

  wait_for_frame(*renderer);  // the frame's statistics
  const FrameStats& stats = renderer->last_frame_stats();
  EXPECT_TRUE(stats.complete);
  EXPECT_GT(stats.intersections, 0u);
  EXPECT_EQ(stats.submissions, 1);
  EXPECT_TRUE(std::any_of(stats.passes.begin(), stats.passes.end(),
                          [](const PassTiming& p) { return p.name == "host_depth_in"; }));

  RenderSettings in_memory = settings;
  in_memory.host->depth = wall;
  const RenderImage expected = renderer->render(camera, in_memory);
  EXPECT_EQ(rgba, expected.rgba);
  EXPECT_EQ(depth_after, expected.host_depth);
  EXPECT_NE(depth_after, wall) << "the splats wrote no depth";

  // A timeline semaphore, waited for on the CPU; no depth image. render() after it waits for the frame
  // by itself.
  const VkSemaphore timeline = make_semaphore(/*timeline=*/true);
  const uint64_t done_value = 1;
  render_to_image(*renderer, camera, {}, target, nullptr,
                  HostFrameSync{{}, {}, {}, {&timeline, 1}, {&done_value, 1}});
  VkSemaphoreWaitInfo wait_info{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
  wait_info.semaphoreCount = 1;
  wait_info.pSemaphores = &timeline;
  wait_info.pValues = &done_value;
  HOST_CHECK(vkWaitSemaphores(device, &wait_info, UINT64_MAX));
  read_image(colour.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL, kWidth, kHeight);
  std::memcpy(rgba.data(), staging_data, colour_bytes);
  EXPECT_EQ(rgba, renderer->render(camera).rgba);

  // Mistakes: a stage or value count that is not one per semaphore, depth out without a depth image.
  const VkPipelineStageFlags two_stages[] = {VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT};
  EXPECT_THROW(
      render_to_image(*renderer, camera, {}, target, nullptr, HostFrameSync{waits, two_stages, {}, {}, {}}),
      std::invalid_argument);
  const uint64_t two_values[] = {1, 2};
  EXPECT_THROW(
      render_to_image(*renderer, camera, {}, target, nullptr, HostFrameSync{{}, {}, {}, signals, two_values}),
      std::invalid_argument);
  EXPECT_THROW(render_to_image(*renderer, camera, settings, target, nullptr, HostFrameSync{}),
               std::invalid_argument);
  renderer.reset();
  release_host_objects();
  EXPECT_EQ(messages, 0) << "validation messages on the host's instance";
}

// The frame recorded into the host's own command buffer, between the host's commands: the host draws
// its depth before it and reads both images back after it, in one submission that signals the host's
// timeline semaphore. The images equal the blocking path's to the bit.
TEST_F(HostApplication, FrameRecordedIntoTheHostsCommandBuffer) {
  constexpr uint32_t kWidth = 160, kHeight = 90;
  const auto [scene, camera, convention, wall] = wall_through_scene(kWidth, kHeight);
  const size_t pixels = size_t(kWidth) * kHeight;
  const VkDeviceSize colour_bytes = pixels * 16;
  const Image colour = make_image(VK_FORMAT_R32G32B32A32_SFLOAT, 0, kWidth, kHeight);
  const Image depth =
      make_image(VK_FORMAT_D32_SFLOAT, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, kWidth, kHeight);
  make_staging(colour_bytes + pixels * sizeof(float));
  std::memcpy(staging_data, wall.data(), pixels * sizeof(float));
  const VkSemaphore timeline = make_semaphore(/*timeline=*/true);
  auto begin_commands = [&] {
    VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cai.commandPool = pool();
    cai.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    EXPECT_EQ(vkAllocateCommandBuffers(device, &cai, &cmd), VK_SUCCESS);
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    EXPECT_EQ(vkBeginCommandBuffer(cmd, &begin), VK_SUCCESS);
    pending_command_buffers.push_back(cmd);
    return cmd;
  };
  auto submit_signalling = [&](VkCommandBuffer cmd, uint64_t value) {
    ASSERT_EQ(vkEndCommandBuffer(cmd), VK_SUCCESS);
    VkTimelineSemaphoreSubmitInfo values{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
    values.signalSemaphoreValueCount = 1;
    values.pSignalSemaphoreValues = &value;
    VkSubmitInfo info{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    info.pNext = &values;
    info.commandBufferCount = 1;
    info.pCommandBuffers = &cmd;
    info.signalSemaphoreCount = 1;
    info.pSignalSemaphores = &timeline;
    ASSERT_EQ(vkQueueSubmit(queue, 1, &info, VK_NULL_HANDLE), VK_SUCCESS);
  };

  RenderSettings settings;
  settings.host = HostDepth{convention, {}, true, 0.5f};
  auto renderer = create_renderer(external());
  renderer->set_scene(scene);
  const ExternalImage target{colour.image, kWidth, kHeight, VK_FORMAT_R32G32B32A32_SFLOAT,
                             VK_IMAGE_LAYOUT_UNDEFINED};
  const ExternalDepthImage host_depth{depth.image, kWidth, kHeight, VK_FORMAT_D32_SFLOAT,
                                      VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkCommandBuffer cmd = begin_commands();
  record_draw_depth(cmd, depth.image, kWidth, kHeight);
  render_to_image(*renderer, camera, settings, target, &host_depth, HostCommandBuffer{cmd, timeline, 1});
  record_read(cmd, colour.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL, kWidth, kHeight, 0);
  record_read(cmd, depth.image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
              kWidth, kHeight, colour_bytes);
  submit_signalling(cmd, 1);
  wait_for_frame(*renderer);  // waits for the timeline to reach 1
  std::vector<float> rgba(pixels * 4), depth_after(pixels);
  std::memcpy(rgba.data(), staging_data, colour_bytes);
  std::memcpy(depth_after.data(), static_cast<const std::byte*>(staging_data) + colour_bytes,
              pixels * sizeof(float));
  EXPECT_TRUE(renderer->last_frame_stats().complete);
  EXPECT_GT(renderer->last_frame_stats().intersections, 0u);
  EXPECT_EQ(renderer->last_frame_stats().submissions, 0);  // the host's

  RenderSettings in_memory = settings;
  in_memory.host->depth = wall;
  const RenderImage expected = renderer->render(camera, in_memory);
  EXPECT_EQ(rgba, expected.rgba);
  EXPECT_EQ(depth_after, expected.host_depth);

  // The stochastic compositor's 100 samples, which its own submissions split in two, fit one command
  // buffer of the host's.
  RenderSettings stochastic;
  stochastic.compositor = Compositor::kStochastic;
  stochastic.stochastic.frames = 100;
  cmd = begin_commands();
  const ExternalImage again{colour.image, kWidth, kHeight, VK_FORMAT_R32G32B32A32_SFLOAT,
                            VK_IMAGE_LAYOUT_UNDEFINED};
  render_to_image(*renderer, camera, stochastic, again, nullptr, HostCommandBuffer{cmd, timeline, 2});
  record_read(cmd, colour.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL, kWidth, kHeight, 0);
  submit_signalling(cmd, 2);
  wait_for_frame(*renderer);
  std::memcpy(rgba.data(), staging_data, colour_bytes);
  EXPECT_EQ(rgba, renderer->render(camera, stochastic).rgba);

  // Refused before anything is recorded: a host sort strategy, a null command buffer or semaphore.
  cmd = begin_commands();
  RenderSettings host_sort;
  host_sort.sort = "cpu-radix";
  EXPECT_THROW(
      render_to_image(*renderer, camera, host_sort, again, nullptr, HostCommandBuffer{cmd, timeline, 3}),
      std::invalid_argument);
  EXPECT_THROW(
      render_to_image(*renderer, camera, {}, again, nullptr, HostCommandBuffer{VK_NULL_HANDLE, timeline, 3}),
      std::invalid_argument);
  EXPECT_THROW(
      render_to_image(*renderer, camera, {}, again, nullptr, HostCommandBuffer{cmd, VK_NULL_HANDLE, 3}),
      std::invalid_argument);
  // Nothing was recorded: the same command buffer takes a frame, and the renderer destroyed while it
  // may still run waits for the timeline first (else the validation layer reports buffers in use).
  render_to_image(*renderer, camera, {}, again, nullptr, HostCommandBuffer{cmd, timeline, 3});
  submit_signalling(cmd, 3);
  renderer.reset();
  release_host_objects();
  EXPECT_EQ(messages, 0) << "validation messages on the host's instance";
}

// A submitted frame cannot re-render: one that wants more (tile, Gaussian) pairs than the key buffers
// hold is drawn with those that fit and says so, and the next frame, with grown buffers, is whole.
TEST_F(HostApplication, SubmittedFrameThatOutgrowsTheBuffersSaysSoAndTheNextIsWhole) {
  constexpr uint32_t kWidth = 640, kHeight = 480;
  GaussianScene big;  // 120 splats over all 1,200 tiles: 144,000 pairs, the key buffers start at 131,072
  big.sh_degree = 0;
  for (int i = 0; i < 120; ++i) {
    big.positions.insert(big.positions.end(), {0.01f * float(i % 40), 0.0f, 2.0f + 0.01f * float(i)});
    big.log_scales.insert(big.log_scales.end(), {1.0f, 1.0f, 1.0f});
    big.rotations.insert(big.rotations.end(), {1, 0, 0, 0});
    big.opacity_logits.push_back(-4.0f);
    big.sh.insert(big.sh.end(), {0.5f, 0.2f, -0.3f});
  }
  const Camera camera = look_at_camera({0, 0, 0}, {0, 0, 1}, {0, -1, 0}, kWidth, kHeight, 60);
  const Image colour = make_image(VK_FORMAT_R32G32B32A32_SFLOAT, 0, kWidth, kHeight);
  make_staging(VkDeviceSize(kWidth) * kHeight * 16);
  auto renderer = create_renderer(external());
  renderer->set_scene(big);
  // UNDEFINED: the read-back leaves the image in TRANSFER_SRC_OPTIMAL, and the frame overwrites it all.
  const ExternalImage target{colour.image, kWidth, kHeight, VK_FORMAT_R32G32B32A32_SFLOAT,
                             VK_IMAGE_LAYOUT_UNDEFINED};
  std::vector<float> frames[2];
  bool complete[2] = {};
  for (int i = 0; i < 2; ++i) {
    render_to_image(*renderer, camera, {}, target, nullptr, HostFrameSync{});
    wait_for_frame(*renderer);
    complete[i] = renderer->last_frame_stats().complete;
    read_image(colour.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL, kWidth, kHeight);
    frames[i].resize(size_t(kWidth) * kHeight * 4);
    std::memcpy(frames[i].data(), staging_data, frames[i].size() * sizeof(float));
  }
  const RenderImage whole = renderer->render(camera);
  EXPECT_EQ(renderer->last_frame_stats().retries, 0) << "the submitted frames grew the buffers already";
  EXPECT_FALSE(complete[0]);
  EXPECT_NE(frames[0], whole.rgba);
  EXPECT_TRUE(complete[1]);
  EXPECT_EQ(frames[1], whole.rgba);
  renderer.reset();
  release_host_objects();
  EXPECT_EQ(messages, 0) << "validation messages on the host's instance";
}

TEST_F(HostApplication, RejectsMissingHandles) {
  ExternalVulkanDevice missing = external();
  missing.queue = VK_NULL_HANDLE;
  EXPECT_THROW(create_renderer(missing), std::invalid_argument);
  ExternalVulkanDevice bad_family = external();
  bad_family.queue_family = 99;
  EXPECT_THROW(create_renderer(bad_family), std::invalid_argument);
}

}  // namespace
}  // namespace tilesplat
