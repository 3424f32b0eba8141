// A large, short-lived scratch array (SGM's cost volume and path sums, tens
// of MB per call): neither zeroed nor kept between calls. On Linux an array
// of 2 MB or more is its own anonymous mapping on 2 MB boundaries, marked for
// transparent huge pages, so the kernel maps it in 2 MB faults rather than
// 4 KB ones, and unmapped when the array goes. (Not from malloc's heap: a
// heap range once marked for huge pages would fault in 2 MB at a time for
// whatever small allocations reuse it after the array is freed, which
// raised the bench's runtime peak from ~250 to 302 MB.) Measured on the
// demo cup (`reconstruct`, both modules): the SGM calls' 4 KB faults were
// ~2/3 of the process's 65k minor faults.
#pragma once

#include <cstddef>

namespace stereorig {

namespace internal {
void* AllocateScratch(size_t bytes);  // never null (throws std::bad_alloc)
void FreeScratch(void* p, size_t bytes);
}  // namespace internal

// `count` elements of a trivial type T, contents unspecified until written.
template <typename T>
class ScratchArray {
 public:
  explicit ScratchArray(size_t count)
      : data_(static_cast<T*>(internal::AllocateScratch(count * sizeof(T)))), size_(count) {}
  ~ScratchArray() { internal::FreeScratch(data_, size_ * sizeof(T)); }
  ScratchArray(const ScratchArray&) = delete;
  ScratchArray& operator=(const ScratchArray&) = delete;
  T* data() { return data_; }
  size_t size() const { return size_; }

 private:
  T* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace stereorig
