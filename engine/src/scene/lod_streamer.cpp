// LodStreamer: a LOD set's levels loaded on a thread of its own while the caller draws what it has.
//
// One worker thread and three slots under one mutex: the request queued (the newest; a newer one
// replaces it), whether a load runs, and the load finished and not yet taken (a newer one replaces it
// too: the caller wants the levels of its newest camera, not every step on the way). The caller's
// thread chooses the levels (select_lod_levels is cheap: the index's boxes), the worker reads the files.
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

#include "tilesplat/lod_set.h"

namespace tilesplat {

struct LodStreamer::Impl {
  const LodSet& set;
  const uint64_t splat_budget;
  const LoadOptions options;
  const std::function<void()> on_loaded;

  mutable std::mutex mutex;
  std::condition_variable work_ready;  // a request was queued, or the streamer is stopping
  std::condition_variable load_done;   // a load finished or failed
  std::optional<LodSelection> queued;
  bool loading = false;
  bool stopping = false;
  std::optional<LodLoad> finished;
  std::exception_ptr failure;
  // The levels of the newest request accepted: a request with equal levels is none.
  std::optional<std::vector<int>> newest_levels;
  std::thread worker;  // last: it starts once the members above exist

  Impl(const LodSet& set_, uint64_t budget, LoadOptions options_, std::function<void()> on_loaded_)
      : set(set_),
        splat_budget(budget),
        options(std::move(options_)),
        on_loaded(std::move(on_loaded_)),
        worker([this] { work(); }) {}

  ~Impl() {
    {
      const std::lock_guard lock(mutex);
      stopping = true;
      queued.reset();
    }
    work_ready.notify_one();
    worker.join();
  }

  void work() {
    std::unique_lock lock(mutex);
    while (true) {
      work_ready.wait(lock, [this] { return stopping || queued; });
      if (stopping) return;
      LodSelection selection = std::move(*queued);
      queued.reset();
      loading = true;
      lock.unlock();
      std::optional<LodLoad> loaded;
      std::exception_ptr error;
      try {
        const auto start = std::chrono::steady_clock::now();
        GaussianScene scene = set.load_selection(selection, options);
        const std::chrono::duration<double, std::milli> took = std::chrono::steady_clock::now() - start;
        loaded = LodLoad{std::move(selection), std::move(scene), took.count()};
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      if (error) {
        failure = error;
        newest_levels.reset();  // the same levels may be asked for again
      } else {
        finished = std::move(loaded);
      }
      // The load can be taken from here on, and the callback (which wakes whoever takes it) runs; the
      // streamer is busy until it has returned, so that wait_and_take() returns after it.
      if (on_loaded) {
        lock.unlock();
        on_loaded();
        lock.lock();
      }
      loading = false;
      load_done.notify_all();
    }
  }

  std::optional<LodLoad> take_locked() {
    if (failure) std::rethrow_exception(std::exchange(failure, nullptr));
    return std::exchange(finished, std::nullopt);
  }
};

LodStreamer::LodStreamer(const LodSet& set, uint64_t splat_budget, LoadOptions options,
                         std::function<void()> on_loaded)
    : impl_(std::make_unique<Impl>(set, splat_budget, std::move(options), std::move(on_loaded))) {}

LodStreamer::~LodStreamer() = default;

LodSelection LodStreamer::request(const Camera& camera) {
  LodSelection selection = select_lod_levels(impl_->set, camera, impl_->splat_budget);
  {
    const std::lock_guard lock(impl_->mutex);
    if (impl_->newest_levels == selection.chunk_levels) return selection;
    impl_->newest_levels = selection.chunk_levels;
    impl_->queued = selection;
  }
  impl_->work_ready.notify_one();
  return selection;
}

std::optional<LodLoad> LodStreamer::take() {
  const std::lock_guard lock(impl_->mutex);
  return impl_->take_locked();
}

std::optional<LodLoad> LodStreamer::wait_and_take() {
  std::unique_lock lock(impl_->mutex);
  impl_->load_done.wait(lock, [this] { return !impl_->queued && !impl_->loading; });
  return impl_->take_locked();
}

bool LodStreamer::busy() const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->queued || impl_->loading;
}

uint64_t LodStreamer::splat_budget() const {
  return impl_->splat_budget;
}

}  // namespace tilesplat
