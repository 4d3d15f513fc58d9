// What the tests that drive a sort strategy directly share: one validated Vulkan context, key
// generators, a run of a strategy on keys (as a frame runs it: count in a SortState block), and the
// check of its order against the expected one.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "passes/frame_counters.h"
#include "passes/key_buffers.h"
#include "sort/sort_strategy.h"
#include "vulkan/buffer.h"
#include "vulkan/context.h"

namespace tilesplat::testing {

vk::Context& sort_test_context();

// A device buffer's first `count` elements, through a staging copy.
template <typename T>
std::vector<T> read_back(const vk::Buffer& buffer, size_t count) {
  std::vector<T> out(count);
  if (count == 0) return out;
  vk::Context& ctx = sort_test_context();
  vk::Buffer staging(ctx, count * sizeof(T), vk::MemoryUse::Readback, "test readback");
  ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, 0, count * sizeof(T)};
    vkCmdCopyBuffer(cmd, buffer.handle(), staging.handle(), 1, &region);
  });
  std::memcpy(out.data(), staging.mapped(), count * sizeof(T));
  return out;
}

// The payload of input position i: a bijection that does not follow the input order, as in the
// frame's tile sort (whose values are Gaussian indices in depth order). A strategy that broke ties
// by value instead of by input position would be caught.
uint32_t payload(uint32_t position);
uint32_t position_of(uint32_t value);

// Uniform keys of `bits` bits; with `distinct` > 0, drawn from that many values (many equal keys).
std::vector<uint64_t> random_keys(size_t n, uint32_t bits, uint64_t seed, uint64_t distinct = 0);
// The input positions in std::stable_sort's order of the keys.
std::vector<uint32_t> stable_order(const std::vector<uint64_t>& keys);

// Keys (with payload(position) values) in key buffers of max(capacity, n, 1) pairs, and a
// FrameCounters block whose tile-sort SortState is the sort's state, zero-filled; with
// count_on_host its count is already n, else the caller sets it on the GPU, as a frame does.
struct DeviceSortInput {
  KeyBuffers buffers;
  vk::Buffer counters;
  uint32_t count = 0;
  SortInput input(uint32_t key_bits, bool depth_in_low_bits = false) {
    return {buffers, counters, kTileSortOffset, key_bits, depth_in_low_bits};
  }
};
DeviceSortInput upload_sort_input(const std::vector<uint64_t>& keys, uint32_t key_bits, uint32_t capacity = 0,
                                  bool count_on_host = true);

// The sorted keys and their input positions (from the payloads), read through staging copies so that
// the check does not depend on device memory being mapped.
struct SortedPairs {
  std::vector<uint64_t> keys;
  std::vector<uint32_t> positions;
};
SortedPairs read_sorted(const KeyBuffers& buffers, bool in_alt, uint32_t n);

// Uploads, records the sort in a stream of its own, runs it and reads the result back.
SortedPairs sort_on_device(SortStrategy& sorter, const std::vector<uint64_t>& keys, uint32_t key_bits,
                           uint32_t capacity = 0);

// EXPECTs got to be `expected` (input positions) with the original keys moved along; reports the
// first five mismatches, prefixed with `what`.
void expect_order(const std::vector<uint64_t>& keys, const std::vector<uint32_t>& expected, const SortedPairs& got,
                  const std::string& what);
inline void expect_stable_order(const std::vector<uint64_t>& keys, const SortedPairs& got, const std::string& what) {
  expect_order(keys, stable_order(keys), got, what);
}

}  // namespace tilesplat::testing
