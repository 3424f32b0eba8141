#include "reconstruct/parallel_for.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace stereorig {
namespace {

TEST(ParallelForChunks, CoversEveryIndexOnce) {
  for (const int n : {0, 1, 2, 7, 100, 10000})
    for (const int threads : {1, 2, 3, 8}) {
      std::vector<std::atomic<int>> hits(static_cast<size_t>(n));
      ParallelForChunks(n, threads, [&](int b, int e) {
        EXPECT_LT(b, e);
        for (int i = b; i < e; ++i) ++hits[size_t(i)];
      });
      for (int i = 0; i < n; ++i) EXPECT_EQ(hits[size_t(i)].load(), 1) << "n " << n << " threads " << threads;
    }
}

TEST(ParallelForChunks, OneThreadIsOneCallOnTheCallingThread) {
  const std::thread::id caller = std::this_thread::get_id();
  std::vector<std::pair<int, int>> calls;
  ParallelForChunks(100, 1, [&](int b, int e) {
    EXPECT_EQ(std::this_thread::get_id(), caller);
    calls.emplace_back(b, e);
  });
  ASSERT_EQ(calls.size(), 1u);
  EXPECT_EQ(calls[0], std::make_pair(0, 100));
}

// An exception in a chunk reaches the caller (leaving a worker thread it
// would end the process).
TEST(ParallelForChunks, AChunksExceptionReachesTheCaller) {
  try {
    ParallelForChunks(1000, 4, [&](int b, int e) {
      if (b <= 500 && 500 < e) throw std::runtime_error("index 500");
    });
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "index 500");
  }
}

// The threads that ran fn's chunks, each chunk taking ~0.2 ms so that every
// thread the pool has gets some.
template <typename Loop>
std::set<std::thread::id> ThreadsUsed(Loop&& loop) {
  std::mutex mutex;
  std::set<std::thread::id> ids;
  loop([&](int b, int e) {
    for (int i = b; i < e; ++i) std::this_thread::sleep_for(std::chrono::microseconds(200));
    std::lock_guard<std::mutex> lock(mutex);
    ids.insert(std::this_thread::get_id());
  });
  return ids;
}

// The runtime's case: two modules in parallel, each splitting its rows. The
// pool caps the threads of both levels together (threads per loop used up
// to 2 x 2); and a thread done with the quick module takes rows of the
// slow one.
TEST(WorkerPool, NestedLoopsShareItsThreads) {
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "needs 2 hardware threads";
  const WorkerPool pool(2);
  std::set<std::thread::id> all, slow_module;
  std::mutex mutex;
  pool.Run([&] {
    ParallelForChunks(2, 2, [&](int b, int e) {
      for (int module = b; module < e; ++module) {
        const int rows = module == 0 ? 4 : 400;  // module 0 is done almost at once
        const std::set<std::thread::id> ids = ThreadsUsed([&](auto fn) { ParallelForChunks(rows, 2, fn); });
        std::lock_guard<std::mutex> lock(mutex);
        all.insert(ids.begin(), ids.end());
        if (module == 1) slow_module = ids;
      }
    });
  });
  EXPECT_LE(all.size(), 2u);
  EXPECT_EQ(slow_module.size(), 2u);
}

TEST(WorkerPool, OneThreadRunsEveryChunkOnTheCallingThread) {
  const std::thread::id caller = std::this_thread::get_id();
  const std::set<std::thread::id> ids =
      WorkerPool(1).Run([&] { return ThreadsUsed([&](auto fn) { ParallelForChunks(50, 8, fn); }); });
  EXPECT_EQ(ids, std::set<std::thread::id>{caller});
}

// Asked for more threads than the machine has, the pool takes what it has,
// without oneTBB's warning on stderr ("The number of workers is currently
// limited to ...") in every command's output.
TEST(WorkerPool, MoreThreadsThanTheMachineHasGiveTheMachinesQuietly) {
  const int hardware = int(std::thread::hardware_concurrency());
  testing::internal::CaptureStderr();
  const WorkerPool pool(4 * hardware + 4);
  const size_t used = pool.Run([&] { return ThreadsUsed([&](auto fn) { ParallelForChunks(400, 64, fn); }).size(); });
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(pool.max_threads(), hardware);
  EXPECT_LE(used, size_t(hardware));
  EXPECT_EQ(WorkerPool(1).max_threads(), 1);
}

TEST(WorkerPool, RunReturnsTheResultAndPassesExceptionsOn) {
  const WorkerPool pool(2);
  EXPECT_EQ(pool.Run([] { return 42; }), 42);
  EXPECT_THROW(pool.Run([]() -> int { throw std::invalid_argument("bad"); }), std::invalid_argument);
}

}  // namespace
}  // namespace stereorig
