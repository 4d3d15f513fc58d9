// Key/value pairs for a sort, double-buffered for the sort's ping-pong.
#pragma once

#include <cstdint>
#include <string>

#include "vulkan/buffer.h"

namespace tilesplat {

struct KeyBuffers {
  vk::Buffer keys, values, keys_alt, values_alt;  // uint64_t keys, uint32_t values
  uint32_t capacity = 0;

  // Device buffers for `capacity` pairs; `name` starts each buffer's name ("depth keys", ...).
  static KeyBuffers allocate(vk::Context& ctx, uint32_t capacity, const std::string& name) {
    KeyBuffers kb;
    kb.keys = vk::Buffer(ctx, VkDeviceSize(capacity) * sizeof(uint64_t), vk::MemoryUse::Device, name + " keys");
    kb.keys_alt = vk::Buffer(ctx, VkDeviceSize(capacity) * sizeof(uint64_t), vk::MemoryUse::Device,
                             name + " keys (ping-pong)");
    kb.values = vk::Buffer(ctx, VkDeviceSize(capacity) * sizeof(uint32_t), vk::MemoryUse::Device, name + " values");
    kb.values_alt = vk::Buffer(ctx, VkDeviceSize(capacity) * sizeof(uint32_t), vk::MemoryUse::Device,
                               name + " values (ping-pong)");
    kb.capacity = capacity;
    return kb;
  }

  uint64_t bytes() const { return keys.size() + values.size() + keys_alt.size() + values_alt.size(); }
};

}  // namespace tilesplat
