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

// Sorts `keys` (only their low key_bits, 1 to 64, may be set) with `sorter`, timing it with `timer`.
// Throws std::invalid_argument for key_bits out of range, more than 2^31 keys or a key with higher bits.
Renderer::SortRun run_key_sort(vk::Context& ctx, vk::GpuTimer& timer, SortStrategy& sorter,
                               const std::vector<uint64_t>& keys, uint32_t key_bits);

// The checks of run_key_sort, on their own: a caller checks before it waits for any device work.
void check_sort_keys(const std::vector<uint64_t>& keys, uint32_t key_bits);

}  // namespace tilesplat
