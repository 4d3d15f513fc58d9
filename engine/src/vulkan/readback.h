// Reading a device buffer back to the host: straight from its mapping when it is host-visible, else
// through a staging buffer and a copy the device finishes before it returns.
#pragma once
#include <cstring>
#include <vector>

#include "vulkan/buffer.h"
#include "vulkan/context.h"

namespace tilesplat::vk {

// The first `count` values of `buffer`, into `out` (resized to count).
template <typename T>
void read_buffer(Context& ctx, const Buffer& buffer, std::vector<T>& out, size_t count) {
  out.resize(count);
  if (count == 0) return;  // memcpy must not see the null data() of an empty vector
  if (buffer.mapped()) {
    std::memcpy(out.data(), buffer.mapped(), count * sizeof(T));
    return;
  }
  Buffer staging(ctx, count * sizeof(T), MemoryUse::Readback, buffer.name() + " (readback)");
  ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, 0, count * sizeof(T)};
    vkCmdCopyBuffer(cmd, buffer.handle(), staging.handle(), 1, &region);
  });
  std::memcpy(out.data(), staging.mapped(), count * sizeof(T));
}

}  // namespace tilesplat::vk
