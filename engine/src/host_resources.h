// The host's memory and cores, and host work spread over the cores in contiguous ranges: range r of `count`
// items over `ranges` threads is [range_begin(count, ranges, r), range_begin(count, ranges, r + 1)). Each
// range is handled in order by one thread, so work that keeps its own range's order (a stable sort's
// counting, a running maximum, a compaction) gives the one-thread result, bit for bit, with carries joined
// afterwards.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <system_error>
#include <thread>
#include <vector>

namespace tilesplat::detail {

// The machine's physical memory in bytes (0 where it cannot be read).
inline uint64_t host_physical_memory() {
  const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page_size > 0 ? uint64_t(pages) * uint64_t(page_size) : 0;
}

// The threads for `items` of host work: the host's cores, but no more than one per `items_per_thread`
// (starting a thread costs tens of microseconds; a small scene stays on the caller's thread).
inline unsigned host_threads_for(size_t items, size_t items_per_thread = size_t(1) << 16) {
  const size_t cores = std::max(1u, std::thread::hardware_concurrency());
  return unsigned(std::clamp<size_t>(items / std::max<size_t>(items_per_thread, 1), 1, cores));
}

// floor(count * range / ranges), without the product's overflow.
inline size_t range_begin(size_t count, unsigned ranges, unsigned range) {
  return count / ranges * range + count % ranges * range / ranges;
}

// Runs body(range, begin, end) for each of `ranges` ranges of [0, count), range 0 on the caller's thread
// and the others on threads of their own, and returns when all are done. An exception a body throws is
// rethrown here (the first range's that threw, by range order).
template <typename Body>
void for_each_range(size_t count, unsigned ranges, const Body& body) {
  ranges = std::max(ranges, 1u);
  std::vector<std::exception_ptr> errors(ranges);
  const auto run = [&](unsigned r) {
    try {
      body(r, range_begin(count, ranges, r), range_begin(count, ranges, r + 1));
    } catch (...) {
      errors[r] = std::current_exception();
    }
  };
  std::vector<std::thread> threads;
  threads.reserve(ranges - 1);
  for (unsigned r = 1; r < ranges; ++r) {
    try {
      threads.emplace_back(run, r);
    } catch (const std::system_error&) {  // no thread to be had: this one does the range
      run(r);
    }
  }
  run(0);
  for (std::thread& thread : threads) thread.join();
  for (const std::exception_ptr& error : errors)
    if (error) std::rethrow_exception(error);
}

}  // namespace tilesplat::detail
