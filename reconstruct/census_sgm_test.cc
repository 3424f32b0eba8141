#include "reconstruct/census_sgm.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <utility>

namespace stereorig {
namespace {

// Bitwise equality of two CV_32FC1 disparity maps (NaN = NaN); counts the
// valid pixels of the first.
int ExpectIdentical(const cv::Mat& a, const cv::Mat& b, const std::string& what) {
  EXPECT_EQ(a.size(), b.size()) << what;
  int valid = 0, differ = 0;
  for (int y = 0; y < a.rows; ++y)
    for (int x = 0; x < a.cols; ++x) {
      const float va = a.at<float>(y, x), vb = b.at<float>(y, x);
      valid += !std::isnan(va);
      differ += std::memcmp(&va, &vb, sizeof(float)) != 0;
    }
  EXPECT_EQ(differ, 0) << what;
  return valid;
}

cv::Mat RandomImage(std::mt19937& rng, int w, int h) {
  cv::Mat img(h, w, CV_8UC1);
  std::uniform_int_distribution<int> grey(0, 255);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.at<uint8_t>(y, x) = uint8_t(grey(rng));
  return img;
}

// The right view of a fronto-parallel scene at disparity shift_px: left
// pixel x appears at right pixel x - shift_px (the last column repeats).
cv::Mat RightViewAt(const cv::Mat& left, int shift_px) {
  cv::Mat right(left.size(), CV_8UC1);
  for (int y = 0; y < left.rows; ++y)
    for (int x = 0; x < left.cols; ++x)
      right.at<uint8_t>(y, x) = left.at<uint8_t>(y, std::min(left.cols - 1, x + shift_px));
  return right;
}

// The signatures against their definition (census_sgm.h), computed here
// pixel by pixel: bit (count - 1 - k) is set iff neighbour k in raster order
// (centre skipped) is darker than the centre, borders replicate the edge.
// Widths that are not multiples of 32 exercise both the 32-pixel AVX2
// blocks and the per-pixel tail; grey levels 0..3 make ties (not darker)
// frequent.
TEST(CensusSgm, CensusTransformMatchesItsDefinition) {
  std::mt19937 rng(11);
  const int w = 101, h = 17;
  for (const int levels : {256, 4}) {
    cv::Mat img = RandomImage(rng, w, h);
    if (levels < 256) img = img / (256 / levels);
    for (const auto& [hw, hh] : {std::pair{1, 1}, std::pair{2, 3}, std::pair{4, 3}, std::pair{3, 2}})
      for (const auto& [c0, c1] : {std::pair{0, w}, std::pair{5, 77}}) {
        const int r0 = 2, r1 = 15;
        const CensusImage c = CensusTransform(img, r0, r1, 2, hw, hh, c0, c1);
        int wrong = 0;
        for (int y = r0; y < r1; ++y)
          for (int x = 0; x < w; ++x) {
            uint64_t expected = 0;
            if (x >= c0 && x < c1)
              for (int dy = -hh; dy <= hh; ++dy)
                for (int dx = -hw; dx <= hw; ++dx) {
                  if (dx == 0 && dy == 0) continue;
                  const uint8_t nb = img.at<uint8_t>(std::clamp(y + dy, 0, h - 1), std::clamp(x + dx, 0, w - 1));
                  expected = (expected << 1) | uint64_t(nb < img.at<uint8_t>(y, x));
                }
            wrong += c.row(y)[x] != expected;
          }
        EXPECT_EQ(wrong, 0) << "levels " << levels << ", window " << 2 * hw + 1 << "x" << 2 * hh + 1 << ", columns ["
                            << c0 << ", " << c1 << ")";
      }
  }
}

TEST(CensusSgm, SimdAndScalarPathsGiveIdenticalDisparities) {
  if (!SgmSimdAvailable()) GTEST_SKIP() << "this build has no AVX2 kernels (STEREORIG_NATIVE off or no AVX2)";
  std::mt19937 rng(5);
  const int w = 120, h = 50;
  int cases = 0, valid_total = 0;
  // Random texture and a right view shifted by 7 px (so many pixels match
  // and the valid path is exercised), and pure noise on both sides (so the
  // uniqueness and left-right rejections are). Ranges: below, at and above
  // multiples of 16 lanes, n = 3, negative minimum, regions at the borders
  // where part of the range falls off the right image.
  const cv::Mat left = RandomImage(rng, w, h);
  const cv::Mat shifted = RightViewAt(left, 7);
  const cv::Mat noise = RandomImage(rng, w, h);
  for (const cv::Mat* right : std::vector<const cv::Mat*>{&shifted, &noise}) {
    for (const int half_width : {2, 4}) {
      const CensusImage cl = CensusTransform(left, 0, h, 1, half_width, 3);
      const CensusImage cr = CensusTransform(*right, 0, h, 1, half_width, 3);
      for (const int n : {3, 15, 16, 17, 33, 64})
        for (const int min_d : {-5, 0, 4})
          for (const cv::Rect& region : {cv::Rect(0, 0, w, h), cv::Rect(3, 5, 40, 30), cv::Rect(w - 30, 10, 30, 20)})
            for (const int paths : {3, 4}) {
              SgmOptions o;
              o.num_paths = paths;
              o.p1 = paths == 3 ? 8 : 11;
              o.p2 = paths == 3 ? 80 : 1000;  // the largest p2 the options allow
              o.simd = true;
              const cv::Mat simd = SgmMatch(cl, cr, region, min_d, n, o);
              o.simd = false;
              const cv::Mat scalar = SgmMatch(cl, cr, region, min_d, n, o);
              valid_total += ExpectIdentical(simd, scalar,
                                             "n " + std::to_string(n) + " min " + std::to_string(min_d) + " paths " +
                                                 std::to_string(paths) + " x " + std::to_string(region.x));
              ++cases;
            }
    }
  }
  EXPECT_EQ(cases, 2 * 2 * 6 * 3 * 3 * 2);
  // Not vacuous: the shifted cases match most pixels whose range holds 7.
  EXPECT_GT(valid_total, 20000);
}

// Signatures using all 64 bits and only the lowest 8 (a 3x3 census): the
// AVX2 path's nibble-plane costs (16 and 2 planes) against the scalar
// path's 64-bit popcounts, which need no planes.
TEST(CensusSgm, NibblePlaneCostsEqualPopcountsForAnySignatureWidth) {
  if (!SgmSimdAvailable()) GTEST_SKIP() << "this build has no AVX2 kernels (STEREORIG_NATIVE off or no AVX2)";
  std::mt19937_64 rng(17);
  const int w = 90, h = 24, shift = 5;
  for (const int bits : {64, 8}) {
    CensusImage left, right;
    for (CensusImage* c : {&left, &right}) {
      c->width = w;
      c->height = h;
      c->signature_bits = bits;
      c->bits.resize(size_t(w) * h);
    }
    const uint64_t mask = bits == 64 ? ~uint64_t(0) : (uint64_t(1) << bits) - 1;
    for (uint64_t& b : left.bits) b = rng() & mask;
    // The right view: the left one moved by `shift` px, a few bits flipped.
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        right.bits[size_t(y) * w + x] =
            (left.bits[size_t(y) * w + std::min(w - 1, x + shift)] ^ (rng() & rng())) & mask;
    for (const int n : {16, 40}) {
      SgmOptions o;
      const cv::Mat simd = SgmMatch(left, right, cv::Rect(8, 0, 80, h), 0, n, o);
      o.simd = false;
      const cv::Mat scalar = SgmMatch(left, right, cv::Rect(8, 0, 80, h), 0, n, o);
      const int valid = ExpectIdentical(simd, scalar, "bits " + std::to_string(bits) + " n " + std::to_string(n));
      EXPECT_GT(valid, 80 * h / 2) << "bits " << bits;  // not vacuous: the shift is found
    }
  }
}

// SGM written out plainly from its definition (census_sgm.h), sharing no
// code with census_sgm.cc: whole int volumes, each path a loop of its own,
// the winner found by scanning. Disparity index d means min_d + d; regions
// are image px.
cv::Mat ReferenceSgm(const CensusImage& left, const CensusImage& right, const cv::Rect& region, int min_d, int n,
                     const SgmOptions& o) {
  const int w = region.width, h = region.height;
  auto at = [&](int x, int y, int d) { return (size_t(y) * w + x) * n + d; };
  std::vector<int> cost(size_t(w) * h * n);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int d = 0; d < n; ++d) {
        const int xl = region.x + x, xr = xl - (min_d + d);
        cost[at(x, y, d)] = xr >= 0 && xr < right.width
                                ? __builtin_popcountll(left.row(region.y + y)[xl] ^ right.row(region.y + y)[xr])
                                : kCensusMaxCost;
      }
  std::vector<int> total(cost.size(), 0);
  // One path, direction (dx, dy): each pixel after its predecessor (x - dx, y - dy).
  auto path = [&](int dx, int dy) {
    std::vector<int> path_cost(cost.size());
    const int step_y = dy < 0 ? -1 : 1, step_x = dx < 0 ? -1 : 1;
    for (int y = dy < 0 ? h - 1 : 0; y >= 0 && y < h; y += step_y)
      for (int x = dx < 0 ? w - 1 : 0; x >= 0 && x < w; x += step_x) {
        const int px = x - dx, py = y - dy;
        const bool first = px < 0 || px >= w || py < 0 || py >= h;
        int prev_min = 1 << 30;
        if (!first)
          for (int d = 0; d < n; ++d) prev_min = std::min(prev_min, path_cost[at(px, py, d)]);
        for (int d = 0; d < n; ++d) {
          int v = cost[at(x, y, d)];
          if (!first) {
            int best = std::min(path_cost[at(px, py, d)], prev_min + o.p2);
            if (d > 0) best = std::min(best, path_cost[at(px, py, d - 1)] + o.p1);
            if (d + 1 < n) best = std::min(best, path_cost[at(px, py, d + 1)] + o.p1);
            v += best - prev_min;
          }
          path_cost[at(x, y, d)] = v;
          total[at(x, y, d)] += v;
        }
      }
  };
  path(1, 0);
  path(-1, 0);
  path(0, 1);
  if (o.num_paths == 4) path(0, -1);
  // The right view's best costs, by right pixel (region-local x - d).
  cv::Mat out(h, w, CV_32FC1, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  std::vector<int> right_best(size_t(w) + n, 1 << 30);
  for (int y = 0; y < h; ++y) {
    std::fill(right_best.begin(), right_best.end(), 1 << 30);
    for (int x = 0; x < w; ++x)
      for (int d = 0; d < n; ++d) right_best[x - d + n] = std::min(right_best[x - d + n], total[at(x, y, d)]);
    for (int x = 0; x < w; ++x) {
      const int* s = &total[at(x, y, 0)];
      const int best = int(std::min_element(s, s + n) - s);  // the first smallest
      if (best == 0 || best == n - 1) continue;
      int second = 1 << 30;
      for (int d = 0; d < n; ++d)
        if (std::abs(d - best) > 1) second = std::min(second, s[d]);
      if (double(second) * (100 - o.uniqueness_percent) < double(s[best]) * 100) continue;
      bool consistent = false;
      for (int k = -o.lr_max_diff_px; k <= o.lr_max_diff_px; ++k)
        if (x + k >= 0 && x + k < w && best + k >= 0 && best + k < n)
          consistent |= total[at(x + k, y, best + k)] <= right_best[x - best + n];
      if (!consistent) continue;
      const double c0 = s[best - 1], c1 = s[best], c2 = s[best + 1];
      const double slope = std::max(c0, c2) - c1;
      const double delta = slope > 0 ? 0.5 * (c0 - c2) / slope : 0.0;
      out.at<float>(y, x) = float(min_d + best + delta);
    }
  }
  return out;
}

// Both kernel sets against ReferenceSgm, bit for bit: ranges of 3 to 270
// disparities (one to 17 blocks of 16 lanes: the unrolled instances and the
// run-time loop), padded and whole last blocks, 3 and 4 paths, a negative
// minimum, a region at the right border (part of the range off the right
// image), region heights of 20, 24, 7 and 1 rows (the 4-path forward sums
// are held in blocks of ~sqrt(h) rows: whole blocks, a short last block, a
// single row), a textured view shifted by 7 px (most pixels pass every test) and
// pure noise (uniqueness and left-right rejections).
TEST(CensusSgm, MatchesAPlainReferenceImplementation) {
  std::mt19937 rng(23);
  const int w = 96, h = 24;
  const cv::Mat left = RandomImage(rng, w, h);
  const cv::Mat shifted = RightViewAt(left, 7);
  const cv::Mat noise = RandomImage(rng, w, h);
  const CensusImage cl = CensusTransform(left, 0, h, 1, 2, 3);
  int cases = 0, valid_total = 0;
  for (const cv::Mat* right : std::vector<const cv::Mat*>{&shifted, &noise}) {
    const CensusImage cr = CensusTransform(*right, 0, h, 1, 2, 3);
    for (const int n : {3, 16, 21, 40, 96, 140, 270})
      for (const int min_d : {-3, 2})
        for (const cv::Rect& region :
             {cv::Rect(10, 2, 80, 20), cv::Rect(w - 25, 0, 25, h), cv::Rect(5, 9, 60, 7), cv::Rect(5, 11, 60, 1)})
          for (const int paths : {3, 4}) {
            SgmOptions o;
            o.num_paths = paths;
            const cv::Mat reference = ReferenceSgm(cl, cr, region, min_d, n, o);
            for (const bool simd : {true, false}) {
              o.simd = simd;
              const std::string what = "n " + std::to_string(n) + " min " + std::to_string(min_d) + " paths " +
                                       std::to_string(paths) + " region " + std::to_string(region.x) + "," +
                                       std::to_string(region.y) + " " + std::to_string(region.width) + "x" +
                                       std::to_string(region.height) + " simd " + std::to_string(simd);
              valid_total += ExpectIdentical(SgmMatch(cl, cr, region, min_d, n, o), reference, what);
              ++cases;
            }
          }
  }
  EXPECT_EQ(cases, 2 * 7 * 2 * 4 * 2 * 2);
  // Not vacuous: the shifted view matches most pixels whose range holds 7.
  EXPECT_GT(valid_total, 10000);
}

// The AVX2 kernels' byte path costs at the edge of where they are exact
// (SgmPathCostsFitBytes): 64-bit random signatures (costs up to 64, the
// largest any signature gives) with p2 = 95 (64 + 2 x 95 = 254: bytes) and
// 96 (16 bits), a small and a large p1, against the plain reference and the
// scalar kernels. Noise on both sides drives the path costs up to their
// ceiling, max cost + p2; a view shifted by 5 px with a few bits flipped
// keeps the valid path busy.
TEST(CensusSgm, BytePathCostsAreExactUpToTheirLimit) {
  if (!SgmSimdAvailable()) GTEST_SKIP() << "this build has no AVX2 kernels (STEREORIG_NATIVE off or no AVX2)";
  std::mt19937_64 rng(29);
  const int w = 90, h = 16, shift = 5;
  CensusImage left, shifted, noise;
  for (CensusImage* c : {&left, &shifted, &noise}) {
    c->width = w;
    c->height = h;
    c->signature_bits = 64;
    c->bits.resize(size_t(w) * h);
  }
  for (uint64_t& b : left.bits) b = rng();
  for (uint64_t& b : noise.bits) b = rng();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      shifted.bits[size_t(y) * w + x] = left.bits[size_t(y) * w + std::min(w - 1, x + shift)] ^ (rng() & rng());
  int cases = 0, valid_total = 0;
  for (const int p2 : {95, 96})
    for (const int p1 : {8, 94})
      for (const int n : {4, 17, 48, 130}) {
        SgmOptions o;
        o.p1 = p1;
        o.p2 = p2;
        EXPECT_EQ(SgmPathCostsFitBytes(o, 64, n), p2 == 95) << "p2 " << p2 << " n " << n;
        for (const CensusImage* right : {&shifted, &noise})
          for (const int paths : {3, 4}) {
            o.num_paths = paths;
            const cv::Rect region(6, 0, 84, h);
            const std::string what = "p2 " + std::to_string(p2) + " p1 " + std::to_string(p1) + " n " +
                                     std::to_string(n) + " paths " + std::to_string(paths);
            o.simd = true;
            const cv::Mat simd = SgmMatch(left, *right, region, 0, n, o);
            valid_total += ExpectIdentical(simd, ReferenceSgm(left, *right, region, 0, n, o), what + " reference");
            o.simd = false;
            ExpectIdentical(simd, SgmMatch(left, *right, region, 0, n, o), what + " scalar");
            ++cases;
          }
      }
  EXPECT_EQ(cases, 2 * 2 * 4 * 2 * 2);
  EXPECT_GT(valid_total, 5000);  // not vacuous: the shifted view is matched
  // The guided search, where a pixel's window can miss its predecessor's
  // best disparity (its smallest path cost then exceeds the largest matching
  // cost, up to max cost + p2): windows on the true shift for 70 % of the
  // pixels, anywhere in [0, 130) for the rest (mostly disjoint from their
  // neighbours'), against the scalar kernels.
  cv::Mat guide(h, 84, CV_16SC1);
  std::uniform_int_distribution<int> anywhere(0, 129);
  std::bernoulli_distribution on_truth(0.7);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < guide.cols; ++x) guide.at<int16_t>(y, x) = int16_t(on_truth(rng) ? shift : anywhere(rng));
  int guided_valid = 0;
  for (const int p2 : {95, 96})
    for (const int paths : {3, 4}) {
      SgmOptions o;
      o.p2 = p2;
      o.num_paths = paths;
      o.simd = true;
      const cv::Mat simd = SgmMatchGuided(left, shifted, cv::Rect(6, 0, 84, h), guide, 8, 0, 130, o);
      o.simd = false;
      guided_valid += ExpectIdentical(simd, SgmMatchGuided(left, shifted, cv::Rect(6, 0, 84, h), guide, 8, 0, 130, o),
                                      "guided p2 " + std::to_string(p2) + " paths " + std::to_string(paths));
    }
  EXPECT_GT(guided_valid, 1000);  // not vacuous
  SgmOptions o;
  EXPECT_FALSE(SgmPathCostsFitBytes(o, 62, 3));  // n = 3: 16 bits (the uniqueness test's empty case)
  EXPECT_TRUE(SgmPathCostsFitBytes(o, 34, 4));   // the default 5x7 census and p2: bytes
}

TEST(CensusSgm, FindsAKnownShiftOnRandomTexture) {
  // Independent of the implementation: the right view is the left one moved
  // by exactly 7 px, so every valid interior pixel must say 7 (+-0.5: the
  // equiangular fit on a noise-free integer shift stays within the pixel).
  std::mt19937 rng(7);
  const int w = 100, h = 40;
  const cv::Mat left = RandomImage(rng, w, h);
  const cv::Mat right = RightViewAt(left, 7);
  for (const bool simd : {true, false}) {
    SgmOptions o;
    o.simd = simd;
    const cv::Rect region(20, 0, 70, h);
    const cv::Mat d = SgmMatch(CensusTransform(left, 0, h, 2), CensusTransform(right, 0, h, 2), region, 0, 20, o);
    int valid = 0, wrong = 0;
    for (int y = 4; y < h - 4; ++y)
      for (int x = 0; x < region.width - 6; ++x) {
        const float v = d.at<float>(y, x);
        if (std::isnan(v)) continue;
        ++valid;
        wrong += std::abs(v - 7.0f) > 0.5f;
      }
    EXPECT_GT(valid, 0.9 * (h - 8) * (region.width - 6)) << "simd " << simd;
    EXPECT_EQ(wrong, 0) << "simd " << simd;
  }
}

}  // namespace
}  // namespace stereorig
