// A sort of given keys by one strategy, outside any frame: what Renderer::sort_keys runs for the sort
// micro-benchmark (tilesplat-bench --sort-bench) and the sort tests. The keys go up in buffers of their
// own; the strategy's scratch is the one the renderer's frames use.
#pragma once
#include <cstdint>
#include <vector>

#include "sort/sort_strategy.h"
#include "tilesplat/renderer.h"
#include "vulkan/context.h"
#include "vulkan/gpu_timer.h"

namespace tilesplat {

// Throws std::invalid_argument for key_bits out of 1..64, more than 2^31 keys or a key with bits above
// key_bits: what run_key_sort takes, checked before any device work (Renderer::sort_keys).
void check_sort_keys(const std::vector<uint64_t>& keys, uint32_t key_bits);

// Sorts `keys`, which check_sort_keys accepted, with `sorter`, timing it with `timer`.
Renderer::SortRun run_key_sort(vk::Context& ctx, vk::GpuTimer& timer, SortStrategy& sorter,
                               const std::vector<uint64_t>& keys, uint32_t key_bits);

}  // namespace tilesplat
