// The key sort as a swappable strategy. A frame sorts twice with it: the Gaussians by view depth,
// then the (tile, Gaussian) pairs by tile. Every strategy must produce the same order: ascending
// 64-bit keys, equal keys in their input order (a stable sort), which is what makes the two sorts
// together equal to one sort by (tile, depth, Gaussian index). The one exception says so with
// exact(): cpu-radix16 orders by 16-bit quantized depths, stably.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "passes/key_buffers.h"
#include "sort/frame_sort_plan.h"
#include "vulkan/buffer.h"
#include "vulkan/command_stream.h"
#include "vulkan/context.h"

namespace tilesplat {

struct SortInput {
  KeyBuffers& keys;              // input in keys/values; keys_alt/values_alt are scratch of equal size
  const vk::Buffer& state;       // holds this sort's SortState (frame_counters.h) at state_offset;
  VkDeviceSize state_offset;     //   its count is set on the GPU before the sort runs. Host-visible:
                                 //   a strategy that sorts on the host reads it after a flush.
  uint32_t key_bits = 64;        // only the low key_bits bits vary; higher bits are zero
  // The low 32 key bits are the bits of a positive float (a view depth), so that a strategy that
  // quantizes depths (cpu-radix16) can do it linearly in depth; false for plain integer keys.
  bool depth_in_low_bits = false;
};


class SortStrategy {
 public:
  virtual ~SortStrategy() = default;
  virtual std::string name() const = 0;
  // Sizes the strategy's scratch for sorts of up to max_keys keys. Called outside command buffer
  // recording: a frame records two sorts, and scratch replaced between them would be freed while
  // the first one still uses it.
  virtual void reserve(uint32_t max_keys) = 0;
  // Records the sort into the stream (input.keys.capacity <= the reserved size). Returns true when
  // the sorted result is in keys_alt/values_alt rather than keys/values. The count is set on the
  // GPU; a GPU strategy's recording may not depend on it (a host strategy flushes and reads it).
  virtual bool record(vk::CommandStream& stream, SortInput& input) = 0;
  virtual FrameSortPlan frame_plan() const { return FrameSortPlan::kDepthThenTile; }
  // False for a strategy that orders by an approximation of the keys (cpu-radix16's 16-bit depths):
  // its order, and so its images, differ from the exact strategies'.
  virtual bool exact() const { return true; }
  // Scratch memory the strategy holds, for the memory report.
  virtual uint64_t device_bytes() const = 0;
  // Times this object's sorts stopped waiting on another workgroup and took their slower fallback
  // path (onesweep's look-back), over its life. 0 for a strategy that never waits. Read it once the
  // recorded sorts have finished.
  virtual uint64_t stall_fallbacks() const { return 0; }
  // True for a strategy that sorts on the host in the middle of the frame (CommandStream::flush): its
  // frame cannot be recorded into a host application's command buffer.
  virtual bool sorts_on_host() const { return false; }
};

// Every strategy by name: the built-in ones, then those added at run time. Thread-safe.
std::vector<std::string> available_sort_strategies();
using SortStrategyMaker = std::function<std::unique_ptr<SortStrategy>(vk::Context&)>;
// Adds a strategy after the built-in ones (tilesplat::register_sort_strategy). Thread-safe. Throws
// std::invalid_argument for an empty name, one with a comma or whitespace, or one already taken.
void add_sort_strategy(const std::string& name, bool exact, SortStrategyMaker make);
// Removes a strategy added at run time (tilesplat::ScopedSortStrategy); the built-in ones stay, and an
// unknown name is ignored. Thread-safe.
void remove_sort_strategy(const std::string& name);
// Throws std::invalid_argument naming the strategy and the valid names.
std::unique_ptr<SortStrategy> make_sort_strategy(const std::string& name, vk::Context& ctx);
// SortStrategy::exact() of a strategy, without a device to make it on. Throws like make_sort_strategy.
bool sort_strategy_exact(const std::string& name);

}  // namespace tilesplat
