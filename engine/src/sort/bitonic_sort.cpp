#include "sort/bitonic_sort.h"

#include <algorithm>
#include <bit>
#include <stdexcept>
#include <string>
#include <thread>

#include "passes/frame_counters.h"

namespace tilesplat {

namespace {

// Each invocation holds a group of 16 keys in registers and runs up to four steps of the network on
// it per pass (GROUP_BITS in compute/bitonic_common.glsl). Larger groups were measured on lavapipe:
// 32 and 64 keys save passes but spill registers, and came out 15% and 20% slower on 2^20 keys.
constexpr uint32_t kGroupBits = 4;
constexpr uint32_t kGroupKeys = 1u << kGroupBits;
constexpr uint32_t kWorkgroupSize = 256;  // local_size_x in compute/bitonic_common.glsl

using SetupPush = shader_io::BitonicSetupPush;  // compute/shader_io.h
using PassPush = shader_io::BitonicPassPush;    // compute/shader_io.h

// The passes loop over their groups, so any workgroup count covers the keys. GPUs want as many as
// the keys fill. A CPU driver runs each workgroup on one thread and pays a setup per workgroup (about
// 8 us on lavapipe, where 256 workgroups made a 2^20-key pass 70% slower than 8), so there a few per
// CPU thread keep every thread busy at a fraction of the cost.
uint32_t workgroup_cap(const vk::Context& ctx) {
  const uint32_t device_limit = ctx.limits().max_workgroup_count_x;
  if (!ctx.is_cpu_device()) return device_limit;
  return std::min(device_limit, 4 * std::max(2u, std::thread::hardware_concurrency()));
}

}  // namespace

BitonicSort::BitonicSort(vk::Context& ctx) : ctx_(ctx), max_workgroups_(workgroup_cap(ctx)) {
  setup_ = vk::ComputePipeline(ctx, "bitonic_setup", sizeof(SetupPush));
  // Variant packed * 2 + wide: keys packed with their positions or not, 32- or 64-bit key buffers.
  for (uint32_t v = 0; v < 4; ++v) {
    const std::vector<vk::SpecConstant> spec{{0, v / 2}, {1, v % 2}};
    sort_groups_[v] = vk::ComputePipeline(ctx, "bitonic_sort_groups", sizeof(PassPush), spec);
    merge_[v] = vk::ComputePipeline(ctx, "bitonic_merge", sizeof(PassPush), spec);
  }
}

bool BitonicSort::record(vk::CommandStream& stream, SortInput& input) {
  VkCommandBuffer cmd = stream.cmd();
  KeyBuffers& kb = input.keys;
  const VkDeviceAddress state = input.state.address() + input.state_offset;
  const VkDeviceSize args_offset = input.state_offset + kSortArgsOffset;
  setup_.bind(cmd, SetupPush{state, kb.capacity, kGroupKeys, kWorkgroupSize, max_workgroups_});
  setup_.dispatch(cmd, 1);
  vk::barrier(cmd);

  // Every index below the capacity fits in index_bits: that is the width of a position, and the
  // network for the capacity has index_bits stages. When the key's varying bits fit beside a
  // position, the network sorts single words.
  const uint32_t index_bits = uint32_t(std::bit_width(std::max<uint32_t>(kb.capacity, 1) - 1));
  // position. Packed words are 64-bit: with 32-bit key buffers they run in the strategy's scratch.
  const bool packed = std::min<uint32_t>(input.key_bits, 64) + index_bits <= 64;
  const uint32_t variant = (packed ? 2 : 0) + (kb.wide_keys ? 1 : 0);
  const bool scratch = packed && !kb.wide_keys;
  if (scratch && network_.size() < VkDeviceSize(kb.capacity) * sizeof(uint64_t))
    throw std::logic_error("bitonic sort: reserve() was not called for " + std::to_string(kb.capacity) + " keys");
  const VkDeviceAddress network = scratch ? network_.address() : kb.keys_alt.address();

  // The network runs in keys_alt and values_alt, so the input values stay intact for the final
  // gather. Each pass loads and stores the same indices in one invocation, which lets the last pass
  // read a key's position from values_alt and overwrite it with the payload.
  PassPush push{kb.keys.address(),
                kb.values.address(),
                network,
                kb.keys_alt.address(),
                kb.values_alt.address(),
                kb.values_alt.address(),
                state,
                kb.capacity,
                index_bits,
                0,
                0,
                0};
  sort_groups_[variant].bind(cmd, push);
  sort_groups_[variant].dispatch_indirect(cmd, input.state.handle(), args_offset);
  vk::barrier(cmd);

  // The first pass ran the stages up to a group. The network is recorded up to the capacity's power
  // of two; the passes past this frame's count return at once on the GPU. A stage of s steps runs its
  // first (s - 1) % 4 + 1 steps (the flip among them) in one pass, then passes of four, so that its
  // last pass ends at stride 1 with groups of 16 consecutive keys.
  for (uint32_t stage_bits = kGroupBits + 1; stage_bits <= index_bits; ++stage_bits) {
    push.stage = 1u << stage_bits;
    for (uint32_t steps_left = stage_bits; steps_left > 0; steps_left -= push.steps) {
      push.steps = (steps_left - 1) % kGroupBits + 1;
      push.stride = 1u << (steps_left - 1);
      merge_[variant].bind(cmd, push);
      merge_[variant].dispatch_indirect(cmd, input.state.handle(), args_offset);
      vk::barrier(cmd);
    }
  }
  return true;
}

void BitonicSort::reserve(uint32_t max_keys) {
  // Packed words of 32-bit keys need 64-bit scratch; allocated for any capacity that may need it.
  const VkDeviceSize bytes = VkDeviceSize(max_keys) * sizeof(uint64_t);
  if (network_.size() < bytes)
    network_ = vk::Buffer(ctx_, bytes, vk::MemoryUse::Device, "bitonic network (packed 32-bit keys)");
}

}  // namespace tilesplat
