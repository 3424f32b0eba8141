#include "reconstruct/parallel_for.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

namespace stereorig {
namespace {

TEST(ParallelForChunks, CoversEveryIndexOnce) {
  for (const int n : {0, 1, 2, 7, 100})
    for (const int threads : {1, 2, 3, 8}) {
      std::vector<std::atomic<int>> hits(static_cast<size_t>(n));
      ParallelForChunks(n, threads, [&](int b, int e) {
        for (int i = b; i < e; ++i) ++hits[size_t(i)];
      });
      for (int i = 0; i < n; ++i) EXPECT_EQ(hits[size_t(i)].load(), 1) << "n " << n << " threads " << threads;
    }
}

// An exception in a worker's chunk reaches the caller, after every chunk has
// run; leaving the std::thread it would have ended the process.
TEST(ParallelForChunks, AWorkersExceptionReachesTheCaller) {
  std::atomic<int> chunks{0};
  try {
    ParallelForChunks(100, 4, [&](int b, int) {
      ++chunks;
      if (b > 0) throw std::runtime_error("chunk " + std::to_string(b));
    });
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "chunk 25");  // the first throwing chunk, in chunk order
  }
  EXPECT_EQ(chunks.load(), 4);
}

}  // namespace
}  // namespace stereorig
