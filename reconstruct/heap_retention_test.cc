// RetainFreedHeapMemory (heap_retention.h): a freed block the size of the
// runtime's maps is reused without faulting its pages in again, measured by
// the kernel's count of the process's minor page faults. The control, with
// glibc's small fixed mmap threshold, shows the count sees the faults.
#include "reconstruct/heap_retention.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdlib>
#include <cstring>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace stereorig {
namespace {

long MinorFaults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

// Allocates `bytes`, writes every page, frees it; the faults that took.
// (The asm keeps the compiler from dropping the malloc/memset/free.)
long FaultsOfOneBlock(size_t bytes) {
  const long before = MinorFaults();
  char* p = static_cast<char*>(std::malloc(bytes));
  if (p == nullptr) return -1;
  std::memset(p, 1, bytes);
  asm volatile("" : : "r"(p) : "memory");
  std::free(p);
  return MinorFaults() - before;
}

#if defined(__GLIBC__)
TEST(HeapRetention, AFreedMapSizedBlockIsReusedWithoutFaultingItInAgain) {
  constexpr size_t kBytes = size_t(2) << 20;    // a 752 x 582 float map: 1.75 MB
  constexpr long kPages = long(kBytes / 4096);  // 512
  // Control: a fixed 128 KB mmap threshold (glibc's start value, without
  // its dynamic raise): every block is its own mapping, unmapped on free,
  // so each round faults all its pages in again (huge pages aside: the
  // test needs only "most").
  // Under AddressSanitizer (STEREORIG_SANITIZE) malloc is not glibc's and
  // mallopt does nothing (returns 0): there is nothing to test.
  if (mallopt(M_MMAP_THRESHOLD, 128 * 1024) != 1) GTEST_SKIP() << "malloc is not glibc's (a sanitizer build?)";
  // Tests run before this one in the same process can leave a free chunk of
  // this size in the heap, which malloc then serves without a fresh mapping
  // or a fault (0 faults, seen with the whole binary in one process):
  // malloc_trim hands every free page back first.
  malloc_trim(0);
  FaultsOfOneBlock(kBytes);
  EXPECT_GT(FaultsOfOneBlock(kBytes), kPages / 2) << "the fault count does not see a fresh mapping's pages";
  ASSERT_TRUE(RetainFreedHeapMemory());
  FaultsOfOneBlock(kBytes);  // the heap grows once...
  // ...and then keeps it: a few faults at most (malloc's own bookkeeping).
  EXPECT_LT(FaultsOfOneBlock(kBytes), 16);
  EXPECT_LT(FaultsOfOneBlock(kBytes), 16);
}
#endif

}  // namespace
}  // namespace stereorig
