// An example of a sort strategy written outside tilesplat (tilesplat/sort_strategy.h): a stable
// LSD radix sort with 8-bit digits in which every GPU invocation owns a chunk of 256 consecutive
// pairs and walks it in order. The walk keeps the sort stable without ranking keys inside a
// workgroup, which makes it short to write (three small shaders) and slower than tilesplat's own
// radix sort; it is here to show the contract, not to win.
#pragma once

#include <tilesplat/sort_strategy.h>

#include <array>
#include <cstdint>

class SerialRadixSort final : public tilesplat::ExternalSortStrategy {
 public:
  static constexpr const char* kName = "serial-radix";

  explicit SerialRadixSort(const tilesplat::SortDevice& device);
  ~SerialRadixSort() override;
  SerialRadixSort(const SerialRadixSort&) = delete;
  SerialRadixSort& operator=(const SerialRadixSort&) = delete;

  void reserve(uint32_t max_keys) override;
  bool record(VkCommandBuffer command_buffer, const tilesplat::SortBuffers& buffers) override;
  uint64_t device_bytes() const override { return counts_bytes_; }

 private:
  void destroy();
  void release_counts();

  tilesplat::SortDevice device_;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  std::array<VkPipeline, 3> pipelines_{};  // count, scan, scatter
  VkBuffer counts_ = VK_NULL_HANDLE;       // RADIX x chunk_capacity_ per-chunk digit counts
  VkDeviceMemory counts_memory_ = VK_NULL_HANDLE;
  VkDeviceAddress counts_address_ = 0;
  uint64_t counts_bytes_ = 0;
  uint32_t chunk_capacity_ = 0;
};
