// The per-pixel sub-pixel fit (subpixel_refine.h) with its vectorised window
// sums (subpixel_window.h) against a straightforward double-precision
// evaluation written here (Lanczos-3 evaluated from sines, no table; linear
// interpolation for the ZNCC), against the portable path, and against the
// rendered truth (synthetic_pair.h).
#include "reconstruct/subpixel_window.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <random>

#include "reconstruct/disparity_state.h"
#include "reconstruct/lanczos_taps.h"
#include "reconstruct/subpixel_refine.h"
#include "reconstruct/synthetic_pair.h"

namespace stereorig {
namespace {

// Lanczos-3 kernel and its derivative.
void Lanczos3(double s, double* value, double* slope) {
  if (std::abs(s) < 1e-9) {
    *value = 1, *slope = 0;
    return;
  }
  if (std::abs(s) >= 3) {
    *value = *slope = 0;
    return;
  }
  const double a = M_PI * s, b = a / 3;
  *value = 3 * std::sin(a) * std::sin(b) / (a * a);
  const double dnum = 3 * M_PI * (std::cos(a) * std::sin(b) + std::sin(a) * std::cos(b) / 3);
  *slope = (dnum * a * a - 3 * std::sin(a) * std::sin(b) * 2 * M_PI * a) / (a * a * a * a);
}

// The row sampled at xr with the taps normalised to sum 1 (as the table).
void SampleExact(const uint8_t* row, double xr, double* value, double* slope) {
  const int i0 = int(std::floor(xr));
  double w[6], g[6], sw = 0, sg = 0;
  for (int k = 0; k < 6; ++k) Lanczos3(xr - (i0 - 2 + k), &w[k], &g[k]), sw += w[k], sg += g[k];
  *value = *slope = 0;
  for (int k = 0; k < 6; ++k) {
    *value += w[k] / sw * row[i0 - 2 + k];
    *slope += (g[k] * sw - w[k] * sg) / (sw * sw) * row[i0 - 2 + k];
  }
}

// RefineDisparity's Gauss-Newton iteration, stated plainly in double.
SubpixelResult RefineReference(const cv::Mat& left, const cv::Mat& right, int x, int y, double start, double gx,
                               double gy, const SubpixelOptions& o) {
  SubpixelResult result;
  const int hw = o.half_width_px, hh = o.half_height_px, n = (2 * hw + 1) * (2 * hh + 1);
  double d = start, gain = 1, offset = 0, lsum = 0, lsum2 = 0, rs = 0, rs2 = 0, lr = 0;
  for (int v = -hh; v <= hh; ++v)
    for (int u = -hw; u <= hw; ++u)
      lsum += left.at<uint8_t>(y + v, x + u), lsum2 += std::pow(left.at<uint8_t>(y + v, x + u), 2);
  for (int it = 0; it < o.max_iterations; ++it) {
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jte = Eigen::Vector3d::Zero();
    rs = rs2 = lr = 0;
    for (int v = -hh; v <= hh; ++v)
      for (int u = -hw; u <= hw; ++u) {
        double r, g;
        SampleExact(right.ptr<uint8_t>(y + v), x + u - d - gx * u - gy * v, &r, &g);
        const double l = left.at<uint8_t>(y + v, x + u), e = l - gain * r - offset;
        const Eigen::Vector3d j(gain * g, -r, -1);
        jtj += j * j.transpose(), jte += j * e;
        rs += r, rs2 += r * r, lr += l * r;
      }
    const Eigen::Vector3d step = -jtj.ldlt().solve(jte);
    d += step[0], gain += step[1], offset += step[2];
    if (std::abs(d - start) > o.max_shift_px) return result;
    if (std::abs(step[0]) < o.converged_step_px) break;
  }
  const double lm = lsum / n, rm = rs / n;
  result.std_dn = std::sqrt(lsum2 / n - lm * lm);
  result.zncc = (lr / n - lm * rm) / (std::sqrt(rs2 / n - rm * rm) * result.std_dn);
  result.disparity_px = d;
  result.ok = gain > 0;
  return result;
}

double ZnccReference(const cv::Mat& left, const cv::Mat& right, int x, int y, double d, double gx, double gy,
                     const SubpixelOptions& o) {
  double ls = 0, ls2 = 0, rs = 0, rs2 = 0, lr = 0;
  const int n = (2 * o.half_width_px + 1) * (2 * o.half_height_px + 1);
  for (int v = -o.half_height_px; v <= o.half_height_px; ++v)
    for (int u = -o.half_width_px; u <= o.half_width_px; ++u) {
      const double xr = x + u - d - gx * u - gy * v, t = xr - std::floor(xr);
      const uint8_t* row = right.ptr<uint8_t>(y + v) + int(std::floor(xr));
      const double r = (1 - t) * row[0] + t * row[1], l = left.at<uint8_t>(y + v, x + u);
      ls += l, ls2 += l * l, rs += r, rs2 += r * r, lr += l * r;
    }
  const double lm = ls / n, rm = rs / n;
  return (lr / n - lm * rm) / std::sqrt((ls2 / n - lm * lm) * (rs2 / n - rm * rm));
}

// Windows spread over a slanted synthetic plane, each started +-0.3 px off
// the truth with slopes off by +-0.02 px/px (as a matcher hands them).
struct Probe {
  int x, y;
  double start, gx, gy, truth;
};
std::vector<Probe> Probes(const SyntheticPair& pair, const SyntheticPairSpec& spec, int count) {
  std::mt19937 rng(3);
  // x >= 80: the right window (at d < 57 px, + the fit's 10 px reach) stays inside.
  std::uniform_int_distribution<int> px(80, pair.left.cols - 13), py(12, pair.left.rows - 13);
  std::uniform_real_distribution<double> off(-0.3, 0.3), slope_off(-0.02, 0.02);
  std::vector<Probe> probes;
  for (int i = 0; i < count; ++i) {
    Probe p{px(rng), py(rng), 0, spec.du + slope_off(rng), spec.dv + slope_off(rng), 0};
    p.truth = pair.true_disparity_px.at<double>(p.y, p.x);
    p.start = p.truth + off(rng);
    probes.push_back(p);
  }
  return probes;
}

TEST(SubpixelWindow, RefineDisparityEqualsPlainDoubleEvaluation) {
  SyntheticPairSpec spec;  // 320x240, d = 40 + 0.04 x + 0.015 y, 2 DN noise
  const SyntheticPair pair = RenderSyntheticPair(spec);
  const SubpixelOptions o;
  double max_dd = 0, max_dzncc = 0;
  int compared = 0;
  for (const Probe& p : Probes(pair, spec, 2000)) {
    const SubpixelResult fast = RefineDisparity(pair.left, pair.right, p.x, p.y, p.start, p.gx, p.gy, o);
    const SubpixelResult ref = RefineReference(pair.left, pair.right, p.x, p.y, p.start, p.gx, p.gy, o);
    ASSERT_EQ(fast.ok, ref.ok) << p.x << "," << p.y;
    if (!fast.ok) continue;
    ++compared;
    max_dd = std::max(max_dd, std::abs(fast.disparity_px - ref.disparity_px));
    max_dzncc = std::max(max_dzncc, std::abs(fast.zncc - ref.zncc));
    EXPECT_NEAR(fast.std_dn, ref.std_dn, 1e-9);  // integer sums: exact
  }
  std::printf("%d fits: |d - plain double fit| max %.5f px, |zncc| max %.6f\n", compared, max_dd, max_dzncc);
  EXPECT_GT(compared, 1900);
  // The fit's table takes the nearest of 256 kernel phases: each sample's
  // position is off by up to 1/512 px (uniform), so the result by at most
  // 0.002 px and typically its mean over the window's samples, ~0.0006.
  // Float sums and positions add < 1e-4 px. A gross kernel error (a
  // misaligned tap: a whole-px shift of a weight) would move d by > 0.1 px.
  // The ZNCC is the last pass's, at a d that differs by as much; the ZNCC's
  // slope there (up to 0.05 px from the peak of a ~1 px wide correlation
  // peak) is < 1 /px: < 0.002 (the acceptance threshold's scale is 0.1).
  EXPECT_LT(max_dd, 0.002);
  EXPECT_LT(max_dzncc, 0.002);
}

TEST(SubpixelWindow, DistinctnessZnccEqualsPlainDoubleEvaluation) {
  SyntheticPairSpec spec;
  const SyntheticPair pair = RenderSyntheticPair(spec);
  const SubpixelOptions o;
  double max_dz = 0;
  for (const Probe& p : Probes(pair, spec, 2000))
    for (const double shift : {-4.0, 0.0, 4.0}) {
      const double d = p.start + shift;
      const double fast = WindowZncc(pair.left, pair.right, p.x, p.y, d, p.gx, p.gy, o);
      ASSERT_GT(fast, -1) << p.x << "," << p.y;  // inside both images, textured
      max_dz = std::max(max_dz, std::abs(fast - ZnccReference(pair.left, pair.right, p.x, p.y, d, p.gx, p.gy, o)));
    }
  std::printf("WindowZncc - plain double: max %.2e\n", max_dz);
  // Float positions (ulp 2^-17 px at x < 512) move a linearly interpolated
  // sample by < 1e-5 * 255 DN; float sums of 27 products ~1e-6 relative: the
  // ZNCC agrees to ~1e-5 (the test's threshold scale is 0.1).
  EXPECT_LT(max_dz, 1e-4);
}

// The distinctness test's two shifts in one walk over the window
// (ZnccPair, WindowZnccProbe::AtPair) against one shift at a time (Zncc,
// At), which DistinctnessZnccEqualsPlainDoubleEvaluation checks against the
// definition: the same arithmetic per shift, so the same doubles, on both
// kernels, and -1 for a shift whose window leaves the right image.
TEST(SubpixelWindow, ZnccPairEqualsTwoSingleZnccs) {
  SyntheticPairSpec spec;
  const SyntheticPair pair = RenderSyntheticPair(spec);
  const SubpixelOptions o;
  int compared = 0, outside = 0;
  for (const Probe& p : Probes(pair, spec, 1000)) {
    for (const WindowKernel kernel : {WindowKernel::kFastest, WindowKernel::kPortable}) {
      const SubpixelWindow window(pair.left, pair.right, p.x, p.y, p.gx, p.gy, o, kernel);
      double pair_zncc[2];
      window.ZnccPair(p.start - 4, p.start + 3.7, pair_zncc);
      ASSERT_EQ(pair_zncc[0], window.Zncc(p.start - 4)) << p.x << "," << p.y;
      ASSERT_EQ(pair_zncc[1], window.Zncc(p.start + 3.7)) << p.x << "," << p.y;
      ++compared;
    }
    // Shifts far enough to leave the right image on one side: At gives -1
    // there, and AtPair the same.
    const WindowZnccProbe probe(pair.left, pair.right, p.x, p.y, p.gx, p.gy, o);
    for (const double far : {-double(pair.right.cols), double(pair.right.cols)}) {
      double at_pair[2];
      probe.AtPair(p.start, p.start + far, at_pair);
      ASSERT_EQ(at_pair[0], probe.At(p.start));
      ASSERT_EQ(at_pair[1], -1.0);
      probe.AtPair(p.start + far, p.start - 2.5, at_pair);
      ASSERT_EQ(at_pair[0], -1.0);
      ASSERT_EQ(at_pair[1], probe.At(p.start - 2.5));
      ++outside;
    }
  }
  EXPECT_GT(compared, 1000);
  EXPECT_GT(outside, 500);
}

// RefineAndAccept (disparity_state.h: one window for the fit and the
// distinctness test) against the plain double fit and the plain ZNCC half
// a period either side, the acceptance tests stated here.
TEST(SubpixelWindow, RefineAndAcceptEqualsThePlainFitAndDistinctnessTest) {
  SyntheticPairSpec spec;
  const SyntheticPair pair = RenderSyntheticPair(spec);
  RefineAcceptance a;  // min_zncc 0.8, texture 1.5 DN, distinctness 0.4 at half_period_px 4
  a.min_disparity_px = 0, a.max_disparity_px = 200;
  // Ignore pixels within this of a threshold: the fit's table moves d by
  // < 0.002 px and the ZNCC by < 0.002 (RefineDisparityEqualsPlain...), so
  // the two may fall either side of a threshold only that close to it.
  constexpr double kMargin = 0.005;
  int accepted = 0, rejected = 0;
  for (const double off_px : {0.0, 2.5, 3.5}) {  // on the match, and a third / half a period off: some fail
    for (Probe p : Probes(pair, spec, 700)) {
      p.start += off_px;
      SubpixelResult fast;
      const PixelStatus why = RefineAndAccept(pair.left, pair.right, p.x, p.y, p.start, p.gx, p.gy, a, &fast);
      const SubpixelResult ref = RefineReference(pair.left, pair.right, p.x, p.y, p.start, p.gx, p.gy, a.subpixel);
      ASSERT_EQ(fast.ok, ref.ok) << p.x << "," << p.y;
      PixelStatus plain = PixelStatus::kPoint;
      double closest = 1;  // how near the plain evaluation is to a threshold
      if (!ref.ok) {
        plain = PixelStatus::kRefineFailed;
      } else {
        closest = std::abs(ref.zncc - a.min_zncc);
        if (ref.zncc < a.min_zncc) {
          plain = PixelStatus::kLowZncc;
        } else {
          const double half = a.half_period_px * (1 - p.gx);
          for (const double shift : {-half, half}) {
            const double margin = ref.zncc - ZnccReference(pair.left, pair.right, p.x, p.y, ref.disparity_px + shift,
                                                           p.gx, p.gy, a.subpixel);
            closest = std::min(closest, std::abs(margin - a.min_distinctness));
            if (margin < a.min_distinctness) {
              plain = PixelStatus::kNotDistinct;
              break;
            }
          }
        }
      }
      if (closest < kMargin) continue;
      ASSERT_EQ(int(why), int(plain)) << p.x << "," << p.y << " start " << p.start;
      if (why == PixelStatus::kPoint) {
        EXPECT_NEAR(fast.disparity_px, ref.disparity_px, 0.002);
        ++accepted;
      } else {
        ++rejected;
      }
    }
  }
  std::printf("RefineAndAccept = plain: %d accepted, %d rejected\n", accepted, rejected);
  EXPECT_GT(accepted, 500);
  EXPECT_GT(rejected, 100) << "the rejections are compared too";
}

TEST(SubpixelWindow, FastSumsEqualPortableSums) {
  SyntheticPairSpec spec;
  const SyntheticPair pair = RenderSyntheticPair(spec);
  // 9, 27, 45 and 63 samples: last chunks of 1, 3 (summed 4 wide), 5 and
  // 7 (8 wide) samples.
  for (const int half_height : {0, 1, 2, 3}) {
    SubpixelOptions o;
    o.half_height_px = half_height;
    double max_step = 0, max_dz = 0;
    for (const Probe& p : Probes(pair, spec, 500)) {
      const SubpixelWindow fast(pair.left, pair.right, p.x, p.y, p.gx, p.gy, o, WindowKernel::kFastest);
      const SubpixelWindow plain(pair.left, pair.right, p.x, p.y, p.gx, p.gy, o, WindowKernel::kPortable);
      // The Gauss-Newton step in d each set of sums gives (gain 1.1, offset 3).
      double step[2];
      for (int k = 0; k < 2; ++k) {
        const FitPassSums s = (k == 0 ? fast : plain).FitPass(p.start, 1.1f, 3.0f);
        Eigen::Matrix3d jtj;
        jtj << 1.21 * s.gg, -1.1 * s.gr, -1.1 * s.g, -1.1 * s.gr, s.rr, s.r, -1.1 * s.g, s.r, double(fast.size());
        step[k] = (jtj.inverse() * Eigen::Vector3d(-1.1 * s.ge, s.re, s.e))[0];
      }
      max_step = std::max(max_step, std::abs(step[0] - step[1]));
      max_dz = std::max(max_dz, std::abs(fast.Zncc(p.start) - plain.Zncc(p.start)));
    }
    std::printf("%d rows: fast - portable: step max %.2e px, zncc max %.2e\n", 2 * half_height + 1, max_step, max_dz);
    // Float summation order, and position rounding: the two paths round a
    // sample's position differently by ~1e-5 px, which picks the
    // neighbouring table entry for a sample within that of an entries'
    // boundary, moving it by 1/kLanczosSteps px and the step by that times
    // the sample's share of the window's weight (< 1).
    EXPECT_LT(max_step, 1.0 / kLanczosSteps);
    EXPECT_LT(max_dz, 1e-4);
  }
}

TEST(SubpixelWindow, RefineDisparityRecoversNoiseFreeTruth) {
  SyntheticPairSpec spec;
  spec.noise_sigma_dn = 0;  // left: 8-bit rounding (0.29 DN rms) and the interpolation
  const SyntheticPair pair = RenderSyntheticPair(spec);
  const SubpixelOptions o;
  double sum = 0, sum2 = 0, ref_sum2 = 0;
  int n = 0;
  for (Probe p : Probes(pair, spec, 2000)) {
    const SubpixelResult r = RefineDisparity(pair.left, pair.right, p.x, p.y, p.start, spec.du, spec.dv, o);
    const SubpixelResult ref = RefineReference(pair.left, pair.right, p.x, p.y, p.start, spec.du, spec.dv, o);
    if (!r.ok || !ref.ok) continue;
    const double e = r.disparity_px - p.truth;
    sum += e, sum2 += e * e, ++n;
    ref_sum2 += std::pow(ref.disparity_px - p.truth, 2);
  }
  const double mean = sum / n, rms = std::sqrt(sum2 / n), ref_rms = std::sqrt(ref_sum2 / n);
  std::printf("noise-free: %d fits, error mean %+.5f px, rms %.5f px (plain double fit %.5f)\n", n, mean, rms, ref_rms);
  EXPECT_GT(n, 1900);
  // The 0.29 DN rounding noise of both images is ~1/7 of the 2 DN for which
  // the fit's CRLB is ~0.015 px (dense_refine_test.cc): ~0.002 px; the rest
  // is Lanczos-3's interpolation error on the ~1 px wide lines, which more
  // Gauss-Newton steps do not change (measured: 0.0084 px rms for 2, 3 or 10
  // steps). The table and float sums may add their 0.002 px at most
  // (above): no more than 0.0005 px rms over the plain double fit. No bias
  // beyond the table's quantisation.
  EXPECT_LT(rms, 0.01);
  EXPECT_LT(rms, ref_rms + 0.0005);
  EXPECT_LT(std::abs(mean), 0.002);
}

// RefineDisparityAndRowOffset's fit stated plainly: Keys cubic rows of
// exactly evaluated Lanczos samples, double throughout.
RowOffsetResult RowOffsetReference(const cv::Mat& left, const cv::Mat& right, int x, int y, double start, double gx,
                                   double gy, const SubpixelOptions& o) {
  auto keys = [](double s, double* w, double* dw) {
    const double a = std::abs(s), sign = s < 0 ? -1.0 : 1.0;
    *w = a <= 1 ? (1.5 * a - 2.5) * a * a + 1 : a < 2 ? ((-0.5 * a + 2.5) * a - 4) * a + 2 : 0;
    *dw = a <= 1 ? sign * (4.5 * a - 5.0) * a : a < 2 ? sign * ((-1.5 * a + 5.0) * a - 4) : 0;
  };
  RowOffsetResult result;
  double d = start, dy = 0, gain = 1, offset = 0;
  for (int it = 0; it < o.max_iterations + 2; ++it) {
    const int i0 = int(std::floor(dy));
    Eigen::Matrix4d jtj = Eigen::Matrix4d::Zero();
    Eigen::Vector4d jte = Eigen::Vector4d::Zero();
    for (int v = -o.half_height_px; v <= o.half_height_px; ++v)
      for (int u = -o.half_width_px; u <= o.half_width_px; ++u) {
        double r = 0, rx = 0, ry = 0;
        for (int k = 0; k < 4; ++k) {
          double w, dw, value, slope;
          keys(dy - i0 - (k - 1), &w, &dw);
          SampleExact(right.ptr<uint8_t>(y + v + i0 - 1 + k), x + u - d - gx * u - gy * v, &value, &slope);
          r += w * value, rx += w * slope, ry += dw * value;
        }
        const double e = left.at<uint8_t>(y + v, x + u) - gain * r - offset;
        const Eigen::Vector4d j(gain * rx, -gain * ry, -r, -1.0);
        jtj += j * j.transpose(), jte += j * e;
      }
    const Eigen::Vector4d step = -jtj.ldlt().solve(jte);
    d += step[0], dy += step[1], gain += step[2], offset += step[3];
    if (std::abs(d - start) > o.max_shift_px || std::abs(dy) > 1.0) return result;
    if (std::abs(step[0]) < 0.01 && std::abs(step[1]) < 0.01) break;
  }
  result.ok = gain > 0, result.disparity_px = d, result.row_offset_px = dy;
  return result;
}

TEST(SubpixelWindow, RowOffsetFitEqualsPlainDoubleEvaluationAndReadsTheVernier) {
  SyntheticPairSpec spec;  // grid period 8 px turned 2.6 deg, 2 DN noise
  const SyntheticPair pair = RenderSyntheticPair(spec);
  SubpixelOptions o;
  o.half_height_px = 4;  // the line index's 9x9 window
  // A start one period off: the near-horizontal lines are then offset by
  // period * tan(angle) = 0.363 px vertically (line_index.h).
  for (const double period_off : {0.0, 1.0}) {
    double max_dd = 0, max_ddy = 0, sum_dy = 0, sum_e = 0;
    int n = 0;
    for (const Probe& p : Probes(pair, spec, 300)) {
      const double start = p.start + period_off * spec.grid_period_px;
      if (p.x - start < 20) continue;  // the shifted window stays inside the right image
      const RowOffsetResult fast =
          RefineDisparityAndRowOffset(pair.left, pair.right, p.x, p.y, start, spec.du, spec.dv, o);
      const RowOffsetResult ref = RowOffsetReference(pair.left, pair.right, p.x, p.y, start, spec.du, spec.dv, o);
      if (!fast.ok || !ref.ok) continue;
      max_dd = std::max(max_dd, std::abs(fast.disparity_px - ref.disparity_px));
      max_ddy = std::max(max_ddy, std::abs(fast.row_offset_px - ref.row_offset_px));
      sum_dy += fast.row_offset_px, sum_e += fast.disparity_px - p.truth - period_off * spec.grid_period_px, ++n;
    }
    std::printf(
        "%g periods off: %d fits, fast - plain: d max %.5f px, dy max %.5f px; mean dy %+.4f px, d - shifted truth "
        "%+.4f px\n",
        period_off, n, max_dd, max_ddy, sum_dy / n, sum_e / n);
    EXPECT_GT(n, 200);
    // The table's 0.002 px (above); float samples add < 1e-4 px.
    EXPECT_LT(max_dd, 0.002);
    EXPECT_LT(max_ddy, 0.002);
    // The vernier: ~0 on the right line, ~0.36 px one period off (either
    // sign by the grid's turn); the mean of > 200 windows scatters by far
    // less than 0.05 px.
    EXPECT_NEAR(std::abs(sum_dy / n), period_off * spec.grid_period_px * std::tan(spec.grid_angle_deg * M_PI / 180),
                0.05);
  }
}

}  // namespace
}  // namespace stereorig
