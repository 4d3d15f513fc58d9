#include "sort/key_sort_run.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "passes/frame_counters.h"
#include "passes/key_buffers.h"
#include "vulkan/buffer.h"
#include "vulkan/command_stream.h"
#include "vulkan/readback.h"

namespace tilesplat {

void check_sort_keys(const std::vector<uint64_t>& keys, uint32_t key_bits) {
  if (key_bits < 1 || key_bits > 64)
    throw std::invalid_argument("sort_keys: key_bits must be 1 to 64, not " + std::to_string(key_bits));
  if (keys.size() > (1u << 31))
    throw std::invalid_argument("sort_keys: " + std::to_string(keys.size()) + " keys, more than 2^31");
  const uint64_t allowed = key_bits == 64 ? ~0ull : (1ull << key_bits) - 1;
  for (size_t i = 0; i < keys.size(); ++i)
    if (keys[i] & ~allowed)
      throw std::invalid_argument("sort_keys: key " + std::to_string(i) + " has bits above the " +
                                  std::to_string(key_bits) + " key bits");
}

Renderer::SortRun run_key_sort(vk::Context& ctx, vk::GpuTimer& timer, SortStrategy& sorter,
                               const std::vector<uint64_t>& keys, uint32_t key_bits) {
  const uint32_t n = uint32_t(keys.size());
  const uint32_t capacity = std::max<uint32_t>(n, 1);
  KeyBuffers kb = KeyBuffers::allocate(ctx, capacity, key_bits, "sort_keys");
  std::vector<uint32_t> positions(n);
  for (uint32_t i = 0; i < n; ++i) positions[i] = i;
  if (n > 0) {
    const std::vector<uint8_t> packed = kb.pack_keys(keys);
    vk::upload(ctx, kb.keys, packed.data(), packed.size());
    vk::upload(ctx, kb.values, positions.data(), VkDeviceSize(n) * sizeof(uint32_t));
  }
  vk::Buffer state(ctx, sizeof(SortState), vk::MemoryUse::Readback, "sort_keys state");
  SortState initial{};
  initial.count = n;
  std::memcpy(state.mapped(), &initial, sizeof(initial));

  sorter.reserve(capacity);
  const uint64_t fallbacks_before = sorter.stall_fallbacks();
  vk::CommandStream stream(ctx);
  timer.begin_frame(stream.cmd());
  SortInput input{kb, state, 0, key_bits};
  const bool in_alt = sorter.record(stream, input);
  timer.mark(stream.cmd(), "sort");
  stream.finish();

  Renderer::SortRun run;
  timer.read(&run.gpu_ms);
  run.fallbacks = sorter.stall_fallbacks() - fallbacks_before;
  std::vector<uint8_t> sorted_keys;
  vk::read_buffer(ctx, in_alt ? kb.keys_alt : kb.keys, sorted_keys, size_t(n) * kb.key_bytes());
  run.keys = kb.unpack_keys(sorted_keys.data(), n);
  vk::read_buffer(ctx, in_alt ? kb.values_alt : kb.values, run.order, n);
  return run;
}

}  // namespace tilesplat
