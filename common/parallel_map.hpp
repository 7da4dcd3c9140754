// parallel_map: runs job(k) for k in [0, n) on a few std::thread workers. Used where independent pieces of work
// run side by side: the dips of the elastic gate (compare/gate/) and the cases of a study (study/study.cpp).
//
// Why std::thread and not an OpenMP parallel region: each piece of work may run a DEM engine, and the engine opens
// its own OpenMP parallel region at every step. Inside an outer OpenMP region those inner regions would be nested
// teams, whose threads libgomp creates afresh at every region (only the outermost level has a cached thread pool),
// thousands of times per run; and unless nesting is switched on (OMP_MAX_ACTIVE_LEVELS), libgomp runs them on one
// thread. A std::thread worker is an OpenMP initial thread instead: its engine's regions get a cached pool of their
// own, as in a single run, and a study can hand a case more threads while it runs.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace rbdem {

// Runs job(k) for every k in [0, n) on up to `threads` workers (at least one; never more than n), the calling
// thread being one of them. Each worker takes the next k from a shared counter, so the items start in order of k.
// A worker that finds no item left calls `on_idle` (if given) once and stops: a study hands that worker's thread to
// the cases still running. After a job throws, no worker takes a new item (those running finish theirs, and no
// worker that stops for that reason calls on_idle); once all workers stopped, the first exception is rethrown.
inline void parallel_map(std::size_t n, int threads, const std::function<void(std::size_t)>& job,
                         const std::function<void()>& on_idle = {}) {
  const std::size_t workers = std::max<std::size_t>(1, std::min<std::size_t>(n, std::size_t(std::max(threads, 1))));
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto fail = [&](std::exception_ptr e) {
    const std::lock_guard<std::mutex> lock(error_mutex);
    if (!error) error = std::move(e);
    failed = true;
  };
  auto work = [&]() {
    while (!failed.load()) {
      const std::size_t k = next.fetch_add(1);
      if (k >= n) {
        if (on_idle) on_idle();
        return;
      }
      try {
        job(k);
      } catch (...) {
        fail(std::current_exception());
        return;
      }
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(workers - 1);
  try {
    for (std::size_t w = 1; w < workers; ++w) pool.emplace_back(work);
  } catch (...) {
    fail(std::current_exception());  // no thread to start: the started workers stop after their item
  }
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace rbdem
