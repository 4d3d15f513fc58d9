#include "sort/onesweep_sort.h"

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "passes/frame_counters.h"

namespace tilesplat {

namespace {

// Must match compute/onesweep_common.glsl.
constexpr uint32_t kRadix = 256;
constexpr uint32_t kDigitBits = 8;
constexpr uint32_t kMaxPasses = 8;
constexpr uint32_t kControlUints = kMaxPasses * kRadix + kMaxPasses + 1;
constexpr uint32_t kMaxKeys = (1u << 30) - 1;  // a status word holds a count below 2^30
// Partition size. A partition's per-digit work (clearing, summing and offsetting a subgroup's 256
// counters, publishing and looking back over 256 status words) is a fixed cost of some 10^4 shared
// and global accesses, which lavapipe runs lane by lane: a pass over 2^20 keys took 290, 125, 100 and
// 80 ms at partitions of 512, 1024, 2048 and 4096 keys. 4096 keys of ranks fill half of the 32 KiB of
// shared memory that every Vulkan device has.
constexpr uint32_t kPartitionKeys = 4096;
// At least 32 lanes, so that each lane owns at most 8 of the 256 digits in the look-back; on lavapipe
// (8 lanes) 4 subgroups, whose 4 x 256 counters are cheaper to clear and offset than 8 x 256.
constexpr uint32_t kMinWorkgroupSize = 32;

using SetupPush = shader_io::OnesweepSetupPush;          // compute/shader_io.h
using HistogramPush = shader_io::OnesweepHistogramPush;  // compute/shader_io.h
using PassPush = shader_io::OnesweepPassPush;            // compute/shader_io.h

uint32_t spin_limit_from_environment() {
  const char* text = std::getenv("TILESPLAT_ONESWEEP_SPIN");
  if (!text || !*text) return OnesweepSort::kDefaultSpinLimit;
  uint32_t value = 0;
  const char* end = text + std::strlen(text);
  const auto [ptr, ec] = std::from_chars(text, end, value);
  if (ec != std::errc() || ptr != end)
    throw std::invalid_argument(std::string("TILESPLAT_ONESWEEP_SPIN: not a spin count: '") + text + "'");
  return value;
}

}  // namespace

// llvmpipe (lavapipe) stops every loop of an invocation once it has run 65535 loop iterations in
// total (LP_MAX_TGSI_LOOP_ITERATIONS, "shared between every loop in a shader"), silently: a longer
// wait would cut the ranking and scatter loops after it short and corrupt the order. The pass's
// other loops take a few thousand iterations, so a CPU driver's waits stay well below that.
constexpr uint32_t kCpuDriverMaxSpin = 16384;

OnesweepSort::OnesweepSort(vk::Context& ctx, std::optional<uint32_t> spin_limit)
    : ctx_(ctx),
      spin_limit_(spin_limit ? *spin_limit : spin_limit_from_environment()),
      texel_buffers_(vk::texel_buffers_wanted(ctx)) {
  if (ctx.is_cpu_device()) spin_limit_ = std::min(spin_limit_, kCpuDriverMaxSpin);
  const uint32_t sg = ctx.limits().subgroup_size;
  workgroup_size_ = std::max<uint32_t>(kMinWorkgroupSize, sg);
  const uint32_t subgroups = workgroup_size_ / sg;
  const uint32_t keys_per_lane = kPartitionKeys / workgroup_size_;
  partition_keys_ = workgroup_size_ * keys_per_lane;
  setup_ = vk::ComputePipeline(ctx, "onesweep_setup", sizeof(SetupPush));
  for (uint32_t wide : {0u, 1u}) {
    histogram_[wide] = vk::ComputePipeline(ctx, "onesweep_histogram", sizeof(HistogramPush),
                                           {{0, workgroup_size_}, {1, partition_keys_}, {2, wide}});
    pass_[wide] = vk::ComputePipeline(ctx, "onesweep_pass", sizeof(PassPush),
                                      {{0, workgroup_size_}, {1, subgroups}, {2, keys_per_lane}, {3, wide}});
    if (texel_buffers_) {
      histogram_texel_[wide] = vk::ComputePipeline(ctx, "onesweep_histogram_texel", sizeof(HistogramPush),
                                                   {{0, workgroup_size_}, {1, partition_keys_}, {2, wide}},
                                                   KeyBuffers::texel_bindings());
      pass_texel_[wide] =
          vk::ComputePipeline(ctx, "onesweep_pass_texel", sizeof(PassPush),
                              {{0, workgroup_size_}, {1, subgroups}, {2, keys_per_lane}, {3, wide}},
                              KeyBuffers::texel_bindings());
    }
  }
  if (texel_buffers_) unused_keys_ = vk::Buffer(ctx, 16, vk::MemoryUse::Device, "onesweep unused key view");
  control_ = vk::Buffer(ctx, kControlUints * sizeof(uint32_t), vk::MemoryUse::Device, "onesweep control");
  fallbacks_ = vk::Buffer(ctx, sizeof(uint32_t), vk::MemoryUse::Readback, "onesweep fallbacks");
  std::memset(fallbacks_.mapped(), 0, sizeof(uint32_t));
}

uint32_t OnesweepSort::partitions_for(uint32_t keys) const {
  return std::max<uint32_t>(1, vk::div_ceil(keys, partition_keys_));
}

void OnesweepSort::reserve(uint32_t max_keys) {
  const uint32_t rows = partitions_for(max_keys);
  if (max_keys > kMaxKeys || rows > ctx_.limits().max_workgroup_count_x)
    throw std::length_error("onesweep sort: " + std::to_string(max_keys) + " keys exceed its limit of " +
                            std::to_string(std::min<uint64_t>(kMaxKeys, uint64_t(ctx_.limits().max_workgroup_count_x) *
                                                                            partition_keys_)));
  if (rows > status_rows_) {
    status_ = vk::Buffer(ctx_, 2ull * rows * kRadix * sizeof(uint32_t), vk::MemoryUse::Device, "onesweep status");
    status_rows_ = rows;
  }
}

uint64_t OnesweepSort::fallbacks() const {
  uint32_t count;
  std::memcpy(&count, fallbacks_.mapped(), sizeof(count));
  return count;
}

bool OnesweepSort::record(vk::CommandStream& stream, SortInput& input) {
  VkCommandBuffer cmd = stream.cmd();
  KeyBuffers& kb = input.keys;
  if (status_rows_ < partitions_for(kb.capacity))
    throw std::logic_error("onesweep sort: reserve() was not called for " + std::to_string(kb.capacity) + " keys");

  const VkDeviceAddress state = input.state.address() + input.state_offset;
  const VkDeviceSize args_offset = input.state_offset + kSortArgsOffset;
  const VkDeviceAddress status[2] = {status_.address(),
                                     status_.address() + VkDeviceSize(status_rows_) * kRadix * sizeof(uint32_t)};
  setup_.bind(cmd, SetupPush{state, control_.address(), partition_keys_});
  setup_.dispatch(cmd, 1);
  vk::barrier(cmd);

  const uint32_t wide = kb.wide_keys ? 1 : 0;
  const uint32_t passes = (std::min<uint32_t>(input.key_bits, 64) + kDigitBits - 1) / kDigitBits;
  // Texel views per direction (none where a buffer has more texels than the device allows: the address
  // variants run); the histogram reads the first pass's keys.
  const std::vector<VkBufferView> views[2] = {
      texel_buffers_ ? kb.texel_views(false, unused_keys_) : std::vector<VkBufferView>{},
      texel_buffers_ ? kb.texel_views(true, unused_keys_) : std::vector<VkBufferView>{}};
  const bool texel = !views[0].empty() && !views[1].empty();
  const vk::ComputePipeline& histogram = texel ? histogram_texel_[wide] : histogram_[wide];
  histogram.bind(cmd, HistogramPush{kb.keys.address(), control_.address(), status[0], state, passes});
  if (texel) histogram.push_texel_views(cmd, views[0]);
  histogram.dispatch_indirect(cmd, input.state.handle(), args_offset);
  vk::barrier(cmd);

  bool in_alt = false;
  for (uint32_t p = 0; p < passes; ++p) {
    const auto [keys_in, values_in, keys_out, values_out] = kb.pass(in_alt);
    const PassPush push{keys_in.address(),  values_in.address(), keys_out.address(),
                        values_out.address(), control_.address(), status[p % 2],
                        status[(p + 1) % 2],  state,              fallbacks_.address(),
                        p * kDigitBits,       p,                  spin_limit_,
                        p + 1 < passes ? 1u : 0u};
    const vk::ComputePipeline& pass = texel ? pass_texel_[wide] : pass_[wide];
    pass.bind(cmd, push);
    if (texel) pass.push_texel_views(cmd, views[in_alt ? 1 : 0]);
    pass.dispatch_indirect(cmd, input.state.handle(), args_offset);
    vk::barrier(cmd);
    in_alt = !in_alt;
  }
  return in_alt;
}

}  // namespace tilesplat
