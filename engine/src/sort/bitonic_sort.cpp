#include "sort/bitonic_sort.h"

#include <algorithm>
#include <bit>
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

struct SetupPush {
  VkDeviceAddress state;
  uint32_t capacity, group_keys, workgroup_size, max_workgroups;
};
struct PassPush {
  VkDeviceAddress keys_in, values_in, keys, positions, values_out, state;
  uint32_t capacity, position_bits, stage, stride, steps, pad;
};

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

BitonicSort::BitonicSort(vk::Context& ctx) : max_workgroups_(workgroup_cap(ctx)) {
  setup_ = vk::ComputePipeline(ctx, "bitonic_setup", sizeof(SetupPush));
  // Variants: narrow keys, wide keys, wide keys packed with their positions.
  const uint32_t variants[3][2] = {{0, 0}, {0, 1}, {1, 1}};
  for (uint32_t v = 0; v < 3; ++v) {
    const std::vector<vk::SpecConstant> spec{{0, variants[v][0]}, {1, variants[v][1]}};
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
  // position. Packing needs 64-bit words to run the network in, which narrow key buffers lack.
  const bool packed = kb.wide_keys && std::min<uint32_t>(input.key_bits, 64) + index_bits <= 64;
  const uint32_t variant = !kb.wide_keys ? 0 : packed ? 2 : 1;

  // The network runs in keys_alt and values_alt, so the input values stay intact for the final
  // gather. Each pass loads and stores the same indices in one invocation, which lets the last pass
  // read a key's position from values_alt and overwrite it with the payload.
  PassPush push{kb.keys.address(),      kb.values.address(),     kb.keys_alt.address(), kb.values_alt.address(),
                kb.values_alt.address(), state,                  kb.capacity,           index_bits,
                0,                       0,                      0,                     0};
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

}  // namespace tilesplat
