#include "sort/cpu_radix_strategy.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstring>
#include <limits>
#include <span>
#include <stdexcept>

#include "passes/frame_counters.h"
#include "tilesplat/sort.h"
#include "vulkan/compute_pipeline.h"

namespace tilesplat {

namespace {

constexpr uint32_t kQuantizedBits = 16;
// Finite positive depths take levels 0 to kLastDepthLevel; anything else (the depth sort's culled
// Gaussians are 0xffffffff, a NaN) takes the level after them, so it neither stretches the range nor
// mixes with the farthest depths.
constexpr uint32_t kLastDepthLevel = 0xfffe;
constexpr uint32_t kNotADepthLevel = 0xffff;
constexpr uint32_t kLastIntegerLevel = 0xffff;
// Staging bytes per key: 8-byte keys and 4-byte values, each with its ping-pong half.
constexpr VkDeviceSize kStagingBytesPerKey = 2 * 8 + 2 * 4;

// The bits of a finite positive float, subnormals included: 1 to 0x7f7fffff. Such bits order like
// the floats they encode, so the range can be found on the bits.
bool positive_finite_float(uint32_t bits) { return bits - 1u < 0x7f7fffffu; }

// Whether the Device buffers are mapped (Buffer maps host-visible coherent memory) and host-cached:
// uncached (write-combined) memory would make the sort's scattered host reads very slow. Decided on
// a probe buffer, as KeyBuffers would allocate one.
bool device_memory_host_cached(vk::Context& ctx) {
  const vk::Buffer probe(ctx, 16, vk::MemoryUse::Device, "cpu-radix memory probe");
  if (!probe.mapped()) return false;
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(ctx.device(), probe.handle(), &req);
  const uint32_t type = ctx.find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  return (ctx.memory_type_flags(type) & VK_MEMORY_PROPERTY_HOST_CACHED_BIT) != 0;
}

}  // namespace

CpuRadixSort::CpuRadixSort(vk::Context& ctx, Keys keys, HostAccess access)
    : ctx_(ctx), keys_(keys), access_(access), device_memory_cached_(device_memory_host_cached(ctx)) {}

void CpuRadixSort::ensure_staging(uint32_t max_keys) {
  const VkDeviceSize bytes = VkDeviceSize(std::max<uint32_t>(max_keys, 1)) * kStagingBytesPerKey;
  if (staging_.size() < bytes) staging_ = vk::Buffer(ctx_, bytes, vk::MemoryUse::Readback, name() + " staging");
}

void CpuRadixSort::ensure_host_scratch(uint32_t max_keys, bool wide_quantized) {
  if (q32_.size() < max_keys) {
    for (auto* v : {&q32_, &q32_scratch_, &positions_, &positions_scratch_}) v->resize(max_keys);
  }
  if (wide_quantized && q64_.size() < max_keys) {
    q64_.resize(max_keys);
    q64_scratch_.resize(max_keys);
  }
}

void CpuRadixSort::reserve(uint32_t max_keys) {
  reserved_keys_ = std::max(reserved_keys_, max_keys);
  if (access_ == HostAccess::kStaging || !device_memory_cached_) ensure_staging(reserved_keys_);
  if (keys_ == Keys::kQuantized16) ensure_host_scratch(reserved_keys_, false);
}

// Sorts n pairs; returns true when the result is in keys_out/values_out, false when in keys/values.
template <typename Key>
bool CpuRadixSort::sort_on_host(Key* keys, uint32_t* values, Key* keys_out, uint32_t* values_out, uint32_t n,
                                const SortInput& input) {
  if (keys_ == Keys::kExact || input.key_bits <= kQuantizedBits)
    return cpu_radix_sort(std::span<Key>(keys, n), std::span<uint32_t>(values, n), std::span<Key>(keys_out, n),
                          std::span<uint32_t>(values_out, n), input.key_bits);
  // The bits above a depth (a tile id) stay above its 16 quantized bits.
  const uint32_t q_bits =
      kQuantizedBits + (input.depth_in_low_bits && input.key_bits > 32 ? input.key_bits - 32 : 0);
  if (q_bits <= 32) {
    sort_quantized(keys, values, keys_out, values_out, n, input, q32_, q32_scratch_, q_bits);
  } else {
    ensure_host_scratch(reserved_keys_, true);  // > 48-bit keys with depths: no frame sorts these
    sort_quantized(keys, values, keys_out, values_out, n, input, q64_, q64_scratch_, q_bits);
  }
  return true;
}

// Sorts the input positions by quantized key, then moves the original keys and the values into the
// output in that order: later passes read the tile ids from the keys.
template <typename Key, typename QKey>
void CpuRadixSort::sort_quantized(const Key* keys, const uint32_t* values, Key* keys_out, uint32_t* values_out,
                                  uint32_t n, const SortInput& input, std::vector<QKey>& q,
                                  std::vector<QKey>& q_scratch, uint32_t q_bits) {
  if (input.depth_in_low_bits) {
    uint32_t lo = std::numeric_limits<uint32_t>::max(), hi = 0;
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t bits = uint32_t(keys[i]);
      if (positive_finite_float(bits)) {
        lo = std::min(lo, bits);
        hi = std::max(hi, bits);
      }
    }
    // As antimatter15/splat: level = (depth - min) * (levels - 1) / (max - min), in doubles; one level
    // for every depth when they are all equal.
    const double min_depth = hi >= lo ? double(std::bit_cast<float>(lo)) : 0.0;
    const double scale = hi > lo ? double(kLastDepthLevel) / (double(std::bit_cast<float>(hi)) - min_depth) : 0.0;
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t bits = uint32_t(keys[i]);
      const uint32_t level =
          positive_finite_float(bits)
              ? std::min(kLastDepthLevel, uint32_t((double(std::bit_cast<float>(bits)) - min_depth) * scale))
              : kNotADepthLevel;
      if constexpr (sizeof(Key) > 4)
        q[i] = QKey(((keys[i] >> 32) << kQuantizedBits) | level);
      else
        q[i] = QKey(level);
    }
  } else {
    Key lo = std::numeric_limits<Key>::max(), hi = 0;
    for (uint32_t i = 0; i < n; ++i) {
      lo = std::min(lo, keys[i]);
      hi = std::max(hi, keys[i]);
    }
    const double scale = hi > lo ? double(kLastIntegerLevel) / double(hi - lo) : 0.0;
    for (uint32_t i = 0; i < n; ++i)
      q[i] = QKey(std::min(kLastIntegerLevel, uint32_t(double(keys[i] - lo) * scale)));
  }
  for (uint32_t i = 0; i < n; ++i) positions_[i] = i;
  const bool in_scratch = cpu_radix_sort(std::span<QKey>(q.data(), n), std::span<uint32_t>(positions_.data(), n),
                                         std::span<QKey>(q_scratch.data(), n),
                                         std::span<uint32_t>(positions_scratch_.data(), n), q_bits);
  const uint32_t* order = in_scratch ? positions_scratch_.data() : positions_.data();
  for (uint32_t i = 0; i < n; ++i) {
    keys_out[i] = keys[order[i]];
    values_out[i] = values[order[i]];
  }
}

bool CpuRadixSort::record(vk::CommandStream& stream, SortInput& input) {
  KeyBuffers& kb = input.keys;
  if (kb.capacity > reserved_keys_)
    throw std::logic_error(name() + ": reserve() was not called for " + std::to_string(kb.capacity) + " keys");
  const auto* state_bytes = static_cast<const char*>(input.state.mapped());
  if (!state_bytes) throw std::logic_error(name() + ": the sort state buffer is not host-visible");

  // Runs the frame so far: it writes the count and the keys.
  stream.flush();
  SortState state;
  std::memcpy(&state, state_bytes + input.state_offset, sizeof(state));
  const uint32_t n = state.count;
  if (n > kb.capacity)
    throw std::runtime_error(name() + ": " + std::to_string(n) + " keys to sort but the key buffers hold " +
                             std::to_string(kb.capacity));
  const bool in_place = access_ == HostAccess::kAuto && device_memory_cached_ && kb.keys.mapped() &&
                        kb.values.mapped() && kb.keys_alt.mapped() && kb.values_alt.mapped();
  last_used_staging_ = !in_place;
  last_host_ms_ = 0;
  if (n == 0) return false;

  const VkDeviceSize key_bytes = VkDeviceSize(n) * kb.key_bytes();
  const VkDeviceSize value_bytes = VkDeviceSize(n) * sizeof(uint32_t);
  char* keys_in;
  char* values_in;
  char* keys_out;
  char* values_out;
  if (in_place) {
    keys_in = static_cast<char*>(kb.keys.mapped());
    values_in = static_cast<char*>(kb.values.mapped());
    keys_out = static_cast<char*>(kb.keys_alt.mapped());
    values_out = static_cast<char*>(kb.values_alt.mapped());
  } else {
    // Sized by reserve() on the devices that need it; grown here only for Device buffers that are
    // unexpectedly not mapped, which is safe: the flush left no submitted work using the old one.
    ensure_staging(kb.capacity);
    const VkBufferCopy keys_down{0, 0, key_bytes};
    const VkBufferCopy values_down{0, 2 * key_bytes, value_bytes};
    vkCmdCopyBuffer(stream.cmd(), kb.keys.handle(), staging_.handle(), 1, &keys_down);
    vkCmdCopyBuffer(stream.cmd(), kb.values.handle(), staging_.handle(), 1, &values_down);
    stream.flush();  // its barrier makes the copies visible to the host
    char* base = static_cast<char*>(staging_.mapped());
    keys_in = base;
    keys_out = base + key_bytes;
    values_in = base + 2 * key_bytes;
    values_out = values_in + value_bytes;
  }

  const auto start = std::chrono::steady_clock::now();
  auto* values_in_u32 = reinterpret_cast<uint32_t*>(values_in);
  auto* values_out_u32 = reinterpret_cast<uint32_t*>(values_out);
  const bool in_out =
      kb.wide_keys ? sort_on_host(reinterpret_cast<uint64_t*>(keys_in), values_in_u32,
                                  reinterpret_cast<uint64_t*>(keys_out), values_out_u32, n, input)
                   : sort_on_host(reinterpret_cast<uint32_t*>(keys_in), values_in_u32,
                                  reinterpret_cast<uint32_t*>(keys_out), values_out_u32, n, input);
  last_host_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (in_place) return in_out;

  // Host writes before a submission are visible to it: only the copies need a barrier after them.
  const VkBufferCopy keys_up{in_out ? key_bytes : 0, 0, key_bytes};
  const VkBufferCopy values_up{2 * key_bytes + (in_out ? value_bytes : 0), 0, value_bytes};
  vkCmdCopyBuffer(stream.cmd(), staging_.handle(), kb.keys.handle(), 1, &keys_up);
  vkCmdCopyBuffer(stream.cmd(), staging_.handle(), kb.values.handle(), 1, &values_up);
  vk::barrier(stream.cmd());
  return false;
}

}  // namespace tilesplat
