// Census transform and semi-global matching (SGM) on a rectified 8-bit pair,
// our own implementation: costs are uint8 Hamming distances of census
// signatures (up to 9x7 window, 62 bits), path costs are uint16 (bytes in
// the AVX2 kernels where that is exact: SgmPathCostsFitBytes), one
// contiguous run of disparities per pixel. The inner loops (sgm_kernels.h)
// run in AVX2 where the build has it, else portably; both give the same
// disparities.
//
// Disparity convention everywhere in reconstruct/: a left pixel x matches the
// right pixel x - d (rectified rows are aligned, so d >= 0 for points in
// front of a parallel rig).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace stereorig {

// 62-bit census signatures of a grey image: bit k says whether neighbour k of
// the 9x7 window is darker than the centre. Borders replicate the edge pixel.
struct CensusImage {
  int width = 0;
  int height = 0;
  int row_begin = 0;           // first row held
  int signature_bits = 64;     // bits a signature may use (the low ones); those above are 0. Default 64
  std::vector<uint64_t> bits;  // (rows held, width), row-major
  // Row y of the image; y must be one of the rows computed.
  const uint64_t* row(int y) const { return bits.data() + size_t(y - row_begin) * width; }
};

// Computes signatures for rows [row_begin, row_end) only (only those are held), on
// `num_threads` threads. `grey` is CV_8UC1. The window is (2*half_width+1) x
// (2*half_height+1) px, at most 63 bits.
// Columns outside [col_begin, col_end) are left 0 too (only the columns the
// matcher reads need signatures).
CensusImage CensusTransform(const cv::Mat& grey, int row_begin, int row_end, int num_threads, int half_width = 4,
                            int half_height = 3, int col_begin = 0, int col_end = 1 << 30);

inline constexpr int kCensusMaxCost = 62;  // bits in the largest (9x7) signature: the cost of "no match"

struct SgmOptions {
  int p1 = 8;                  // penalty for a 1 px disparity step, census bits; default 8
  int p2 = 80;                 // penalty for a larger step, census bits (> p1); default 80
  int num_paths = 4;           // 3 (left, right, top: one pass, no volume kept) or 4 (+bottom); default 4
  int uniqueness_percent = 5;  // best cost must beat every cost off the best+-1 by this %; default 5
  int lr_max_diff_px = 1;      // left-right consistency tolerance, whole px; default 1
  bool simd = true;            // AVX2 kernels if the build has them (else scalar); false = scalar; default true
  // 4 paths: rows per block of the forward sums the bottom->top pass reads
  // (census_sgm.cc); 0 = about sqrt(rows), the least memory. The result
  // does not depend on it, only memory and time do. Default 0.
  int block_rows = 0;
  void Check() const;  // throws InputError naming the bad field
};

// SGM over `region` (left image px) for integer disparities
// [min_disparity, min_disparity + num_disparities). Returns a CV_32FC1 image
// of region.size(): the disparity refined by an equiangular (symmetric V) fit
// of the aggregated cost, or NaN where the left-right check or the
// uniqueness test failed, or the best cost sits at the edge of the range.
cv::Mat SgmMatch(const CensusImage& left, const CensusImage& right, const cv::Rect& region, int min_disparity,
                 int num_disparities, const SgmOptions& options);

// SGM as above, but each pixel searches only the 2*radius_px+1 disparities
// [guide - radius_px, guide + radius_px] (moved inside [min_disparity,
// min_disparity + num_disparities) where they would leave it); guide_px:
// CV_16SC1 of region.size(), full-resolution px (GuideFromCoarse,
// sgm_guide.h). Path costs step between neighbours whose windows differ by
// comparing equal disparities; a disparity outside the neighbour's window
// counts as the maximum cost. A minimum at the edge of a pixel's window is
// rejected like one at the edge of the range. Where the truth lies inside
// every window along the paths this gives SgmMatch's disparities with
// 2*radius_px+1 disparities per pixel instead of num_disparities. A window
// as wide as the range runs SgmMatch.
cv::Mat SgmMatchGuided(const CensusImage& left, const CensusImage& right, const cv::Rect& region,
                       const cv::Mat& guide_px, int radius_px, int min_disparity, int num_disparities,
                       const SgmOptions& options);

// True if this build has the AVX2 kernels (SgmOptions::simd uses them).
bool SgmSimdAvailable();

// True if the AVX2 kernels keep the path costs in bytes (32 disparities per
// instruction; sgm_kernels.h, Avx2ByteKernels) for these options, signature
// width and disparities per pixel, which they do only where that gives the
// 16-bit path costs exactly. Every path cost lies in [0, max cost + p2] (max
// cost: kCensusMaxCost or the signatures' width), so a path's smallest cost
// does too, and the capped term a step compares, smallest + p2, is at most
// max cost + 2 p2 (with constant windows the smallest is at most max cost,
// but a guided search's predecessor may have its best outside the pixel's
// window); the bytes are taken while that is <= 254, and the uniqueness
// test needs a lane off the best +-1 (more than 3 disparities).
// The default p2 of 80: 62 + 160 = 222, so bytes; p2 above 95 (96 with
// 62-bit signatures): 16 bits. Either way the same disparities.
bool SgmPathCostsFitBytes(const SgmOptions& options, int signature_bits, int num_disparities);

}  // namespace stereorig
