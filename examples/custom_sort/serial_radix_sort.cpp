#include "serial_radix_sort.h"

#include <stdexcept>
#include <string>

#include "count_spirv.h"
#include "scan_spirv.h"
#include "scatter_spirv.h"

namespace {

constexpr uint32_t kChunk = 256;  // pairs per invocation: CHUNK in shaders/common.glsl
constexpr uint32_t kRadix = 256;
constexpr uint32_t kWorkgroup = 64;  // local_size_x of count.comp and scatter.comp

// The push constants of shaders/common.glsl.
struct Push {
  VkDeviceAddress keys_in, values_in, keys_out, values_out, counts, count;
  uint32_t shift, wide, chunk_capacity, pad;
};

void check(VkResult result, const char* what) {
  if (result != VK_SUCCESS)
    throw std::runtime_error(std::string("serial-radix: ") + what + " failed (VkResult " +
                             std::to_string(result) + ")");
}

// A full barrier between two of the sort's passes: what one wrote, the next reads.
void barrier(VkCommandBuffer cmd) {
  VkMemoryBarrier memory{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  memory.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  memory.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1,
                       &memory, 0, nullptr, 0, nullptr);
}

template <size_t N>
VkPipeline make_pipeline(VkDevice device, VkPipelineLayout layout, const uint32_t (&spirv)[N]) {
  VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  module_info.codeSize = sizeof(spirv);
  module_info.pCode = spirv;
  VkShaderModule module = VK_NULL_HANDLE;
  check(vkCreateShaderModule(device, &module_info, nullptr, &module), "vkCreateShaderModule");
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = "main";
  info.layout = layout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  const VkResult result = vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline);
  vkDestroyShaderModule(device, module, nullptr);
  check(result, "vkCreateComputePipelines");
  return pipeline;
}

uint32_t device_local_memory_type(VkPhysicalDevice physical, uint32_t allowed) {
  VkPhysicalDeviceMemoryProperties properties;
  vkGetPhysicalDeviceMemoryProperties(physical, &properties);
  for (uint32_t i = 0; i < properties.memoryTypeCount; ++i)
    if ((allowed & (1u << i)) &&
        (properties.memoryTypes[i].propertyFlags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT))
      return i;
  throw std::runtime_error("serial-radix: no device-local memory type for the counts buffer");
}

}  // namespace

SerialRadixSort::SerialRadixSort(const tilesplat::SortDevice& device) : device_(device) {
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(Push)};
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.pushConstantRangeCount = 1;
  layout_info.pPushConstantRanges = &range;
  check(vkCreatePipelineLayout(device_.device, &layout_info, nullptr, &layout_), "vkCreatePipelineLayout");
  try {
    pipelines_[0] = make_pipeline(device_.device, layout_, kcount_spirv);
    pipelines_[1] = make_pipeline(device_.device, layout_, kscan_spirv);
    pipelines_[2] = make_pipeline(device_.device, layout_, kscatter_spirv);
  } catch (...) {
    destroy();  // a constructor that throws runs no destructor: release what was made
    throw;
  }
}

SerialRadixSort::~SerialRadixSort() {
  destroy();
}

void SerialRadixSort::destroy() {
  release_counts();
  for (VkPipeline& pipeline : pipelines_) {
    if (pipeline) vkDestroyPipeline(device_.device, pipeline, nullptr);
    pipeline = VK_NULL_HANDLE;
  }
  if (layout_) vkDestroyPipelineLayout(device_.device, layout_, nullptr);
  layout_ = VK_NULL_HANDLE;
}

void SerialRadixSort::release_counts() {
  if (counts_) vkDestroyBuffer(device_.device, counts_, nullptr);
  if (counts_memory_) vkFreeMemory(device_.device, counts_memory_, nullptr);
  counts_ = VK_NULL_HANDLE;
  counts_memory_ = VK_NULL_HANDLE;
  counts_bytes_ = 0;
  chunk_capacity_ = 0;
}

// reserve() runs outside recording, while no sort of this strategy is in flight, so the old counts
// buffer may be destroyed here.
void SerialRadixSort::reserve(uint32_t max_keys) {
  const uint32_t chunks = (max_keys + kChunk - 1) / kChunk;
  if (chunks <= chunk_capacity_ && counts_) return;
  release_counts();
  const uint32_t capacity = chunks > 0 ? chunks : 1;
  VkBufferCreateInfo buffer_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  buffer_info.size = VkDeviceSize(kRadix) * capacity * sizeof(uint32_t);
  buffer_info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  check(vkCreateBuffer(device_.device, &buffer_info, nullptr, &counts_), "vkCreateBuffer");
  VkMemoryRequirements requirements;
  vkGetBufferMemoryRequirements(device_.device, counts_, &requirements);
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
  allocate.allocationSize = requirements.size;
  allocate.memoryTypeIndex = device_local_memory_type(device_.physical_device, requirements.memoryTypeBits);
  check(vkAllocateMemory(device_.device, &allocate, nullptr, &counts_memory_), "vkAllocateMemory");
  check(vkBindBufferMemory(device_.device, counts_, counts_memory_, 0), "vkBindBufferMemory");
  VkBufferDeviceAddressInfo address{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  address.buffer = counts_;
  counts_address_ = vkGetBufferDeviceAddress(device_.device, &address);
  counts_bytes_ = requirements.size;
  chunk_capacity_ = capacity;
}

bool SerialRadixSort::record(VkCommandBuffer cmd, const tilesplat::SortBuffers& buffers) {
  if (buffers.capacity > uint64_t(chunk_capacity_) * kChunk)
    throw std::logic_error("serial-radix: reserve() was not called for " + std::to_string(buffers.capacity) +
                           " keys");
  const uint32_t groups = (chunk_capacity_ + kWorkgroup - 1) / kWorkgroup;
  const uint32_t passes = (buffers.key_bits + 7) / 8;
  bool in_alt = false;
  for (uint32_t pass = 0; pass < passes; ++pass) {
    Push push{};
    push.keys_in = in_alt ? buffers.keys_alt_address : buffers.keys_address;
    push.values_in = in_alt ? buffers.values_alt_address : buffers.values_address;
    push.keys_out = in_alt ? buffers.keys_address : buffers.keys_alt_address;
    push.values_out = in_alt ? buffers.values_address : buffers.values_alt_address;
    push.counts = counts_address_;
    push.count = buffers.count_address;
    push.shift = pass * 8;
    push.wide = buffers.key_bytes == 8 ? 1 : 0;
    push.chunk_capacity = chunk_capacity_;
    for (size_t p = 0; p < pipelines_.size(); ++p) {
      vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelines_[p]);
      vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
      vkCmdDispatch(cmd, p == 1 ? 1 : groups, 1, 1);  // the scan is one workgroup
      if (p + 1 < pipelines_.size()) barrier(cmd);
    }
    if (pass + 1 < passes) barrier(cmd);
    in_alt = !in_alt;
  }
  return in_alt;
}
