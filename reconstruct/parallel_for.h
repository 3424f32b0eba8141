// A minimal parallel loop over [0, n) on std::threads, for row-parallel image
// work. Chunks are contiguous so each thread walks memory in order.
#pragma once

#include <algorithm>
#include <thread>
#include <vector>

namespace stereorig {

// Calls fn(begin, end) on `num_threads` disjoint contiguous chunks of [0, n).
// num_threads <= 1 runs inline. fn must be thread-safe across chunks.
template <typename Fn>
void ParallelForChunks(int n, int num_threads, Fn&& fn) {
  num_threads = std::max(1, std::min(num_threads, n));
  if (num_threads == 1) {
    if (n > 0) fn(0, n);
    return;
  }
  std::vector<std::thread> threads;
  threads.reserve(num_threads - 1);
  const int chunk = (n + num_threads - 1) / num_threads;
  for (int t = 1; t < num_threads; ++t) {
    const int b = t * chunk, e = std::min(n, b + chunk);
    if (b < e) threads.emplace_back([&fn, b, e] { fn(b, e); });
  }
  fn(0, std::min(n, chunk));
  for (auto& th : threads) th.join();
}

}  // namespace stereorig
