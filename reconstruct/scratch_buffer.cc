#include "reconstruct/scratch_buffer.h"

#include <algorithm>
#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace stereorig::internal {

namespace {
constexpr size_t kHugePageBytes = size_t(2) << 20;
}  // namespace

void* AllocateScratch(size_t bytes) {
  // Smaller arrays gain nothing from huge pages; they take the ordinary heap.
  const bool huge = bytes >= kHugePageBytes;
  const size_t alignment = huge ? kHugePageBytes : 64;
  const size_t rounded = (std::max<size_t>(bytes, 1) + alignment - 1) / alignment * alignment;
  void* p = std::aligned_alloc(alignment, rounded);
  if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  // Advice only: where transparent huge pages are off it fails harmlessly.
  if (huge) madvise(p, rounded, MADV_HUGEPAGE);
#endif
  return p;
}

void FreeScratch::operator()(void* p) const { std::free(p); }

}  // namespace stereorig::internal
