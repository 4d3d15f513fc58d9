#include "sort/radix_sort.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "passes/frame_counters.h"

namespace tilesplat {

namespace {

constexpr uint32_t kRadix = 256;
constexpr uint32_t kDigitBits = 8;
// Keys per block is a multiple of the subgroup size: a subgroup walks its block this many times.
constexpr uint32_t kStepsPerBlock = 256;
// From this many keys on, blocks are twice as large. A CPU driver pays for every workgroup (2^22
// keys: 8% faster on lavapipe with the larger blocks), but small counts need the smaller blocks to
// keep every core busy (2^16 keys: 50% slower with the larger ones).
constexpr uint32_t kLargeCount = 1u << 20;
// The scan gives each digit one subgroup; a workgroup of 8 covers 8 digits.
constexpr uint32_t kScanDigitsPerWorkgroup = 8;

using SetupPush = shader_io::RadixSetupPush;  // compute/shader_io.h
using PassPush = shader_io::RadixPassPush;    // compute/shader_io.h
using ScanPush = shader_io::RadixScanPush;    // compute/shader_io.h

uint32_t workgroup_subgroups(const vk::Context& ctx) {
  // Four subgroups per workgroup keeps the per-subgroup shared counters small (4 KiB) on every device.
  (void)ctx;
  return 4;
}

}  // namespace

RadixSort::RadixSort(vk::Context& ctx)
    : ctx_(ctx),
      subgroups_per_workgroup_(workgroup_subgroups(ctx)),
      block_keys_(ctx.limits().subgroup_size * kStepsPerBlock),
      texel_buffers_(vk::texel_buffers_wanted(ctx)) {
  const uint32_t sg = ctx.limits().subgroup_size;
  setup_ = vk::ComputePipeline(ctx, "radix_setup", sizeof(SetupPush));
  scan_pass_ = vk::ComputePipeline(ctx, "radix_scan", sizeof(ScanPush),
                                   {{0, sg * kScanDigitsPerWorkgroup}, {1, kScanDigitsPerWorkgroup}});
  for (uint32_t wide : {0u, 1u}) {
    const std::vector<vk::SpecConstant> spec{
        {0, sg * subgroups_per_workgroup_}, {1, subgroups_per_workgroup_}, {3, wide}};
    histogram_pass_[wide] = vk::ComputePipeline(ctx, "radix_histogram", sizeof(PassPush), spec);
    scatter_pass_[wide] = vk::ComputePipeline(ctx, "radix_scatter", sizeof(PassPush), spec);
    if (texel_buffers_) {
      histogram_texel_pass_[wide] = vk::ComputePipeline(ctx, "radix_histogram_texel", sizeof(PassPush), spec,
                                                        KeyBuffers::texel_bindings());
      scatter_texel_pass_[wide] = vk::ComputePipeline(ctx, "radix_scatter_texel", sizeof(PassPush), spec,
                                                      KeyBuffers::texel_bindings());
    }
  }
  if (texel_buffers_) unused_keys_ = vk::Buffer(ctx, 16, vk::MemoryUse::Device, "radix unused key view");
  digit_totals_ = vk::Buffer(ctx, kRadix * sizeof(uint32_t), vk::MemoryUse::Device, "radix digit totals");
}

uint32_t RadixSort::blocks_for(uint32_t keys) const {
  return std::max<uint32_t>(1, uint32_t((uint64_t(keys) + block_keys_ - 1) / block_keys_));
}

void RadixSort::reserve(uint32_t max_keys) {
  const VkDeviceSize histogram_bytes = VkDeviceSize(blocks_for(max_keys)) * kRadix * sizeof(uint32_t);
  if (histogram_.size() < histogram_bytes)
    histogram_ = vk::Buffer(ctx_, histogram_bytes, vk::MemoryUse::Device, "radix histogram");
}

bool RadixSort::record(vk::CommandStream& stream, SortInput& input) {
  VkCommandBuffer cmd = stream.cmd();
  KeyBuffers& kb = input.keys;
  if (histogram_.size() < VkDeviceSize(blocks_for(kb.capacity)) * kRadix * sizeof(uint32_t))
    throw std::logic_error("radix sort: reserve() was not called for " + std::to_string(kb.capacity) + " keys");

  const VkDeviceAddress state = input.state.address() + input.state_offset;
  const VkDeviceSize args_offset = input.state_offset + kSortArgsOffset;
  setup_.bind(cmd, SetupPush{state, block_keys_, kLargeCount, subgroups_per_workgroup_});
  setup_.dispatch(cmd, 1);
  vk::barrier(cmd);

  const uint32_t wide = kb.wide_keys ? 1 : 0;
  const uint32_t passes = (std::min<uint32_t>(input.key_bits, 64) + kDigitBits - 1) / kDigitBits;
  bool in_alt = false;
  for (uint32_t p = 0; p < passes; ++p) {
    const auto [keys_in, values_in, keys_out, values_out] = kb.pass(in_alt);
    PassPush push{keys_in.address(),
                  values_in.address(),
                  keys_out.address(),
                  values_out.address(),
                  histogram_.address(),
                  digit_totals_.address(),
                  state,
                  p * kDigitBits};
    // Texel views (none where a buffer has more texels than the device allows: the address variants run).
    const std::vector<VkBufferView> views =
        texel_buffers_ ? kb.texel_views(in_alt, unused_keys_) : std::vector<VkBufferView>{};
    const vk::ComputePipeline& histogram_pass =
        views.empty() ? histogram_pass_[wide] : histogram_texel_pass_[wide];
    const vk::ComputePipeline& scatter_pass = views.empty() ? scatter_pass_[wide] : scatter_texel_pass_[wide];
    histogram_pass.bind(cmd, push);
    if (!views.empty()) histogram_pass.push_texel_views(cmd, views);
    histogram_pass.dispatch_indirect(cmd, input.state.handle(), args_offset);
    vk::barrier(cmd);
    scan_pass_.bind(cmd, ScanPush{histogram_.address(), digit_totals_.address(), state});
    scan_pass_.dispatch(cmd, kRadix / kScanDigitsPerWorkgroup);
    vk::barrier(cmd);
    scatter_pass.bind(cmd, push);
    if (!views.empty()) scatter_pass.push_texel_views(cmd, views);
    scatter_pass.dispatch_indirect(cmd, input.state.handle(), args_offset);
    vk::barrier(cmd);
    in_alt = !in_alt;
  }
  return in_alt;
}

}  // namespace tilesplat
