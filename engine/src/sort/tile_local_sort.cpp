#include "sort/tile_local_sort.h"

#include <algorithm>
#include <bit>
#include <thread>

#include "passes/frame_counters.h"

namespace tilesplat {

namespace {

constexpr uint32_t kBinsHeader = 4;   // BINS_COUNTS in compute/tile_local_bins.glsl
constexpr uint32_t kBinsBigArgs = 1;  // BINS_BIG_ARGS
// 2^16 bins cover the 13 tile bits of a 1080p frame with room; more would make the table and its
// scan costly for small sorts.
constexpr uint32_t kMaxBinBits = 16;
// Keys per bin the bin count aims at for keys of uniform high bits: a bin of 2^9 keys takes nine
// passes of the network, and bins much smaller leave most of a sorting workgroup idle.
constexpr uint32_t kTargetBinBits = 9;
constexpr uint32_t kKeyWorkgroupSize = 256;  // local_size_x in compute/tile_local_bin.comp
// Invocations of a bin-sorting workgroup on a GPU, each holding a group of 16 elements: up to 1024
// elements per pass of the network without looping. Most frame tiles have a few hundred keys. A CPU
// driver runs a workgroup's subgroups one after another on one thread, and a subgroup without an
// active lane still runs a loop's body once under an empty mask, so there a bin is sorted by a
// single subgroup: 64 invocations made 2^16 45-bit keys 6 times slower on lavapipe.
constexpr uint32_t kSortWorkgroupSize = 64;
// The big-bin variant runs the network over a whole large bin in one workgroup, as wide as the
// device allows. lavapipe ends every loop of an invocation once the invocation has run 65535 loop
// iterations in all (gallivm's loop limiter), so an invocation's share of a bin's passes must stay
// below that: with 1024 invocations, bins up to 2^23 keys.
constexpr uint32_t kBigWorkgroupSize = 1024;
// Bins per sorting workgroup at most, for the same limit: a bin of the shared capacity (2048) takes
// about 200 loop iterations in a workgroup of one 8-wide subgroup (in each of its 6 merges, 16 groups
// of outputs per invocation and one merge path search of up to 11 steps).
constexpr uint32_t kMaxBinsPerWorkgroup = 64;
constexpr uint32_t kMaxSharedCapacity = 4096;

using SetupPush = shader_io::TileLocalSetupPush;  // compute/shader_io.h
using BinPush = shader_io::TileLocalBinPush;      // compute/shader_io.h
using ScanPush = shader_io::TileLocalScanPush;    // compute/shader_io.h
using SortPush = shader_io::TileLocalSortPush;    // compute/shader_io.h

// The most elements, a multiple of the 16 of a group, whose two merge buffers fill the device's
// shared memory (the shader has no other shared memory). A wide local key's high part takes a 64-bit
// word of its own: 16 bytes per element.
uint32_t fit_shared(const vk::Context& ctx, uint32_t bytes_per_element) {
  constexpr uint32_t kGroup = 16;
  const uint32_t elements = ctx.limits().max_shared_memory / (2 * bytes_per_element);
  return std::min(kMaxSharedCapacity, elements / kGroup * kGroup);
}

// A CPU driver runs each workgroup on one thread and pays a setup per workgroup (see
// bitonic_sort.cpp): a few workgroups per CPU thread, each looping, keep the threads busy. GPUs want
// as many as there is work for.
uint32_t workgroup_cap(const vk::Context& ctx, uint32_t gpu_cap) {
  const uint32_t device_limit = ctx.limits().max_workgroup_count_x;
  if (!ctx.is_cpu_device()) return std::min(device_limit, gpu_cap);
  return std::min(device_limit, 4 * std::max(2u, std::thread::hardware_concurrency()));
}

}  // namespace

TileLocalSort::Binning TileLocalSort::binning_for(uint32_t key_bits, uint32_t capacity) {
  key_bits = std::clamp<uint32_t>(key_bits, 1, 64);
  // Bins on the bits above 32 (a frame's tile id) keep the local keys within 32 bits; more bins
  // when the count asks for them, so that uniform keys make bins of about 2^kTargetBinBits.
  const uint32_t count_bits = uint32_t(std::bit_width(std::max<uint32_t>(capacity, 1)));
  uint32_t bits = std::max(key_bits > 32 ? key_bits - 32 : 1u, count_bits > kTargetBinBits ? count_bits - kTargetBinBits : 1u);
  bits = std::min({bits, kMaxBinBits, key_bits});
  return {bits, key_bits - bits};
}

TileLocalSort::TileLocalSort(vk::Context& ctx)
    : ctx_(ctx),
      key_workgroups_(workgroup_cap(ctx, ctx.limits().max_workgroup_count_x)),
      bin_workgroups_(workgroup_cap(ctx, 1u << kMaxBinBits)),
      shared_capacity_{fit_shared(ctx, 8), fit_shared(ctx, 16)} {
  setup_ = vk::ComputePipeline(ctx, "tile_local_setup", sizeof(SetupPush));
  scan_ = vk::ComputePipeline(ctx, "tile_local_scan", sizeof(ScanPush));
  for (uint32_t wide : {0u, 1u}) {
    count_[wide] = vk::ComputePipeline(ctx, "tile_local_bin", sizeof(BinPush), {{0, wide}, {1, 0}});
    scatter_[wide] = vk::ComputePipeline(ctx, "tile_local_bin", sizeof(BinPush), {{0, wide}, {1, 1}});
  }
  // Header, counts, ends and the big-bin list (compute/tile_local_bins.glsl).
  const VkDeviceSize bin_bytes = (kBinsHeader + 3 * (VkDeviceSize(1) << kMaxBinBits)) * sizeof(uint32_t);
  bins_ = vk::Buffer(ctx, bin_bytes, vk::MemoryUse::Device, "tile-local bins");
}

const vk::ComputePipeline& TileLocalSort::sort_pipeline(bool wide_keys, bool wide_local, bool big) {
  auto& slot = sort_[size_t(wide_keys) * 4 + size_t(wide_local) * 2 + size_t(big)];
  if (!slot) {
    // The big-bin variant sorts in global memory: its shared buffers only need to exist.
    const uint32_t capacity = big ? 1 : shared_capacity(wide_local);
    const uint32_t small_size = ctx_.is_cpu_device() ? ctx_.limits().subgroup_size : kSortWorkgroupSize;
    const uint32_t size = big ? std::min(kBigWorkgroupSize, ctx_.limits().max_workgroup_invocations) : small_size;
    const std::vector<vk::SpecConstant> spec{{0, size},     {1, wide_keys}, {2, wide_local},
                                             {3, big},      {4, capacity},  {5, wide_local ? capacity : 0}};
    slot = std::make_unique<vk::ComputePipeline>(ctx_, "tile_local_sort", uint32_t(sizeof(SortPush)), spec);
  }
  return *slot;
}

bool TileLocalSort::record(vk::CommandStream& stream, SortInput& input) {
  VkCommandBuffer cmd = stream.cmd();
  KeyBuffers& kb = input.keys;
  const Binning binning = binning_for(input.key_bits, kb.capacity);
  const uint32_t bin_count = 1u << binning.bin_bits;
  const bool wide_local = binning.shift > 32;
  const uint32_t wide = kb.wide_keys ? 1 : 0;
  const VkDeviceAddress state = input.state.address() + input.state_offset;
  const VkDeviceSize args_offset = input.state_offset + kSortArgsOffset;

  // The big-bin count, its indirect dispatch (no workgroups yet) and the bin counts
  // (compute/tile_local_bins.glsl).
  vkCmdFillBuffer(cmd, bins_.handle(), 0, 2 * sizeof(uint32_t), 0);
  vkCmdFillBuffer(cmd, bins_.handle(), 2 * sizeof(uint32_t), 2 * sizeof(uint32_t), 1);
  vkCmdFillBuffer(cmd, bins_.handle(), kBinsHeader * sizeof(uint32_t), bin_count * sizeof(uint32_t), 0);
  setup_.bind(cmd, SetupPush{state, kb.capacity, kKeyWorkgroupSize, key_workgroups_});
  setup_.dispatch(cmd, 1);
  vk::barrier(cmd);

  BinPush bin_push{
      kb.keys.address(), kb.keys_alt.address(), kb.values_alt.address(), bins_.address(), state, kb.capacity,
      bin_count,         binning.shift};
  count_[wide].bind(cmd, bin_push);
  count_[wide].dispatch_indirect(cmd, input.state.handle(), args_offset);
  vk::barrier(cmd);
  scan_.bind(cmd, ScanPush{bins_.address(), bin_count});
  scan_.dispatch(cmd, 1);
  vk::barrier(cmd);
  scatter_[wide].bind(cmd, bin_push);
  scatter_[wide].dispatch_indirect(cmd, input.state.handle(), args_offset);
  vk::barrier(cmd);

  // The small-bin variant lists the bins over the shared capacity for the big-bin variant, so that
  // its few workgroups of up to 1024 invocations do not scan every bin.
  const SortPush sort_push{
      kb.keys_alt.address(), kb.values_alt.address(), kb.values.address(), bins_.address(), bin_count,
      binning.shift,         bin_workgroups_};
  const vk::ComputePipeline& sort_small = sort_pipeline(kb.wide_keys, wide_local, false);
  sort_small.bind(cmd, sort_push);
  sort_small.dispatch(cmd, std::min(bin_count, std::max(bin_workgroups_, vk::div_ceil(bin_count, kMaxBinsPerWorkgroup))));
  vk::barrier(cmd);
  const vk::ComputePipeline& sort_big = sort_pipeline(kb.wide_keys, wide_local, true);
  sort_big.bind(cmd, sort_push);
  // A workgroup per big bin, as many as the small variant listed: a frame usually has none, and an
  // empty dispatch of 1024-invocation workgroups still costs lavapipe a millisecond.
  sort_big.dispatch_indirect(cmd, bins_.handle(), kBinsBigArgs * sizeof(uint32_t));
  vk::barrier(cmd);
  return true;
}

}  // namespace tilesplat
