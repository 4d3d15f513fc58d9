// Key/value pairs for a sort, double-buffered for the sort's ping-pong.
#pragma once

#include <cstdint>

#include "vulkan/buffer.h"

namespace tilesplat {

struct KeyBuffers {
  vk::Buffer keys, values, keys_alt, values_alt;  // uint64_t keys, uint32_t values
  uint32_t capacity = 0;
};

}  // namespace tilesplat
