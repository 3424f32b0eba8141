// Stage 3 honours the earlier stages' verdicts (calib/system.h,
// SystemExclusions): the views stage 1 dropped and the corners mrcal's
// outlier rejection flagged in stage 1 or stage 2 stay out of the bundle
// adjustment, whose Huber loss only bounds their pull.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "calib/calib_test_util.h"
#include "calib/calibrate.h"
#include "calib/core/mrcal_c.h"
#include "calib/projection_uncertainty.h"
#include "calib/system.h"

namespace stereorig {
namespace {

constexpr double kNoisePx = 0.2;

// S[0][1]'s error against the truth in the terms of its reported 1 sigma
// (STransformSigma): a rotation about the reference's x, y, z (deg) and the
// translation (mm).
struct SError {
  Eigen::Vector3d rotation_deg, translation_mm;
};
SError SErrorAgainstTruth(const Rig& got, const Rig& truth) {
  const Pose& g = got.S(0, 1);
  const Pose& t = truth.S(0, 1);
  return {Pose(g.rotation() * t.rotation().transpose(), Eigen::Vector3d::Zero()).RotationVector() * 180.0 / M_PI,
          g.translation_mm() - t.translation_mm()};
}

// The default rig, 25 captures at 0.2 px, with six of camera 0's views
// corrupted: the largest one by +-5 px alternating from corner to corner (no
// board pose fits it: stage 1 drops the view), the next five by +5 px in y on
// the board's rows 4..6 (their poses cannot take it up: mrcal flags those
// corners). Before stage 3 honoured the verdicts (measured when written), its
// reprojection RMS was 0.66 px, camera 0's refined intrinsics up to 9.3 and
// S up to 8.7 noise sigmas off the truth (the bounds below are 4); after,
// 0.196 px and 1.6 / 1.6 sigmas.
TEST(CalibrateSystemVerdicts, CornersEarlierStagesRejectedStayOut) {
  auto s = testing::MakeDefaultScene(71, 25, kNoisePx);
  std::vector<BoardObservation*> cam0;
  int total_corners = 0;
  for (BoardObservation& o : s.data.input.observations) {
    total_corners += static_cast<int>(o.corner_ids.size());
    if (o.camera == 0) cam0.push_back(&o);
  }
  std::stable_sort(cam0.begin(), cam0.end(),
                   [](const auto* a, const auto* b) { return a->corner_ids.size() > b->corner_ids.size(); });
  ASSERT_GE(cam0.size(), 6u);
  const int cx = s.data.input.target.corners_x;
  const int dropped_corners = static_cast<int>(cam0[0]->corner_ids.size());
  for (int v = 0; v < 6; ++v) {
    BoardObservation& o = *cam0[v];
    for (size_t i = 0; i < o.corner_ids.size(); ++i) {
      const double row = o.corner_ids[i] / cx;  // integer division: the board row
      const double d = v == 0 ? (i % 2 ? 5.0 : -5.0) : (row >= 4 ? 5.0 : 0.0);
      o.q_px[i].y() = std::clamp(o.q_px[i].y() + d, 0.0, s.data.input.cameras[0].height_px - 1.0);
    }
  }

  const CalibrationResult r = Calibrate(s.data.input, CalibrationOptions());
  const SystemReport& sys = r.report.system;
  std::printf("%s", SummaryText(r.report).c_str());

  // The verdicts, counted: the view stage 1 dropped, whole, and at least the
  // corners stage 1 flagged in camera 0; every corner is either a residual
  // or counted as skipped (no capture of this scene is set aside).
  EXPECT_EQ(r.report.intrinsics[0].num_views_dropped, 1);
  EXPECT_EQ(sys.num_skipped_views, 1);
  EXPECT_EQ(sys.num_skipped_view_corners, dropped_corners);
  EXPECT_GE(sys.num_skipped_outlier_corners, r.report.intrinsics[0].num_outliers);
  EXPECT_GT(r.report.intrinsics[0].num_outliers, 0);
  EXPECT_EQ(sys.num_residual_corners + sys.num_skipped_view_corners + sys.num_skipped_outlier_corners, total_corners);
  const nlohmann::json j = nlohmann::json::parse(r.report.ToJson());
  EXPECT_EQ(j["stage3_system"]["skipped_views"], sys.num_skipped_views);
  EXPECT_EQ(j["stage3_system"]["skipped_view_corners"], sys.num_skipped_view_corners);
  EXPECT_EQ(j["stage3_system"]["skipped_outlier_corners"], sys.num_skipped_outlier_corners);

  // What is left is the injected noise: the RMS of the residual coordinates
  // within 10% of it (as the ring's e2e test asks).
  EXPECT_NEAR(sys.refined_reprojection_rms_px, kNoisePx, 0.1 * kNoisePx);

  // Against the truth, in the noise's own sigma. Stage 3 reports sigma =
  // sqrt(diag(inv(J'J))) * the residual RMS (with its n/(n-p) factor);
  // rescaled by kNoisePx / RMS it is the covariance at the injected 0.2 px
  // Gaussian noise, independent of what an outlier left in would do to the
  // RMS (which inflates the reported sigma and would hide its own pull). The
  // statistical test shows these sigmas honest (RMS z 0.85 - 1.1), and
  // leaving out ~6% of one camera's corners widens them by ~3%, which the
  // reported sigma already includes. 4 sigma per component over 4 cameras x 9
  // intrinsics + 6 of S = 42 components: a false alarm ~42 x 6.3e-5 = 3e-3.
  const double to_noise = kNoisePx / sys.refined_reprojection_rms_px;
  ASSERT_EQ(sys.intrinsics_sigma.size(), 4u);
  double max_z = 0;
  for (const RefinedIntrinsicsSigma& x : sys.intrinsics_sigma) {
    const std::vector<double>& t = s.truth.rig.camera(x.camera).intrinsics();
    for (size_t i = 0; i < x.intrinsics.size(); ++i) {
      const double z = (x.intrinsics[i] - t[i]) / (x.sigma[i] * to_noise);
      EXPECT_LT(std::abs(z), 4.0) << "camera " << x.camera << " intrinsic " << i;
      max_z = std::max(max_z, std::abs(z));
    }
  }
  ASSERT_EQ(sys.sigma.size(), 1u);
  const SError e = SErrorAgainstTruth(r.rig, s.truth.rig);
  const Eigen::Vector3d &dr = e.rotation_deg, &dt = e.translation_mm;
  double max_s = 0;
  for (int i = 0; i < 3; ++i) {
    max_s = std::max({max_s, std::abs(dr(i)) / (sys.sigma[0].rotation_deg(i) * to_noise),
                      std::abs(dt(i)) / (sys.sigma[0].translation_mm(i) * to_noise)});
    EXPECT_LT(std::abs(dr(i)), 4.0 * sys.sigma[0].rotation_deg(i) * to_noise) << "S rotation " << i;
    EXPECT_LT(std::abs(dt(i)), 4.0 * sys.sigma[0].translation_mm(i) * to_noise) << "S translation " << i;
  }
  std::printf("largest |error| / noise sigma: intrinsics %.2f, S %.2f\n", max_z, max_s);
}

// A capture stage 2 set aside for a module (its cameras saw different faces)
// stays out of stage 3 as stage 2's list says (SystemExclusions::
// module_captures), not as stage 3 would judge it again: here an ordinary
// capture, which stage 3's own look at the faces would keep, is named set
// aside for module 1, and both of module 1's views of it leave the
// adjustment and its Horn poses. Stage 3 alone, on the true cameras.
TEST(CalibrateSystemVerdicts, ACaptureStageTwoSetAsideStaysOut) {
  const auto s = testing::MakeDefaultScene(72, 12, kNoisePx);
  const CalibrationInput& in = s.data.input;
  std::vector<ModuleCameras> modules;
  for (int k = 0; k < 2; ++k) {
    const StereoModule& m = s.truth.rig.module(k);
    modules.push_back({m.left_camera, m.right_camera, s.truth.rig.camera(m.left_camera),
                       s.truth.rig.camera(m.right_camera), m.right_from_left});
  }
  SystemOptions options;
  options.compute_covariance = false;
  const SystemReport all = CalibrateSystem(in, modules, kNoisePx, options, SystemExclusions{}).report;
  // A capture both modules posed: module 1's corners in it.
  const auto views = PoseBoardsByTriangulation(in, modules, options.min_triangulated_corners);
  int capture = -1;
  for (const auto& [c, v] : views[1])
    if (views[0].count(c)) capture = c;
  ASSERT_GE(capture, 0);
  int module1_corners = 0;
  for (const BoardObservation& o : in.observations)
    if (o.capture == capture && (o.camera == 2 || o.camera == 3))
      module1_corners += static_cast<int>(o.corner_ids.size());
  ASSERT_GT(module1_corners, 0);

  SystemExclusions set_aside;
  set_aside.module_captures.insert({capture, 1});
  const SystemReport without = CalibrateSystem(in, modules, kNoisePx, options, set_aside).report;
  EXPECT_EQ(without.num_residual_corners, all.num_residual_corners - module1_corners);
  EXPECT_EQ(without.shared_captures.at({0, 1}), all.shared_captures.at({0, 1}) - 1);
  EXPECT_EQ(without.num_captures, all.num_captures);  // module 0 still poses it
}

// Stage 3 with LENSMODEL_OPENCV12 (default rig, its lenses OPENCV8 with k4..k6
// 0, 25 captures at 0.2 px). Ceres has none of mrcal's regularisation:
// freed outright, the rational k4..k6 and the thin-prism s1..s4 were not
// determined by the corners (on the demo dataset Ceres stopped at
// NO_CONVERGENCE after 100 iterations, k1..k6 in the hundreds, a pole-zero
// pair inside the image, S[0][1] 2.95 mm off the truth against a reported
// 1 sigma of 0.0099 mm, and the rig was written). They are refined under
// stage 2's covariance of them (its regularisation as the prior), which
// keeps them within its spread and the solve converging.
TEST(CalibrateSystemVerdicts, OpenCv12RefinesItsRationalAndPrismTermsUnderAPriorAndConverges) {
  const auto s = testing::MakeDefaultScene(73, 25, kNoisePx);
  CalibrationOptions opt;
  opt.intrinsics.lensmodel = "LENSMODEL_OPENCV12";
  const CalibrationResult r = Calibrate(s.data.input, opt);
  const SystemReport& sys = r.report.system;
  std::printf("%s", SummaryText(r.report).c_str());
  EXPECT_EQ(r.report.not_converged, "");
  EXPECT_NE(sys.solver_summary.find("Termination: CONVERGENCE"), std::string::npos) << sys.solver_summary;
  EXPECT_EQ(sys.covariance_status, "ok");
  EXPECT_EQ(sys.sigma_conditional_on, "");

  // k4..k6, s1..s4 (mrcal's indices 9..15): moved from stage 2's values by
  // less than 4 of stage 2's sigmas (the prior's), and reported with those
  // sigmas (stage 3's corners are stage 2's: what they say of these terms
  // stage 2 already took in, calib/system.cc). k1..k6 stay far from a
  // pole-zero pair (the default lenses' |k| <= 0.11).
  ASSERT_EQ(sys.intrinsics_sigma.size(), 4u);
  for (const RefinedIntrinsicsSigma& x : sys.intrinsics_sigma) {
    const StereoReport& module = r.report.stereo[x.camera / 2];  // the default rig: cameras 2k, 2k + 1
    const IntrinsicsReport& stage2 = x.camera % 2 ? module.right : module.left;
    ASSERT_EQ(x.intrinsics.size(), 16u);
    ASSERT_EQ(stage2.intrinsics_covariance.size(), 16u * 16u);
    for (size_t i = 0; i < 16; ++i) {
      EXPECT_GT(x.sigma[i], 0.0) << "camera " << x.camera << " intrinsic " << i;
      if (i < 9) continue;
      const double prior_sigma = std::sqrt(stage2.intrinsics_covariance[i * 16 + i]);
      EXPECT_LT(std::abs(x.intrinsics[i] - stage2.intrinsics[i]), 4.0 * prior_sigma)
          << "camera " << x.camera << " intrinsic " << i;
      EXPECT_NEAR(x.sigma[i], prior_sigma, 1e-6 * prior_sigma) << "camera " << x.camera << " intrinsic " << i;
    }
    for (size_t i : {4, 5, 8, 9, 10, 11}) EXPECT_LT(std::abs(x.intrinsics[i]), 1.0) << "camera " << x.camera;
  }

  // S: OPENCV12's stage 1 leaves each principal point 6-27 px (1 sigma)
  // from these views, so each module's frame (its left camera's) is known to
  // ~1 deg and S against the truth judges the lens, not stage 3. What the
  // frames do not change is judged: the two modules' measurements of the
  // same points agree within the e2e tests' bound at this noise
  // (calibrate_test.cc, CheckRig: 0.05 mm).
  const auto points = VolumePoints(s.ref_from_volume, Eigen::Vector3d(75, 75, 50), 500, 73);
  const double agreement = testing::ModuleAgreementRms(s.truth.rig, r.rig, r.rig.S(0, 1), 0, 1, points);
  std::printf("agreement 0-1: %.4f mm\n", agreement);
  EXPECT_LT(agreement, 0.05);
}

// S's 1 sigma with OPENCV12 holds the uncertainty of the terms stage 3
// cannot determine alone (k4..k6, s1..s4): it refines them under stage 2's
// covariance of them, where before it held them at stage 2's values and
// reported S as if they were exact. The thin-prism terms trade with the
// principal points, which a camera's frame, and so S, follows: held, S was
// 24-75 sigma from the truth on the demo dataset (1.67 mm against
// 0.02 mm), its principal points 4 px off against a reported 0.05 px.
// Judged on two seeds of the default rig, 50 captures at 0.2 px, in the
// reported sigma: S's 6 components and each camera's cx, cy, 14 z's a seed.
// Gaussian, each |z| is below 4 but for 6.3e-5 of draws: a false alarm ~28
// x 6.3e-5 = 2e-3. Measured when written, over seeds 73..82: largest |z|
// of S 0.75 - 2.49, of cx, cy 1.18 - 2.67. With 25 captures OPENCV12's
// principal points are known to 6-27 px, S's error reaches degrees and the
// linearised covariance holds less well: S 0.97 - 3.74, cx, cy up to 4.9.
// Held (before), seeds 73 and 74 read S's |z| up to 21.4 and 37.9, cx, cy up to 76.6 and
// 56.4.
TEST(CalibrateSystemVerdicts, OpenCv12SigmaOfSHoldsItsHeldTermsUncertainty) {
  for (unsigned seed : {73u, 74u}) {
    const auto s = testing::MakeDefaultScene(seed, 50, kNoisePx);
    CalibrationOptions opt;
    opt.intrinsics.lensmodel = "LENSMODEL_OPENCV12";
    const CalibrationResult r = Calibrate(s.data.input, opt);
    const SystemReport& sys = r.report.system;
    ASSERT_EQ(r.report.not_converged, "") << "seed " << seed;
    ASSERT_EQ(sys.covariance_status, "ok") << "seed " << seed;
    ASSERT_EQ(sys.sigma.size(), 1u);
    const SError e = SErrorAgainstTruth(r.rig, s.truth.rig);
    const Eigen::Vector3d &dr = e.rotation_deg, &dt = e.translation_mm;
    double max_s = 0, max_c = 0;
    for (int i = 0; i < 3; ++i) {
      const double zr = dr(i) / sys.sigma[0].rotation_deg(i), zt = dt(i) / sys.sigma[0].translation_mm(i);
      EXPECT_LT(std::abs(zr), 4.0) << "seed " << seed << ", S rotation " << i << ": " << dr(i) << " deg";
      EXPECT_LT(std::abs(zt), 4.0) << "seed " << seed << ", S translation " << i << ": " << dt(i) << " mm";
      max_s = std::max({max_s, std::abs(zr), std::abs(zt)});
    }
    ASSERT_EQ(sys.intrinsics_sigma.size(), 4u);
    for (const RefinedIntrinsicsSigma& x : sys.intrinsics_sigma) {
      const std::vector<double>& t = s.truth.rig.camera(x.camera).intrinsics();
      for (int i : {2, 3}) {
        const double z = (x.intrinsics[i] - t[i]) / x.sigma[i];
        EXPECT_LT(std::abs(z), 4.0) << "seed " << seed << ", camera " << x.camera << (i == 2 ? " cx " : " cy ")
                                    << x.intrinsics[i] << " against " << t[i] << " +- " << x.sigma[i];
        max_c = std::max(max_c, std::abs(z));
      }
    }
    std::printf("seed %u: largest |error| / reported sigma: S %.2f, principal points %.2f\n", seed, max_s, max_c);
  }
}

// Stage 2 solves a module's two lenses jointly, so their terms are not
// independent: it reports their cross-covariance (StereoReport::
// intrinsics_cross_covariance), and stage 3's prior on the terms it cannot
// determine alone is joint over the pair (HeldIntrinsicsPrior::CreateJoint;
// before, each camera's alone). Checked against the joint solve's own
// covariance through another route: Var(theta_l + theta_r) of each held
// term, from a gradient on the sum, is Var(theta_l) + Var(theta_r) + 2
// Cov(theta_l, theta_r). Measured (OPENCV12, demo dataset): the held terms'
// correlation across a pair is at most 0.085 and 0.114, and S's and the
// principal points' sigmas and z-scores against the truth move in the
// third digit (S's largest |z| 1.41 either way, cx, cy 2.27 against 2.26;
// default rig, 50 captures, seeds 73-82: S 0.74 - 2.49 against 0.75 -
// 2.49, cx, cy 1.18 - 2.66 against 1.18 - 2.67).
TEST(CalibrateSystemVerdicts, StageTwoGivesTheCrossCovarianceOfAModulesLenses) {
  const auto s = testing::MakeDefaultScene(73, 25, kNoisePx);
  CalibrationOptions opt;
  opt.intrinsics.lensmodel = "LENSMODEL_OPENCV12";
  const CalibrationResult r = Calibrate(s.data.input, opt);
  ASSERT_EQ(r.report.not_converged, "");
  const MrcalProblem& p = r.stage2[0].problem;
  const StereoReport& m = r.report.stereo[0];
  const int n = p.num_params();
  ASSERT_EQ(m.intrinsics_cross_covariance.size(), static_cast<size_t>(n * n));
  const ProjectionUncertaintyEvaluator eval(p);
  ASSERT_TRUE(eval.ok());
  int istate[2];
  for (int k = 0; k < 2; ++k)
    istate[k] = mrcal_state_index_intrinsics(k, p.num_intrinsics_cameras, p.num_extrinsics(), p.num_frames(), 0, 0,
                                             p.num_observations(), p.selections, &p.lensmodel);
  double largest_correlation = 0;
  for (int i : Stage3HeldIntrinsics("LENSMODEL_OPENCV12", n)) {
    StateGradient sum = StateGradient::Zero(1, p.num_states());
    sum(0, istate[0] + i) = sum(0, istate[1] + i) = 1.0;
    const double var_sum = eval.Covariance(sum, /*regularisation_as_prior=*/true)(0, 0);
    const double var_l = m.left.intrinsics_covariance[i * n + i], var_r = m.right.intrinsics_covariance[i * n + i];
    const double cov_lr = m.intrinsics_cross_covariance[i * n + i];
    EXPECT_NEAR(var_sum, var_l + var_r + 2 * cov_lr, 1e-9 * var_sum) << "intrinsic " << i;
    largest_correlation = std::max(largest_correlation, std::abs(cov_lr) / std::sqrt(var_l * var_r));
  }
  std::printf("largest correlation of a held term across module 0's pair: %.3f\n", largest_correlation);
  EXPECT_GT(largest_correlation, 0.0);
  EXPECT_LT(largest_correlation, 1.0);
}

// Without stage 2's covariance of them (CalibrateSystem called with bare
// cameras), OPENCV8's k4..k6 are held at their values, reported with sigma
// 0, and the report says S's 1 sigma is conditional on them; with the
// intrinsics not refined at all, on every camera's.
TEST(CalibrateSystemVerdicts, HeldWithoutAPriorTheSigmaOfSIsSaidConditional) {
  const auto s = testing::MakeDefaultScene(72, 12, kNoisePx);
  std::vector<ModuleCameras> modules;
  for (int k = 0; k < 2; ++k) {
    const StereoModule& m = s.truth.rig.module(k);
    modules.push_back({m.left_camera, m.right_camera, s.truth.rig.camera(m.left_camera),
                       s.truth.rig.camera(m.right_camera), m.right_from_left});
  }
  ASSERT_EQ(modules[0].left.lensmodel_name(), "LENSMODEL_OPENCV8");
  const SystemReport held = CalibrateSystem(s.data.input, modules, kNoisePx, SystemOptions(), {}).report;
  EXPECT_EQ(held.covariance_status, "ok");
  EXPECT_EQ(held.sigma_conditional_on.rfind("camera(s) 0, 1, 2, 3's k4..", 0), 0u) << held.sigma_conditional_on;
  ASSERT_EQ(held.intrinsics_sigma.size(), 4u);
  for (const RefinedIntrinsicsSigma& x : held.intrinsics_sigma) {
    for (size_t i = 9; i < 12; ++i) {
      EXPECT_EQ(x.sigma[i], 0.0) << "camera " << x.camera << " intrinsic " << i;
      EXPECT_EQ(x.intrinsics[i], s.truth.rig.camera(x.camera).intrinsics()[i]);
    }
  }
  SystemOptions fixed;
  fixed.refine_intrinsics = false;
  const SystemReport all_held = CalibrateSystem(s.data.input, modules, kNoisePx, fixed, {}).report;
  EXPECT_EQ(all_held.sigma_conditional_on.rfind("every camera's intrinsics", 0), 0u) << all_held.sigma_conditional_on;
}

// A stage 3 whose Ceres solve stopped short (here at its iteration limit,
// 1) did not converge, whatever its RMS: the rig file is not written. Its
// RMS after one step from Horn is already near the noise, which alone let
// it pass before. The refusal names the limit and its flag.
TEST(CalibrateSystemVerdicts, ASolveThatStoppedShortDidNotConverge) {
  const auto s = testing::MakeDefaultScene(74, 12, kNoisePx);
  CalibrationOptions opt;
  opt.system.max_iterations = 1;
  const CalibrationResult r = Calibrate(s.data.input, opt);
  EXPECT_EQ(r.report.not_converged.rfind("stage 3 did not converge: Ceres ", 0), 0u) << r.report.not_converged;
  EXPECT_NE(r.report.not_converged.find("NO_CONVERGENCE"), std::string::npos) << r.report.not_converged;
  EXPECT_NE(r.report.not_converged.find("it reached its iteration limit, --max-iterations 1: "), std::string::npos)
      << r.report.not_converged;
}

// Stage 3's first solve, Horn-only (S and the stereo pairs held at Horn's
// and stage 2's, the board poses solved), had its ending unchecked: stopped
// short, its rms (the report's horn_only, the rig file's
// rig_horn_only_rms_px) is where it stopped, not what Horn's S gives. It
// only seeds the full adjustment, which is judged on its own, so it is
// warned of (the report's warnings, the summary), not refused for. The
// seam: max_iterations = 1 stops it (and the full solve) short; the
// default (100) does not.
TEST(CalibrateSystemVerdicts, AHornOnlySolveThatStoppedShortIsWarnedOf) {
  const auto s = testing::MakeDefaultScene(74, 12, kNoisePx);
  const CalibrationResult ok = Calibrate(s.data.input, CalibrationOptions());
  EXPECT_EQ(ok.report.not_converged, "");
  EXPECT_TRUE(ok.report.warnings.empty()) << ok.report.warnings[0];
  EXPECT_EQ(nlohmann::json::parse(ok.report.ToJson())["stage3_system"]["horn_only"]["solver_problem"], "");

  CalibrationOptions opt;
  opt.system.max_iterations = 1;
  const CalibrationResult r = Calibrate(s.data.input, opt);
  ASSERT_EQ(r.report.warnings.size(), 1u);
  const std::string& w = r.report.warnings[0];
  EXPECT_EQ(w.rfind("stage 3's Horn-only solve (S and the stereo pairs held at Horn's and stage 2's, the board poses "
                    "solved) did not converge: Ceres ended at NO_CONVERGENCE after 1 iteration (",
                    0),
            0u)
      << w;
  EXPECT_NE(w.find("its rms (the report's horn_only, the rig file's rig_horn_only_rms_px) is where it stopped"),
            std::string::npos)
      << w;
  const nlohmann::json j = nlohmann::json::parse(r.report.ToJson());
  EXPECT_EQ(
      j["stage3_system"]["horn_only"]["solver_problem"].get<std::string>().rfind("Ceres ended at NO_CONVERGENCE", 0),
      0u);
  EXPECT_EQ(j["warnings"][0], w);
  EXPECT_NE(SummaryText(r.report).find("  (the Horn-only rms is where its solve stopped: Ceres ended at "
                                       "NO_CONVERGENCE"),
            std::string::npos);
}

}  // namespace
}  // namespace stereorig
