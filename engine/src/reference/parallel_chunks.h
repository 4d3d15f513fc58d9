// The float64 reference's one way of using every CPU core: chunks of an index range handed to threads.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace tilesplat::reference {

// The threads for `work_items` items: every core, never more threads than items.
inline unsigned worker_count(size_t work_items) {
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  return static_cast<unsigned>(std::min<size_t>(hardware, std::max<size_t>(1, work_items)));
}

// Runs body(begin, end) over [0, count) in chunks handed out by an atomic counter, so threads that
// draw cheap chunks (empty tiles, culled Gaussians) take more of them.
template <typename Body>
void parallel_chunks(size_t count, size_t chunk, const Body& body) {
  if (count == 0) return;
  const size_t chunks = (count + chunk - 1) / chunk;
  std::atomic<size_t> next_chunk{0};
  auto worker = [&] {
    for (size_t c = next_chunk.fetch_add(1); c < chunks; c = next_chunk.fetch_add(1))
      body(c * chunk, std::min(count, (c + 1) * chunk));
  };
  const unsigned threads = worker_count(chunks);
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& thread : pool) thread.join();
}

}  // namespace tilesplat::reference
