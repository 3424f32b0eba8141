// Which pixels of a region of a disparity map hold a disparity (a finite
// value), one bit per pixel, for growing (region_grow.h).
//
// Growing reads the validity of the pixels around every pixel it tries: the
// plane fit over a 7x7 window (local_plane.h), the seeds (valid pixels with
// an empty 4-neighbour). As bits, a window row is one shift of a word and
// the fit visits its valid pixels only; the seeds come 64 pixels at a time.
// The caller keeps it in step with the map (Set after each write).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace stereorig {

class ValidityBits {
 public:
  // disparity: CV_32FC1; a pixel of `roi` (inside it) is valid iff finite.
  ValidityBits(const cv::Mat& disparity, const cv::Rect& roi);

  // (x, y) inside roi.
  bool Test(int x, int y) const {
    const int o = x - roi_.x;
    return (Row(y)[o >> 6] >> (o & 63)) & 1;
  }
  void Set(int x, int y, bool valid) {
    const int o = x - roi_.x;
    uint64_t& word = Row(y)[o >> 6];
    word = (word & ~(uint64_t(1) << (o & 63))) | (uint64_t(valid) << (o & 63));
  }
  // Bit i (i < count) is pixel (x + i, y); x .. x + count - 1 inside roi,
  // 1 <= count <= 63.
  uint64_t Span(int x, int y, int count) const {
    const int o = x - roi_.x, s = o & 63;
    const uint64_t* w = Row(y) + (o >> 6);
    // w[1] exists: every row has a spare word at its end. Shifted in two
    // steps, so that s = 0 shifts by 64 (no bits) without a branch.
    const uint64_t bits = (w[0] >> s) | ((w[1] << 1) << (63 - s));
    return bits & ((uint64_t(1) << count) - 1);
  }

  // The valid pixels of roi with an empty 4-neighbour inside roi, in raster
  // order (a neighbour outside roi counts as not empty).
  std::vector<cv::Point> EdgePixels() const;

 private:
  const uint64_t* Row(int y) const { return words_.data() + size_t(y - roi_.y) * size_t(stride_); }
  uint64_t* Row(int y) { return words_.data() + size_t(y - roi_.y) * size_t(stride_); }

  cv::Rect roi_;
  int stride_ = 0;  // words per row: ceil(width / 64) + 1 (the spare one is 0)
  std::vector<uint64_t> words_;
};

}  // namespace stereorig
