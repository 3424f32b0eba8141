// The parallel loop of the row-parallel image steps, on oneTBB's
// work-stealing pool (the pool OpenCV's own parallel loops run on here).
//
// One pool, not threads per loop: the modules of a capture run in parallel
// and each splits its row loops, so with threads per loop a core one module
// has finished with sat idle while the other's loop ran on in its fixed
// halves, and every loop paid a thread start. On the pool a loop is cut
// into chunks as threads come free, a thread done with its own module takes
// chunks of the other's, and the threads live for the process (bench on the demo
// captures, four alternated pairs: 7.7-9.0 -> 9.2-9.4 objects/s at the same
// CPU per object; docs/reconstruct-log.md, "Session 26").
#pragma once

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <memory>
#include <utility>

namespace stereorig {

// Calls fn(begin, end) on disjoint contiguous chunks that cover [0, n) once
// each. num_threads <= 1 runs the whole range here in one call; otherwise
// the chunks (their number and bounds are the pool's choice) run on the
// threads of the pool the caller is in (WorkerPool below; outside one, the
// process's: one per hardware thread). So fn's result must not depend on
// where the chunks start, and fn must be thread-safe across chunks. If fn
// throws, chunks not yet started are skipped and, once the running ones have
// returned, one of the exceptions thrown is rethrown here.
template <typename Fn>
void ParallelForChunks(int n, int num_threads, Fn&& fn) {
  if (n <= 0) return;
  if (num_threads <= 1 || n == 1) {
    fn(0, n);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, n),
                    [&fn](const tbb::blocked_range<int>& chunk) { fn(chunk.begin(), chunk.end()); });
}

// A pool of at most `threads` threads (fewer if the machine has fewer
// hardware threads): the ParallelForChunks loops started inside Run(), and
// OpenCV's, share them. Copies share the pool. Run() may be called from
// several threads at once.
class WorkerPool {
 public:
  WorkerPool() : WorkerPool(1) {}
  // Capped at the hardware threads here: oneTBB warns on stderr when asked
  // for more workers than it has.
  explicit WorkerPool(int threads)
      : arena_(std::make_shared<tbb::task_arena>(std::clamp(threads, 1, tbb::info::default_concurrency()))) {}
  int max_threads() const { return arena_->max_concurrency(); }
  template <typename Fn>
  auto Run(Fn&& fn) const {
    return arena_->execute(std::forward<Fn>(fn));
  }

 private:
  std::shared_ptr<tbb::task_arena> arena_;
};

}  // namespace stereorig
