// LSD radix sort, 8-bit digits, Onesweep (Adinets & Merrill 2022): one histogram kernel reads the keys
// once and counts the digits of every pass; then each pass is ONE kernel in which every workgroup takes
// a partition ticket, ranks its partition's keys stably, publishes its digit counts, finds its prefix
// by decoupled look-back over the earlier partitions, and scatters. A pass is 1 dispatch where the
// reduce-then-scan radix sort needs 3, and its counts come from its own ranking, not a histogram pass.
// (It still reads its keys twice on lavapipe: they are read again at the scatter rather than kept in
// registers, see onesweep_pass.comp.)
//
// When it is safe. A look-back waits for an earlier partition to publish its counts, and Vulkan does
// not guarantee that a workgroup makes progress while another one spins: a device may run the waiter
// and never schedule (or resume) the one it waits for. Tickets are taken when a workgroup starts, so
// every partition waited on belongs to a workgroup that has started; the wait ends in practice when
// started workgroups keep running on their own threads or compute units (lavapipe's thread pool runs a
// workgroup to completion on one thread; desktop GPUs keep resident workgroups scheduled), and may not
// end where a started workgroup can be parked behind a spinner (some mobile schedulers, preemption).
// It is made safe anyway by never waiting unboundedly: after spin_limit polling rounds on a status
// that is still empty, the waiter counts that partition's digits itself from the pass's input keys, which no one
// writes during the pass (the "decoupled fallback" of Smith, Levien & Owens 2024). That needs nothing
// from the stalled workgroup, so every look-back ends and the sort cannot hang the device; it only
// costs reading one partition's keys again. The order is the same either way: a fallback computes
// exactly the count the stalled workgroup would publish. The wait is polled by the whole workgroup in
// rounds with a barrier each, never by one lane alone: a long loop of one lane broke lavapipe's
// barriers (see onesweep_pass.comp). On a CPU driver the spin limit is capped: llvmpipe silently
// ends every loop of an invocation after 65535 iterations in all (see onesweep_sort.cpp), which
// explains that breakage, too.
//
// Partitions of 4096 keys, workgroups of max(32, subgroup size) lanes; fewer than 2^30 keys (a status
// word keeps 2 flag bits).
#pragma once

#include <optional>

#include "sort/sort_strategy.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

class OnesweepSort final : public SortStrategy {
 public:
  // Polling rounds (the whole workgroup re-reads the statuses it lacks, then votes) on an unpublished
  // predecessor before a look-back counts its keys itself; 0 forces that fallback for every
  // partition's immediate predecessor (tests). Without a value: the environment variable
  // TILESPLAT_ONESWEEP_SPIN, else kDefaultSpinLimit. On lavapipe a round costs about as much as
  // counting a few dozen keys, and a fallback counts 4096.
  static constexpr uint32_t kDefaultSpinLimit = 64;
  explicit OnesweepSort(vk::Context& ctx, std::optional<uint32_t> spin_limit = std::nullopt);
  std::string name() const override { return "onesweep"; }
  void reserve(uint32_t max_keys) override;
  bool record(vk::CommandStream& stream, SortInput& input) override;
  uint64_t device_bytes() const override { return control_.size() + status_.size() + fallbacks_.size(); }

  uint32_t partition_keys() const { return partition_keys_; }
  uint32_t spin_limit() const { return spin_limit_; }
  // Look-back steps that gave up waiting and counted a predecessor's keys, over this object's life
  // (a 32-bit GPU counter). Read it once the recorded sorts have finished.
  uint64_t fallbacks() const;
  uint64_t stall_fallbacks() const override { return fallbacks(); }

 private:
  uint32_t partitions_for(uint32_t keys) const;

  vk::Context& ctx_;
  uint32_t workgroup_size_;
  uint32_t partition_keys_;
  uint32_t spin_limit_;
  bool texel_buffers_;        // CPU drivers: the _texel variants (compute/sort_key_texels.glsl)
  uint32_t status_rows_ = 0;  // partitions each of the two status halves has room for
  vk::ComputePipeline setup_;
  vk::ComputePipeline histogram_[2], pass_[2];              // [wide keys]
  vk::ComputePipeline histogram_texel_[2], pass_texel_[2];  // [wide keys]
  vk::Buffer unused_keys_;  // the texel binding of the key width a pass does not write
  vk::Buffer control_;    // digit bases and tickets (onesweep_common.glsl)
  vk::Buffer status_;     // two halves of RADIX words per partition: passes alternate between them
  vk::Buffer fallbacks_;  // host-visible counter
};

}  // namespace tilesplat
