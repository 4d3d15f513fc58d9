// Key/value pairs for a sort, double-buffered for the sort's ping-pong.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "vulkan/buffer.h"
#include "vulkan/compute_pipeline.h"
#include "vulkan/context.h"

namespace tilesplat {

struct KeyBuffers {
  vk::Buffer keys, values, keys_alt, values_alt;  // keys of key_bytes() each, uint32_t values
  uint32_t capacity = 0;
  // Keys are 32-bit words when every key fits in 32 bits (both sorts of a frame: view depth bits and
  // tile ids), 64-bit otherwise. The narrow layout halves the key traffic of every sort pass.
  bool wide_keys = true;

  uint32_t key_bytes() const { return wide_keys ? 8 : 4; }

  // Device buffers for `capacity` pairs of keys up to key_bits wide; `name` starts each buffer's
  // name ("depth keys", ...).
  static KeyBuffers allocate(vk::Context& ctx, uint32_t capacity, uint32_t key_bits, const std::string& name) {
    KeyBuffers kb;
    kb.wide_keys = key_bits > 32;
    const VkDeviceSize key_bytes = VkDeviceSize(capacity) * kb.key_bytes();
    const VkDeviceSize value_bytes = VkDeviceSize(capacity) * sizeof(uint32_t);
    kb.keys = vk::Buffer(ctx, key_bytes, vk::MemoryUse::Device, name + " keys");
    kb.keys_alt = vk::Buffer(ctx, key_bytes, vk::MemoryUse::Device, name + " keys (ping-pong)");
    kb.values = vk::Buffer(ctx, value_bytes, vk::MemoryUse::Device, name + " values");
    kb.values_alt = vk::Buffer(ctx, value_bytes, vk::MemoryUse::Device, name + " values (ping-pong)");
    kb.capacity = capacity;
    return kb;
  }

  uint64_t bytes() const { return keys.size() + values.size() + keys_alt.size() + values_alt.size(); }

  // One pass of a ping-pong sort: it reads the pair the previous pass wrote (keys/values first) and
  // writes the other.
  struct Pass {
    const vk::Buffer &keys_in, &values_in, &keys_out, &values_out;
  };
  Pass pass(bool from_alt) const {
    return from_alt ? Pass{keys_alt, values_alt, keys, values} : Pass{keys, values, keys_alt, values_alt};
  }

  // The texel-buffer views of a pass for the sorts' CPU-driver variants (compute/sort_key_texels.glsl):
  // keys and values in; narrow keys, wide keys and values out, with `unused` (any small buffer) in the
  // key width the pass does not write. Empty where a buffer has more texels than the device allows.
  std::vector<VkBufferView> texel_views(bool from_alt, const vk::Buffer& unused) const {
    const Pass p = pass(from_alt);
    const VkFormat key_format = wide_keys ? VK_FORMAT_R32G32_UINT : VK_FORMAT_R32_UINT;
    return vk::complete_views({p.keys_in.texel_view(key_format, key_bytes()),
                               p.values_in.texel_view(VK_FORMAT_R32_UINT, 4),
                               (wide_keys ? unused : p.keys_out).texel_view(VK_FORMAT_R32_UINT, 4),
                               (wide_keys ? p.keys_out : unused).texel_view(VK_FORMAT_R32G32_UINT, 8),
                               p.values_out.texel_view(VK_FORMAT_R32_UINT, 4)});
  }
  // The descriptor types of those views, in binding order.
  static const std::vector<VkDescriptorType>& texel_bindings() {
    static const std::vector<VkDescriptorType> types = {
        VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER,
        VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER,
        VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER};
    return types;
  }

  // Host-side keys in and out of this layout (the caller guarantees narrow keys fit 32 bits).
  std::vector<uint8_t> pack_keys(const std::vector<uint64_t>& host) const {
    std::vector<uint8_t> bytes(host.size() * key_bytes());
    for (size_t i = 0; i < host.size(); ++i) {
      if (wide_keys) {
        std::memcpy(bytes.data() + i * 8, &host[i], 8);
      } else {
        const uint32_t narrow = uint32_t(host[i]);
        std::memcpy(bytes.data() + i * 4, &narrow, 4);
      }
    }
    return bytes;
  }
  std::vector<uint64_t> unpack_keys(const void* data, size_t count) const {
    std::vector<uint64_t> host(count);
    const auto* bytes = static_cast<const uint8_t*>(data);
    for (size_t i = 0; i < count; ++i) {
      if (wide_keys) {
        std::memcpy(&host[i], bytes + i * 8, 8);
      } else {
        uint32_t narrow;
        std::memcpy(&narrow, bytes + i * 4, 4);
        host[i] = narrow;
      }
    }
    return host;
  }
};

}  // namespace tilesplat
