// The line-index test against ground truth: an analytically rendered plane
// (synthetic_pair.h) whose disparity is known, with patches put one grid
// period off by hand.
#include "reconstruct/line_index.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <utility>

#include "reconstruct/synthetic_pair.h"

namespace stereorig {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// A fronto-parallel plane at 40 px of disparity, grid period 8 px turned
// 2.6 deg (one period off reads a row offset of 8 tan 2.6 deg = 0.36 px).
SyntheticPair Plane() {
  SyntheticPairSpec spec;
  spec.d0_px = 40, spec.du = 0, spec.dv = 0;
  return RenderSyntheticPair(spec);
}

// The plane with strong noise in each view (a stand-in for speckle, which
// decorrelates the views) and a shallower grid (1.3 deg: one period off reads
// 8 tan 1.3 deg = 0.18 px, as the vernier's step reads at speckle 0.4 on the
// simulator's scenes).
SyntheticPair ShallowNoisyPlane(double noise_dn, uint64_t seed) {
  SyntheticPairSpec spec;
  spec.d0_px = 40, spec.du = 0, spec.dv = 0;
  spec.noise_sigma_dn = noise_dn;
  spec.grid_angle_deg = 1.3;
  spec.seed = seed;
  return RenderSyntheticPair(spec);
}

DisparityState EmptyState(const cv::Size& size) {
  return DisparityState{cv::Mat(size, CV_32FC1, cv::Scalar(kInf)), cv::Mat(size, CV_32FC1, cv::Scalar(0)),
                        cv::Mat(size, CV_8UC1, cv::Scalar(uint8_t(PixelStatus::kNoSgmMatch))),
                        cv::Mat(size, CV_32FC1, cv::Scalar(0)), cv::Mat(size, CV_32FC1, cv::Scalar(0))};
}

// Puts columns [x0, x1) of rows [20, 220) at disparity `d`.
void Patch(DisparityState* s, int x0, int x1, float d) {
  for (int y = 20; y < 220; ++y)
    for (int x = x0; x < x1; ++x) {
      s->disparity_px.at<float>(y, x) = d;
      s->confidence.at<float>(y, x) = 0.9f;
      s->status.at<uint8_t>(y, x) = uint8_t(PixelStatus::kPoint);
    }
}

RefineAcceptance Acceptance() {
  RefineAcceptance a;
  a.min_disparity_px = 0;
  a.max_disparity_px = 80;
  return a;
}

struct Outcome {
  int right_line = 0, period_off = 0, wrong_line_status = 0, other = 0;
};

// Each pixel of columns [x0, x1) against the true disparity (40 px). The
// refined disparity's noise at the injected 2 DN is ~0.02 px rms (matcher
// tests), so 0.5 px tells the right line from one 8 px period off by a wide
// margin; the 1 px band around -8 covers the refinement's max_shift_px.
Outcome Classify(const DisparityState& s, const SyntheticPair& pair, int x0, int x1) {
  Outcome o;
  for (int y = 20; y < 220; ++y)
    for (int x = x0; x < x1; ++x) {
      const float d = s.disparity_px.at<float>(y, x);
      const double e = d - pair.true_disparity_px.at<double>(y, x);
      if (std::isfinite(d) && std::abs(e) < 0.5) {
        ++o.right_line;
      } else if (std::isfinite(d) && std::abs(e + 8) < 1.0) {
        ++o.period_off;
      } else if (s.status.at<uint8_t>(y, x) == uint8_t(PixelStatus::kWrongLine)) {
        ++o.wrong_line_status;
      } else {
        ++o.other;
      }
    }
  return o;
}

// Left pixels x < 44 have their true match (x - 40, window +-4 px) at least
// partly outside the right image, so the true line cannot be read there;
// one period off (d = 32), columns >= 39 land inside it (x - 32 - 4 - 3
// Lanczos taps >= 0). A patch at [39, 44) is therefore on the wrong line with
// the right one out of reach; a patch at [150, 160) one period off can be
// moved back; a patch at [200, 210) on the right line must stay.
TEST(LineIndex, DropsAWrongLinePatchWhoseRightLineIsOutsideTheRightImage) {
  const SyntheticPair pair = Plane();
  const cv::Rect roi(0, 0, pair.left.cols, pair.left.rows);
  for (const double drop_px : {0.15, 0.0}) {
    DisparityState s = EmptyState(pair.left.size());
    Patch(&s, 39, 44, 32.f);
    Patch(&s, 150, 160, 32.f);
    Patch(&s, 200, 210, 40.f);
    LineIndexOptions o;
    o.drop_row_offset_px = drop_px;
    if (drop_px == 0) o.ambiguity_sigmas = 0, o.footprint_gap_px = 0;  // the vernier as before session 6
    CorrectLineIndex(pair.left, pair.right, roi, o, Acceptance(), &s);
    const Outcome edge = Classify(s, pair, 39, 44), movable = Classify(s, pair, 150, 160),
                  right = Classify(s, pair, 200, 210);
    SCOPED_TRACE(drop_px);
    // The movable and the correct patches: all on the right line, with or
    // without the drop (refinement may refuse a few pixels: < 2 %).
    EXPECT_GE(movable.right_line, 0.98 * 2000);
    EXPECT_GE(right.right_line, 0.98 * 2000);
    EXPECT_EQ(movable.wrong_line_status + right.wrong_line_status, 0);
    if (drop_px > 0) {
      // Dropped, or (the footprint reaching past the patch reads the right
      // alignment) moved and then refused by the refinement: never kept.
      EXPECT_EQ(edge.period_off, 0);
      EXPECT_EQ(edge.right_line, 0);
      EXPECT_EQ(edge.wrong_line_status + edge.other, 1000);
    } else {
      EXPECT_EQ(edge.period_off, 1000);  // off: kept one period off, as before the option
    }
  }
}

// Bit for bit the same map on 1 and on 4 threads: the readings fit every
// sample once and sum them in the samples' order whatever the chunks, and a
// moved component's pixels each write only their own state. A patch one
// period off is moved (so the alignment scan and the move both run), one on
// the right line kept. Seen failing with a chunk's last sample, or last
// moved pixel, skipped.
TEST(LineIndex, TheSameMapOnAnyNumberOfThreads) {
  const SyntheticPair pair = Plane();
  const cv::Rect roi(0, 0, pair.left.cols, pair.left.rows);
  DisparityState on[2];
  int moved[2];
  for (int k = 0; k < 2; ++k) {
    on[k] = EmptyState(pair.left.size());
    Patch(&on[k], 100, 140, 40.f);
    Patch(&on[k], 150, 170, 32.f);
    LineIndexOptions o;
    o.num_threads = k == 0 ? 1 : 4;
    moved[k] = CorrectLineIndex(pair.left, pair.right, roi, o, Acceptance(), &on[k]);
  }
  EXPECT_EQ(moved[0], 1);
  EXPECT_EQ(moved[1], 1);
  EXPECT_GE(Classify(on[1], pair, 150, 170).right_line, 0.98 * 4000);  // moved to the right line (40 px)
  for (const auto& [a, b] : {std::pair{on[0].disparity_px, on[1].disparity_px},
                             std::pair{on[0].confidence, on[1].confidence}, std::pair{on[0].status, on[1].status}}) {
    ASSERT_TRUE(a.isContinuous() && b.isContinuous() && a.size() == b.size() && a.type() == b.type());
    EXPECT_EQ(std::memcmp(a.data, b.data, a.total() * a.elemSize()), 0);
  }
}

// Two patches meeting along a seam with a one-period jump: the join moves
// the one on the wrong line. The vernier test is made to keep both
// (max_row_offset_px 0.9 > the 0.36 px one period off reads), so it leaves
// the map unchanged and the join may take its components instead of
// labelling again: the outcome must be the same either way.
TEST(LineIndex, JoinMovesThePatchAcrossAPeriodJumpWithOrWithoutTheVernierTestsComponents) {
  const SyntheticPair pair = Plane();
  const cv::Rect roi(0, 0, pair.left.cols, pair.left.rows);
  LineIndexOptions o;
  o.max_row_offset_px = 0.9;
  DisparityState shared = EmptyState(pair.left.size());
  Patch(&shared, 100, 150, 40.f);
  Patch(&shared, 150, 170, 32.f);
  DisparityState separate{shared.disparity_px.clone(), shared.confidence.clone(), shared.status.clone(),
                          shared.slope_x.clone(), shared.slope_y.clone()};
  DisparityComponents components;
  EXPECT_EQ(CorrectLineIndex(pair.left, pair.right, roi, o, Acceptance(), &shared, &components), 0);
  EXPECT_TRUE(components.matches_disparity);
  EXPECT_EQ(JoinAcrossPeriodJumps(pair.left, pair.right, roi, o, Acceptance(), &shared, &components), 1);
  EXPECT_FALSE(components.matches_disparity);
  CorrectLineIndex(pair.left, pair.right, roi, o, Acceptance(), &separate);
  EXPECT_EQ(JoinAcrossPeriodJumps(pair.left, pair.right, roi, o, Acceptance(), &separate), 1);
  // Against the truth (40 px): both patches on the right line (refinement
  // may refuse a few pixels: < 2 %).
  const Outcome a = Classify(shared, pair, 100, 150), b = Classify(shared, pair, 150, 170);
  EXPECT_GE(a.right_line, 0.98 * 10000);
  EXPECT_GE(b.right_line, 0.98 * 4000);
  cv::Mat diff;
  cv::compare(shared.disparity_px, separate.disparity_px, diff, cv::CMP_NE);
  EXPECT_EQ(cv::countNonZero(diff), 0);
  cv::compare(shared.status, separate.status, diff, cv::CMP_NE);
  EXPECT_EQ(cv::countNonZero(diff), 0);
}

// Strong noise (30 DN: a stand-in for speckle, which decorrelates the views)
// and a shallower grid (1.3 deg: one period off reads 8 tan 1.3 deg = 0.18
// px, as the vernier's step reads at speckle 0.4 on the simulator's scenes):
// the vernier's standard error becomes a large part of its step, so a small
// patch one period off cannot always be told from the right line. With the
// ambiguity test it must never stay one period off (moved back, or dropped as
// kWrongLine), checked against the truth (40 px) over five noise seeds.
TEST(LineIndex, AnAmbiguousReadingDropsRatherThanKeepsAPeriodOffPatch) {
  int kept_off_without = 0;
  for (int seed = 1; seed <= 5; ++seed) {
    const SyntheticPair pair = ShallowNoisyPlane(30, seed);
    const cv::Rect roi(0, 0, pair.left.cols, pair.left.rows);
    for (const double sigmas : {1.0, 0.0}) {
      DisparityState s = EmptyState(pair.left.size());
      Patch(&s, 150, 156, 32.f);
      LineIndexOptions o;
      o.ambiguity_sigmas = sigmas;
      if (sigmas == 0) o.footprint_gap_px = 0, o.lattice_sampling = false;  // as before session 6
      o.samples = 16;
      CorrectLineIndex(pair.left, pair.right, roi, o, Acceptance(), &s);
      const Outcome off = Classify(s, pair, 150, 156);
      SCOPED_TRACE(seed);
      SCOPED_TRACE(sigmas);
      if (sigmas > 0) {
        EXPECT_EQ(off.period_off, 0);
      } else {
        kept_off_without += off.period_off > 0;
      }
    }
  }
  // Without it, at least one seed keeps the patch one period off: the test
  // above is not vacuous.
  EXPECT_GT(kept_off_without, 0);
}

// The seam join on a perturbed period jump: the surface at 40 px (columns
// 100-150, rows 20-220) and a patch one period off at 32 px (columns
// 150-170), each pixel then moved by perturb(x, y), joined at spread_px
// with the vernier test out of the way. Returns the moves; *patch: the
// patch's pixels against the truth (40 px).
int JoinPerturbedPeriodJump(const SyntheticPair& pair, double spread_px, const std::function<float(int, int)>& perturb,
                            Outcome* patch) {
  DisparityState s = EmptyState(pair.left.size());
  Patch(&s, 100, 150, 40.f);
  Patch(&s, 150, 170, 32.f);
  for (int y = 20; y < 220; ++y)
    for (int x = 100; x < 170; ++x) s.disparity_px.at<float>(y, x) += perturb(x, y);
  LineIndexOptions o;
  o.max_row_offset_px = 0.9;  // the vernier test keeps both: only the join acts
  o.seam_spread_px = spread_px;
  const int moved =
      JoinAcrossPeriodJumps(pair.left, pair.right, cv::Rect(0, 0, pair.left.cols, pair.left.rows), o, Acceptance(), &s);
  *patch = Classify(s, pair, 150, 170);
  return moved;
}

// The perturbed period jump at two spreads: refused at `refused_px` (no
// move, no patch pixel on the right line), joined at `joined_px` (one move,
// at least min_right_line of the patch's 4 000 pixels on the right line and
// fewer than max_period_off a period off).
void ExpectRefusedThenJoined(const SyntheticPair& pair, double refused_px, double joined_px,
                             const std::function<float(int, int)>& perturb, int min_right_line, int max_period_off) {
  for (const double spread_px : {refused_px, joined_px}) {
    Outcome patch;
    const int moved = JoinPerturbedPeriodJump(pair, spread_px, perturb, &patch);
    std::printf("seam spread %.0f px: %d moved; patch: %d on the right line, %d a period off\n", spread_px, moved,
                patch.right_line, patch.period_off);
    SCOPED_TRACE(spread_px);
    if (spread_px == refused_px) {
      EXPECT_EQ(moved, 0);
      EXPECT_EQ(patch.right_line, 0);
    } else {
      EXPECT_EQ(moved, 1);
      EXPECT_GE(patch.right_line, min_right_line);
      EXPECT_LT(patch.period_off, max_period_off);
    }
  }
}

// The seam join at strong speckle (LineIndexOptions::seam_spread_px): the
// disparities on both sides of a seam scatter (speckle 0.4: the simulator's
// plate read its seam differences from -10.8 to -7.0 px around -9.2, 10th to
// 90th percentile). Here each pixel's disparity gets 0.8 px of Gaussian
// noise, so a seam difference scatters by sqrt(2) x 0.8 = 1.13 px: 38 % of
// them lie beyond 1 px of the median (the join refuses: more than a
// quarter), 8 % beyond 2 px (a quarter period: it joins). Against the truth
// (40 px): with 2 px the period-off patch is moved onto the right line.
TEST(LineIndex, JoinReadsANoisySeamAsAPeriodJumpWithinAQuarterPeriod) {
  cv::RNG rng(5);
  // Joined: moved and re-refined, from the noisy disparities (+-0.8 px)
  // plus the period: most of the patch on the right line (measured 90 %;
  // the rest refused or, 3 %, back a period off).
  ExpectRefusedThenJoined(
      Plane(), 1.0, 2.0, [&rng](int, int) { return float(rng.gaussian(0.8)); }, int(0.85 * 4000), int(0.05 * 4000));
}

// A seam scattered wider, as on a steep limb, where the differences carry
// each pixel's slope extrapolated over gaps of up to max_seam_gap_px (the
// default-speckle ball bar of seed 5, module 1: a 128-pixel seam read 10.5
// px, 34 % of it beyond 2 px; reconstruct-log.md, session 24). Here the
// patch one period off wanders by 2.5 px sin(2 pi y / 50) along the seam
// (smoothly: neighbours stay within 1 px, one component), so 41 % of the
// differences lie beyond 2 px of the median (refused) and none beyond 3 px,
// the default (joined). Against the truth (40 px).
TEST(LineIndex, JoinReadsASeamScatteredAsOnASteepLimbAsAPeriodJump) {
  EXPECT_EQ(LineIndexOptions{}.seam_spread_px, 3.0);
  auto wander = [](int x, int y) { return x < 150 ? 0.f : float(2.5 * std::sin(2 * M_PI * y / 50.0)); };
  // Joined: moved and re-refined from up to 2.5 px off the truth (Move
  // tries starts 2 px either side): nearly all on the right line, none a
  // period off.
  ExpectRefusedThenJoined(Plane(), 2.0, 3.0, wander, int(0.95 * 4000), 1);
}

// A depth edge is no period jump: its step varies along it. Here the patch
// beside the surface steps down by 2 px at its top row to 14 px at its
// bottom (median ~8, a period; half the seam farther than 3 px from it):
// the join must leave it, at the default spread and at the largest allowed.
TEST(LineIndex, JoinLeavesADepthEdgeWhoseStepVariesAlongIt) {
  const SyntheticPair pair = Plane();
  const cv::Rect roi(0, 0, pair.left.cols, pair.left.rows);
  for (const double spread_px : {3.0, 4.0}) {
    DisparityState s = EmptyState(pair.left.size());
    Patch(&s, 100, 150, 40.f);
    Patch(&s, 150, 170, 0.f);
    for (int y = 20; y < 220; ++y)
      for (int x = 150; x < 170; ++x) s.disparity_px.at<float>(y, x) = float(40 - 2 - 12 * (y - 20) / 199.0);
    const cv::Mat before = s.disparity_px.clone();
    LineIndexOptions o;
    o.max_row_offset_px = 0.9;
    o.seam_spread_px = spread_px;
    SCOPED_TRACE(spread_px);
    EXPECT_EQ(JoinAcrossPeriodJumps(pair.left, pair.right, roi, o, Acceptance(), &s), 0);
    cv::Mat diff;
    cv::compare(s.disparity_px, before, diff, cv::CMP_NE);
    EXPECT_EQ(cv::countNonZero(diff), 0);
  }
}

// Reading the whole footprint (LineIndexOptions::area_per_sample_px) on a
// plane at 45 DN with a shallow grid (1.3 deg: one period off reads 0.18 px,
// as at speckle 0.4). A large component on the right line read from 6
// samples (15 on the lattice: pitch 48) is not conclusive (standard error
// ~0.1 px against the 0.1 px keep threshold and 0.18 px step) and is
// dropped; reading one sample per 81 px (the 9 px lattice, ~290 of its
// footprint: standard error ~4x smaller) it must be kept whole, over five noise seeds, and a large patch one period off
// must still never be kept one period off (measured: moved, ~1200 of its 16 000 pixels pass the refinement's tests at
// 45 DN, none a period off).
TEST(LineIndex, ReadingTheWholeFootprintKeepsALargeRightComponent) {
  int lost_small = 0, lost_whole = 0, kept_off_whole = 0;
  for (int seed = 1; seed <= 5; ++seed) {
    const SyntheticPair pair = ShallowNoisyPlane(45, seed);
    const cv::Rect roi(0, 0, pair.left.cols, pair.left.rows);
    for (const int area : {0, 81}) {
      DisparityState s = EmptyState(pair.left.size());
      Patch(&s, 60, 180, 40.f);   // right line: 24 000 px
      Patch(&s, 220, 300, 32.f);  // one period off: 16 000 px
      LineIndexOptions o;
      o.samples = 6;
      o.area_per_sample_px = area;
      CorrectLineIndex(pair.left, pair.right, roi, o, Acceptance(), &s);
      const Outcome right = Classify(s, pair, 60, 180), off = Classify(s, pair, 220, 300);
      (area ? lost_whole : lost_small) += right.right_line < 0.9 * 24000;
      if (area) kept_off_whole += off.period_off > 0;
    }
  }
  std::printf("right component lost in %d of 5 seeds from 6 samples, %d reading the whole footprint\n", lost_small,
              lost_whole);
  EXPECT_EQ(lost_whole, 0);
  EXPECT_EQ(kept_off_whole, 0);
  EXPECT_GT(lost_small, 0);  // not vacuous: 6 samples alone lose it (measured: 5 of 5)
}

// The decision is stable where the evidence is (LineIndexOptions::
// lattice_sampling): the same two patches (the right line, and one period
// off) as above, matched again with 2 % of their pixels missing (a slightly
// different SGM result), on the noisy shallow-grid plane. Each patch's
// outcome (right line kept, moved back, or dropped) against the truth
// (40 px) is compared with the unperturbed run's: read by raster rank, the
// samples move and the outcome flips on some runs; on the image's lattice,
// the samples stay and the outcome with them. The lattice must never keep the off patch one period off. Six
// samples (without the whole-footprint re-read) put the readings near
// their thresholds, as 48 do on the simulator's ball bar.
TEST(LineIndex, LatticeSamplingKeepsTheDecisionWhenAComponentLosesAFewPixels) {
  // 0 = on the right line (>= 90 % of its remaining pixels), 1 = one period
  // off (any), 2 = neither (dropped, or refused).
  auto classify = [](const DisparityState& s, const SyntheticPair& pair, int x0, int x1) {
    const Outcome o = Classify(s, pair, x0, x1);
    if (o.period_off > 0.01 * (x1 - x0) * 200) return 1;  // not counting isolated pixels (< min_component_px)
    return o.right_line >= 0.9 * (o.right_line + o.other + o.wrong_line_status) ? 0 : 2;
  };
  int flips[2] = {0, 0}, runs = 0, kept_off[2] = {0, 0};
  for (int seed = 1; seed <= 4; ++seed) {
    const SyntheticPair pair = ShallowNoisyPlane(45, seed);
    const cv::Rect roi(0, 0, pair.left.cols, pair.left.rows);
    for (const bool lattice : {true, false}) {
      int first[2] = {-1, -1};
      for (int perturbation = 0; perturbation <= 6; ++perturbation) {
        DisparityState s = EmptyState(pair.left.size());
        Patch(&s, 60, 180, 40.f);   // right line
        Patch(&s, 220, 300, 32.f);  // one period off
        cv::RNG rng(uint64_t(100 * seed + perturbation));
        if (perturbation > 0)
          for (int y = 20; y < 220; ++y)
            for (int x = 60; x < 300; ++x)
              if (rng.uniform(0.0, 1.0) < 0.02) s.disparity_px.at<float>(y, x) = kInf;
        LineIndexOptions o;
        o.lattice_sampling = lattice;
        // Few samples: readings near their thresholds. On the lattice 6 give
        // pitch 48: 15 and 10 pixels of the two footprints; by raster rank
        // 12, about as many.
        o.samples = lattice ? 6 : 12, o.area_per_sample_px = 0;
        CorrectLineIndex(pair.left, pair.right, roi, o, Acceptance(), &s);
        const int outcome[2] = {classify(s, pair, 60, 180), classify(s, pair, 220, 300)};
        kept_off[lattice ? 0 : 1] += outcome[1] == 1;
        if (perturbation == 0) {
          first[0] = outcome[0], first[1] = outcome[1];
          continue;
        }
        flips[lattice ? 0 : 1] += (outcome[0] != first[0]) + (outcome[1] != first[1]);
        runs += lattice;
      }
    }
  }
  std::printf(
      "outcome flips in %d perturbed runs (2 patches each): lattice %d, raster rank %d; off patch kept off: "
      "lattice %d, raster rank %d (of %d runs)\n",
      runs, flips[0], flips[1], kept_off[0], kept_off[1], runs + 4);
  EXPECT_EQ(kept_off[0], 0);
  // Measured: lattice 0, raster rank 8. The lattice's perturbed samples are
  // its unperturbed ones less ~2 %: only a reading within that of its
  // threshold could flip; allow one such of the 48 outcomes.
  EXPECT_LE(flips[0], 1);
  EXPECT_GT(flips[1], flips[0]);  // not vacuous: raster rank flips here
}

// LineIndexOptions::quick_keep off (the matcher, where growing's noise floor
// bites): no component is kept on its own reading before the other
// alignments are read. Its benefit is measured on the simulator's scenes
// (speckle 0.4 ball bar, module 1: kept one period off under 2 of 6 option
// controls with it, 0 of 6 without; docs/reconstruct-log.md); this checks its
// cost against the truth (40 px) on the noisy shallow-grid plane: a large
// right-line patch read through the full test is still kept (>= 90 %), and
// a patch one period off is still never kept one period off, over 5 seeds.
TEST(LineIndex, WithoutTheQuickKeepARightPatchIsStillKeptAndAnOffOneNever) {
  int right_kept[2] = {0, 0}, kept_off[2] = {0, 0};
  for (int seed = 1; seed <= 5; ++seed) {
    const SyntheticPair pair = ShallowNoisyPlane(30, seed);
    const cv::Rect roi(0, 0, pair.left.cols, pair.left.rows);
    for (const bool quick : {true, false}) {
      DisparityState s = EmptyState(pair.left.size());
      Patch(&s, 60, 180, 40.f);   // right line
      Patch(&s, 220, 300, 32.f);  // one period off
      LineIndexOptions o;
      o.quick_keep = quick;
      CorrectLineIndex(pair.left, pair.right, roi, o, Acceptance(), &s);
      right_kept[quick ? 0 : 1] += Classify(s, pair, 60, 180).right_line >= 0.9 * 24000;
      kept_off[quick ? 0 : 1] += Classify(s, pair, 220, 300).period_off > 0.01 * 16000;
    }
  }
  std::printf("right patch kept in %d / %d of 5 seeds, off patch kept off in %d / %d (quick keep on / off)\n",
              right_kept[0], right_kept[1], kept_off[0], kept_off[1]);
  EXPECT_EQ(right_kept[1], 5);
  EXPECT_EQ(kept_off[1], 0);
}

}  // namespace
}  // namespace stereorig
