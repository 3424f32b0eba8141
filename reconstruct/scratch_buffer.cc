#include "reconstruct/scratch_buffer.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace stereorig::internal {

namespace {
constexpr size_t kHugePageBytes = size_t(2) << 20;
constexpr size_t kSmallAlignment = 64;

size_t RoundUp(size_t bytes, size_t to) { return (std::max<size_t>(bytes, 1) + to - 1) / to * to; }

#if defined(__linux__) && defined(MADV_HUGEPAGE)
constexpr bool kOwnMappings = true;
#else
constexpr bool kOwnMappings = false;
#endif
}  // namespace

void* AllocateScratch(size_t bytes) {
  if (!kOwnMappings || bytes < kHugePageBytes) {
    void* p = std::aligned_alloc(kSmallAlignment, RoundUp(bytes, kSmallAlignment));
    if (p == nullptr) throw std::bad_alloc();
    return p;
  }
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  // Map 2 MB more than needed, then unmap the unaligned head and the tail.
  const size_t size = RoundUp(bytes, kHugePageBytes);
  void* raw = mmap(nullptr, size + kHugePageBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const uintptr_t begin = reinterpret_cast<uintptr_t>(raw);
  const uintptr_t aligned = (begin + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
  if (aligned > begin) munmap(raw, aligned - begin);
  const uintptr_t end = begin + size + kHugePageBytes;
  if (end > aligned + size) munmap(reinterpret_cast<void*>(aligned + size), end - (aligned + size));
  // Advice only: where transparent huge pages are off it fails harmlessly.
  madvise(reinterpret_cast<void*>(aligned), size, MADV_HUGEPAGE);
  return reinterpret_cast<void*>(aligned);
#else
  return nullptr;  // unreachable: kOwnMappings is false
#endif
}

void FreeScratch(void* p, size_t bytes) {
  if (p == nullptr) return;
  if (!kOwnMappings || bytes < kHugePageBytes) {
    std::free(p);
    return;
  }
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  munmap(p, RoundUp(bytes, kHugePageBytes));
#endif
}

}  // namespace stereorig::internal
