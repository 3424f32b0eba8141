// A large, short-lived scratch array (SGM's cost volume and path sums, tens
// of MB per call): neither zeroed nor kept between calls. It is placed on
// 2 MB boundaries and, on Linux, marked for transparent huge pages, so the
// kernel maps it in 2 MB faults rather than 4 KB ones. Measured on the demo
// cup (`reconstruct`, both modules): the SGM calls' 4 KB faults were ~2/3
// of the process's 65k minor faults.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

namespace stereorig {

namespace internal {
void* AllocateScratch(size_t bytes);  // never null (throws std::bad_alloc)
struct FreeScratch {
  void operator()(void* p) const;
};
}  // namespace internal

// `count` elements of a trivial type T, contents unspecified until written.
template <typename T>
class ScratchArray {
 public:
  explicit ScratchArray(size_t count)
      : data_(static_cast<T*>(internal::AllocateScratch(count * sizeof(T)))), size_(count) {}
  T* data() { return data_.get(); }
  size_t size() const { return size_; }

 private:
  std::unique_ptr<T[], internal::FreeScratch> data_;
  size_t size_ = 0;
};

}  // namespace stereorig
