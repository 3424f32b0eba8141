// A minimal parallel loop over [0, n) on std::threads, for row-parallel image
// work. Chunks are contiguous so each thread walks memory in order.
#pragma once

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

namespace stereorig {

// Calls fn(begin, end) on `num_threads` disjoint contiguous chunks of [0, n).
// num_threads <= 1 runs inline. fn must be thread-safe across chunks. If fn
// throws, every chunk still finishes (or throws) and its thread is joined;
// then the first chunk's exception, in chunk order, is rethrown here (an
// exception leaving a std::thread would end the process).
template <typename Fn>
void ParallelForChunks(int n, int num_threads, Fn&& fn) {
  num_threads = std::max(1, std::min(num_threads, n));
  if (num_threads == 1) {
    if (n > 0) fn(0, n);
    return;
  }
  const int chunk = (n + num_threads - 1) / num_threads;
  std::vector<std::exception_ptr> errors(num_threads);
  auto run = [&fn, &errors](int t, int b, int e) {
    try {
      fn(b, e);
    } catch (...) {
      errors[t] = std::current_exception();
    }
  };
  std::vector<std::thread> threads;
  threads.reserve(num_threads - 1);
  try {
    for (int t = 1; t < num_threads; ++t) {
      const int b = t * chunk, e = std::min(n, b + chunk);
      if (b < e) threads.emplace_back(run, t, b, e);
    }
  } catch (...) {  // no thread to be had: those started are joined before the error goes on
    for (auto& th : threads) th.join();
    throw;
  }
  run(0, 0, std::min(n, chunk));
  for (auto& th : threads) th.join();
  for (const std::exception_ptr& error : errors)
    if (error) std::rethrow_exception(error);
}

}  // namespace stereorig
