// The key sort as a swappable strategy. Every strategy must produce the same order: ascending 64-bit
// keys, equal keys in their input order (the key emission writes them in Gaussian index order).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "passes/key_emission_pass.h"
#include "vulkan/buffer.h"
#include "vulkan/context.h"

namespace tilesplat {

struct SortInput {
  KeyBuffers& keys;           // input in keys/values; keys_alt/values_alt are scratch of equal size
  const vk::Buffer& counters; // COUNTER_SORT_COUNT holds this frame's key count (set on the GPU)
  uint32_t key_bits = 64;     // only the low key_bits bits vary; higher bits are zero
};

class SortStrategy {
 public:
  virtual ~SortStrategy() = default;
  virtual std::string name() const = 0;
  // Records the sort. Returns true when the sorted result is in keys_alt/values_alt rather than
  // keys/values. The count is read on the GPU; the recording may not depend on it.
  virtual bool record(VkCommandBuffer cmd, SortInput& input) = 0;
  // Scratch memory the strategy holds, for the memory report.
  virtual uint64_t device_bytes() const = 0;
};

std::vector<std::string> available_sort_strategies();
// Throws std::invalid_argument naming the strategy and the valid names.
std::unique_ptr<SortStrategy> make_sort_strategy(const std::string& name, vk::Context& ctx);

}  // namespace tilesplat
