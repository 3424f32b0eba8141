#include "reconstruct/heap_retention.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace stereorig {

bool RetainFreedHeapMemory() {
#if defined(__GLIBC__)
  // Fixed values also end glibc's dynamic thresholds (which chase the
  // largest block freed so far and trim at twice it).
  const int mmap_ok = mallopt(M_MMAP_THRESHOLD, int(kHeapMmapThresholdBytes));
  const int trim_ok = mallopt(M_TRIM_THRESHOLD, int(kHeapTrimThresholdBytes));
  return mmap_ok == 1 && trim_ok == 1;
#else
  return false;
#endif
}

}  // namespace stereorig
