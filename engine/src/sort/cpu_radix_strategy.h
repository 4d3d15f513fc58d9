// The sort on the host, in the middle of the frame: the stream is flushed (the keys and their count
// are then in memory the host can read), the pairs are sorted by tilesplat::cpu_radix_sort on one
// CPU thread, and the frame goes on in the stream's next command buffer. The timer marks around the
// sort then span the transfers and the host sort, so its time is counted like any other pass.
//
// Where the pairs live while the host sorts them depends on the device:
// - Device memory that is host-visible, coherent and host-cached (unified memory: lavapipe, most
//   integrated GPUs) is sorted where it lies: keys/values ping-pong with keys_alt/values_alt through
//   the mappings, nothing is copied and record() returns where the result ended up.
// - Otherwise (discrete GPUs, or uncached host-visible memory, whose host reads are many times slower
//   than a copy) the pairs are copied into one host-cached staging buffer, sorted there between its
//   halves, and copied back from whichever half holds the result into keys/values.
//
// cpu-radix16 sorts by a 16-bit quantized key instead, as the classic web viewers (antimatter15/splat)
// do with depth, so its order is not the exact one of the other strategies (exact() is false) and its
// images differ slightly. Keys of up to 16 bits are sorted exactly. Otherwise, with
// depth_in_low_bits, the low 32 bits of each key are a depth: the finite positive ones are mapped
// linearly from this sort's [min, max] onto levels 0 to 65534, computed in doubles as
// min(65534, uint32((depth - min) * (65534 / (max - min)))) (all level 0 when max == min); the rest
// (culled Gaussians: 0xffffffff) take level 65535, last. The bits above the depth (a tile id) go
// above the 16 level bits. Integer keys are mapped the same way over the [min, max] of the keys,
// onto 0 to 65535. Equal levels keep their input order; the keys moved are the original ones.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sort/sort_strategy.h"

namespace tilesplat {

class CpuRadixSort final : public SortStrategy {
 public:
  enum class Keys { kExact, kQuantized16 };
  // kAuto sorts in place when the device memory allows it (see above); kStaging always copies, so that
  // the discrete-GPU path can be tested on unified-memory devices too.
  enum class HostAccess { kAuto, kStaging };

  CpuRadixSort(vk::Context& ctx, Keys keys, HostAccess access = HostAccess::kAuto);
  std::string name() const override { return keys_ == Keys::kExact ? "cpu-radix" : "cpu-radix16"; }
  void reserve(uint32_t max_keys) override;
  bool record(vk::CommandStream& stream, SortInput& input) override;
  bool exact() const override { return keys_ == Keys::kExact; }
  bool sorts_on_host() const override { return true; }
  uint64_t device_bytes() const override { return staging_.size(); }

  // Whether the last record() copied through the staging buffer (false: it sorted in place).
  bool last_used_staging() const { return last_used_staging_; }
  // Host time of the last record()'s sort alone (wall clock, transfers and flushes excluded).
  double last_host_ms() const { return last_host_ms_; }

 private:
  template <typename Key>
  bool sort_on_host(Key* keys, uint32_t* values, Key* keys_out, uint32_t* values_out, uint32_t n,
                    const SortInput& input);
  template <typename Key, typename QKey>
  void sort_quantized(const Key* keys, const uint32_t* values, Key* keys_out, uint32_t* values_out, uint32_t n,
                      const SortInput& input, std::vector<QKey>& q, std::vector<QKey>& q_scratch, uint32_t q_bits);
  void ensure_staging(uint32_t max_keys);
  void ensure_host_scratch(uint32_t max_keys, bool wide_quantized);

  vk::Context& ctx_;
  Keys keys_;
  HostAccess access_;
  bool device_memory_cached_ = false;  // Device buffers are host-visible, coherent and cached
  uint32_t reserved_keys_ = 0;
  // [keys | keys scratch | values | values scratch], 8-byte keys; only allocated when sorts copy.
  vk::Buffer staging_;
  // cpu-radix16: the quantized keys and the input position of each, with their radix-sort scratch.
  // Persistent so that no sort times an allocation; the 64-bit ones only exist for keys wider than
  // 48 bits with a depth in the low bits, which no frame sorts.
  std::vector<uint32_t> q32_, q32_scratch_, positions_, positions_scratch_;
  std::vector<uint64_t> q64_, q64_scratch_;
  bool last_used_staging_ = false;
  double last_host_ms_ = 0;
};

}  // namespace tilesplat
