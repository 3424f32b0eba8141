// End to end and statistical: the engine on synthetic captures of the
// default rig, over 20 seeds, judged against the truth by the users' own
// figures, and every reported parameter against its reported 1 sigma: stage 1's
// intrinsics, stage 2's right_from_left, and stage 3's refined intrinsics and
// right_from_left (the values the rig file holds, with ceres::Covariance's
// sigma).
// Noise: 0.2 px Gaussian per corner coordinate; 25 captures of a 9x7, 12 mm
// double-sided board.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "calib/calib_test_util.h"
#include "calib/calibrate.h"

namespace stereorig {
namespace {

constexpr double kNoisePx = 0.2;
constexpr int kCaptures = 25;

struct SeedFigures {
  double max_stage1_rms_dev = 0;                     // max |rms - noise| / noise over cameras
  std::vector<double> e2_centre, s2_centre;          // per camera: |e|^2 and predicted sigma^2 at the centre
  std::vector<double> e2_corners, s2_corners;        // the same (|e|^2 / 2, sigma^2) at the four image corners
  std::vector<double> module_3d_rms;                 // per module, mm
  double agreement_refined = 0, agreement_horn = 0;  // mm
  Eigen::Matrix<double, 6, 1> s_z = Eigen::Matrix<double, 6, 1>::Zero();  // S[0][1] error / sigma
  double bff_measured_error_mm = 0, bff_refined_error_mm = 0;             // |t| error of back_from_front vs truth
  // Reported parameter error / reported 1 sigma (z-scores):
  std::vector<std::vector<double>> intrinsics_z;  // stage 1: (cameras, Nparams)
  std::vector<std::vector<double>> stereo_z;      // stage 2: (modules, kStereoParams)
  // The rig file's (stage 3's refined) values against stage 3's own sigma:
  std::vector<std::vector<double>> refined_stereo_z;      // (modules, kStereoParams)
  std::vector<std::vector<double>> refined_intrinsics_z;  // (cameras, Nparams)
  double seconds = 0;
};

// Stage 2's reported parameters, in the order of SeedFigures::stereo_z.
const char* const kStereoParams[] = {"baseline", "rotation angle", "rotvec x", "rotvec y", "rotvec z", "t x", "t y",
                                     "t z"};
constexpr int kNumStereoParams = 8;

SeedFigures RunSeed(unsigned seed, CalibrationResult* out = nullptr) {
  const auto scene = testing::MakeDefaultScene(seed, kCaptures, kNoisePx);
  const auto t0 = std::chrono::steady_clock::now();
  CalibrationOptions opt;
  CalibrationResult r = Calibrate(scene.data.input, opt);
  SeedFigures f;
  f.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const Rig& truth = scene.truth.rig;
  for (const IntrinsicsReport& ir : r.report.intrinsics) {
    f.max_stage1_rms_dev = std::max(f.max_stage1_rms_dev, std::abs(ir.rms_px - kNoisePx) / kNoisePx);
  }
  for (int cam = 0; cam < 4; ++cam) {
    const IntrinsicsResult& s1 = r.stage1[cam];
    std::vector<Pose> true_cam_from_face;
    for (size_t k = 0; k < s1.captures.size(); ++k) {
      const Pose face_from_front = s1.faces[k] == Face::kFront ? Pose::Identity() : scene.true_back_from_front;
      true_cam_from_face.push_back(truth.CamFromReference(cam) * scene.data.ref_from_front[s1.captures[k]] *
                                   face_from_front.Inverse());
    }
    const PixelUncertainty& u = s1.report.uncertainty.at(0);
    // The actual error at the range the predicted sigma is reported at (the
    // camera's median board distance, ~205-215 mm here), not a fixed 200 mm.
    const double range_mm = s1.report.uncertainty_range_mm;
    const Eigen::Vector2d e = testing::MeanFramesProjectionError(truth.camera(cam), true_cam_from_face, s1.camera,
                                                                 s1.cam_from_face, u.q_px, range_mm);
    f.e2_centre.push_back(e.squaredNorm() / 2.0);
    f.s2_centre.push_back(u.rms_stdev_px * u.rms_stdev_px);
    // The four image corners too (extrapolated beyond most of the corners seen).
    for (size_t k = 1; k < s1.report.uncertainty.size(); ++k) {
      const PixelUncertainty& uk = s1.report.uncertainty[k];
      const Eigen::Vector2d ek = testing::MeanFramesProjectionError(truth.camera(cam), true_cam_from_face, s1.camera,
                                                                    s1.cam_from_face, uk.q_px, range_mm);
      f.e2_corners.push_back(ek.squaredNorm() / 2.0);
      f.s2_corners.push_back(uk.rms_stdev_px * uk.rms_stdev_px);
    }
  }
  // Every reported intrinsic of stage 1 (OPENCV5 = the first 9 of the true
  // OPENCV8 lens, whose k4..k6 are 0) against the truth, in its sigma.
  for (int cam = 0; cam < 4; ++cam) {
    const IntrinsicsReport& ir = r.report.intrinsics[cam];
    const std::vector<double>& t = truth.camera(cam).intrinsics();
    std::vector<double> z;
    for (size_t i = 0; i < ir.intrinsics.size(); ++i) z.push_back((ir.intrinsics[i] - t[i]) / ir.intrinsics_sigma[i]);
    f.intrinsics_z.push_back(z);
  }
  // Stage 2's right_from_left, baseline and rotation angle.
  for (const StereoReport& st : r.report.stereo) {
    const Pose& t = truth.module(st.module).right_from_left;
    const Eigen::Vector3d rv_deg = t.RotationVector() * 180.0 / M_PI;
    std::vector<double> z = {(st.baseline_mm - t.DistanceMm()) / st.baseline_sigma_mm,
                             (st.rotation_deg - t.AngleDeg()) / st.rotation_sigma_deg};
    for (int i = 0; i < 3; ++i) {
      z.push_back((st.right_from_left_rotation_vector_deg(i) - rv_deg(i)) /
                  st.right_from_left_rotation_vector_sigma_deg(i));
    }
    for (int i = 0; i < 3; ++i) {
      z.push_back((st.right_from_left_translation_mm(i) - t.translation_mm()(i)) /
                  st.right_from_left_translation_sigma_mm(i));
    }
    f.stereo_z.push_back(z);
  }
  // Stage 3's refined right_from_left and intrinsics (what the rig file
  // holds), checked on the rig itself, in stage 3's reported sigma.
  for (const RefinedStereoSigma& x : r.report.system.stereo_sigma) {
    const Pose& t = truth.module(x.module).right_from_left;
    const Pose& est = r.rig.module(x.module).right_from_left;
    const Eigen::Vector3d rv_deg = t.RotationVector() * 180.0 / M_PI;
    const Eigen::Vector3d est_rv_deg = est.RotationVector() * 180.0 / M_PI;
    std::vector<double> z = {(est.DistanceMm() - t.DistanceMm()) / x.baseline_sigma_mm,
                             (est.AngleDeg() - t.AngleDeg()) / x.rotation_sigma_deg};
    for (int i = 0; i < 3; ++i) z.push_back((est_rv_deg(i) - rv_deg(i)) / x.rotation_vector_sigma_deg(i));
    for (int i = 0; i < 3; ++i) {
      z.push_back((est.translation_mm()(i) - t.translation_mm()(i)) / x.translation_sigma_mm(i));
    }
    f.refined_stereo_z.push_back(z);
  }
  for (const RefinedIntrinsicsSigma& x : r.report.system.intrinsics_sigma) {
    const std::vector<double>& t = truth.camera(x.camera).intrinsics();
    const std::vector<double>& est = r.rig.camera(x.camera).intrinsics();
    std::vector<double> z;
    for (size_t i = 0; i < est.size(); ++i) z.push_back((est[i] - t[i]) / x.sigma[i]);
    f.refined_intrinsics_z.push_back(z);
  }
  const auto points = VolumePoints(scene.ref_from_volume, Eigen::Vector3d(75, 75, 50), 500, seed + 1000);
  for (int k = 0; k < 2; ++k) {
    std::vector<Eigen::Vector3d> pc, pt;
    testing::TriangulateThroughModule(truth, r.rig, k, points, &pc, &pt);
    f.module_3d_rms.push_back(testing::RigidAlignedRms(pt, pc));
  }
  f.agreement_refined = testing::ModuleAgreementRms(truth, r.rig, r.rig.S(0, 1), 0, 1, points);
  // Horn-only is judged with the cameras it was computed from (stage 2's).
  std::vector<Camera> cams = r.rig.cameras();
  std::vector<StereoModule> mods = r.rig.modules();
  for (int k = 0; k < 2; ++k) {
    cams[mods[k].left_camera] = r.stage2[k].left;
    cams[mods[k].right_camera] = r.stage2[k].right;
    mods[k].right_from_left = r.stage2[k].right_from_left;
  }
  const Rig horn_rig(cams, r.rig.camera_names(), mods, r.stage3.module0_from_module_horn);
  f.agreement_horn = testing::ModuleAgreementRms(truth, horn_rig, horn_rig.S(0, 1), 0, 1, points);
  if (!r.report.system.sigma.empty()) {
    const STransformSigma& s = r.report.system.sigma[0];
    // Rotation error in the reference frame (left perturbation), as sigma is.
    const Eigen::Vector3d dr =
        Pose(r.rig.S(0, 1).rotation() * truth.S(0, 1).rotation().transpose(), Eigen::Vector3d::Zero())
            .RotationVector() *
        180.0 / M_PI;
    const Eigen::Vector3d dt = r.rig.S(0, 1).translation_mm() - truth.S(0, 1).translation_mm();
    for (int i = 0; i < 3; ++i) {
      f.s_z(i) = dr(i) / s.rotation_deg(i);
      f.s_z(3 + i) = dt(i) / s.translation_mm(i);
    }
  }
  {
    const Pose& told = scene.data.input.target.back_from_front;
    const Pose& est = r.report.system.back_from_front;
    const Pose& tru = scene.true_back_from_front;
    f.bff_measured_error_mm = (told.translation_mm() - tru.translation_mm()).norm();
    f.bff_refined_error_mm = (est.translation_mm() - tru.translation_mm()).norm();
  }
  if (out) *out = std::move(r);
  return f;
}

TEST(CalibrateE2E, DefaultRigOverSeeds) {
  const int kSeeds = 20;
  std::vector<SeedFigures> all;
  for (int s = 0; s < kSeeds; ++s) {
    all.push_back(RunSeed(100 + s));
    const SeedFigures& f = all.back();
    std::printf(
        "seed %d: %.2fs rmsdev %.3f 3d %.4f %.4f agree refined %.4f horn %.4f z [%.1f %.1f %.1f %.1f %.1f %.1f]\n", s,
        f.seconds, f.max_stage1_rms_dev, f.module_3d_rms[0], f.module_3d_rms[1], f.agreement_refined, f.agreement_horn,
        f.s_z(0), f.s_z(1), f.s_z(2), f.s_z(3), f.s_z(4), f.s_z(5));
  }
  // Residuals: every camera's stage-1 RMS within 10% of the injected noise.
  for (const auto& f : all) EXPECT_LT(f.max_stage1_rms_dev, 0.10);
  // Uncertainty that tells the truth: RMS actual projection error at the
  // image centre (mean-frames, against the true camera) over RMS predicted
  // 1 sigma, pooled over 20 seeds x 4 cameras, in [0.7, 1.4]; and the error
  // within 3 predicted sigma (per coordinate) in >= 95% of cases.
  double e2 = 0, s2 = 0;
  int within3 = 0, n = 0;
  for (const auto& f : all)
    for (size_t c = 0; c < f.e2_centre.size(); ++c) {
      e2 += f.e2_centre[c], s2 += f.s2_centre[c];
      within3 += f.e2_centre[c] <= 9.0 * f.s2_centre[c];
      ++n;
    }
  const double honesty = std::sqrt(e2 / s2);
  std::printf("uncertainty honesty at the centre: actual/predicted = %.3f; within 3 sigma %d/%d\n", honesty, within3,
              n);
  EXPECT_GE(honesty, 0.7);
  EXPECT_LE(honesty, 1.4);
  EXPECT_GE(within3, 0.95 * n);
  // At the image corners as well (pooled over 20 seeds x 4 cameras x 4 corners).
  double e2c = 0, s2c = 0;
  for (const auto& f : all)
    for (size_t c = 0; c < f.e2_corners.size(); ++c) e2c += f.e2_corners[c], s2c += f.s2_corners[c];
  const double honesty_corners = std::sqrt(e2c / s2c);
  std::printf("uncertainty honesty at the image corners: actual/predicted = %.3f\n", honesty_corners);
  EXPECT_GE(honesty_corners, 0.7);
  EXPECT_LE(honesty_corners, 1.4);
  // A module's 3D error from calibration alone <= 0.05 mm in 95% of seeds x modules.
  int ok3d = 0, n3d = 0;
  for (const auto& f : all)
    for (double e : f.module_3d_rms) ok3d += e <= 0.05, ++n3d;
  EXPECT_GE(ok3d, 0.95 * n3d);
  // Module agreement through S <= 0.05 mm in 95% of seeds; the refined S
  // beats Horn alone (in 95% of seeds and on average).
  int ok_agree = 0, beats = 0;
  double mean_refined = 0, mean_horn = 0;
  for (const auto& f : all) {
    ok_agree += f.agreement_refined <= 0.05;
    beats += f.agreement_refined < f.agreement_horn;
    mean_refined += f.agreement_refined / kSeeds;
    mean_horn += f.agreement_horn / kSeeds;
  }
  std::printf("agreement: refined mean %.4f mm, Horn-only mean %.4f mm; refined <= 0.05 in %d/%d\n", mean_refined,
              mean_horn, ok_agree, kSeeds);
  EXPECT_GE(ok_agree, 0.95 * kSeeds);
  EXPECT_GE(beats, 0.95 * kSeeds);
  EXPECT_LT(mean_refined, mean_horn);
  // The reported sigma of S against the truth: each of the 6 entries within
  // 3 sigma in >= 95% of seeds, and the RMS z-score near 1 ([0.6, 1.5]).
  double z2 = 0;
  for (int i = 0; i < 6; ++i) {
    int in3 = 0;
    for (const auto& f : all) {
      in3 += std::abs(f.s_z(i)) <= 3.0;
      z2 += f.s_z(i) * f.s_z(i);
    }
    EXPECT_GE(in3, 0.95 * kSeeds) << "S entry " << i;
  }
  // back_from_front: the adjustment moves it towards the truth from the
  // measured value it was given (drawn with 0.05 mm sigma per axis).
  int bff_better = 0;
  for (const auto& f : all) bff_better += f.bff_refined_error_mm < f.bff_measured_error_mm;
  EXPECT_GE(bff_better, 0.95 * kSeeds);
  const double z_rms = std::sqrt(z2 / (6.0 * kSeeds));
  std::printf("S sigma honesty: RMS z-score %.3f\n", z_rms);
  EXPECT_GE(z_rms, 0.6);
  EXPECT_LE(z_rms, 1.5);

  // Every reported parameter of stages 1 and 2 against the truth: for each
  // parameter, the error within 3 reported sigma in >= 95% of the seeds,
  // pooled over the cameras (80 camera-seeds) or modules (40), and its RMS
  // z-score near 1 ([0.7, 1.4], the band for the projection
  // honesty). Per single camera the distortion coefficients fall short: k1,
  // k2 of camera 0 are beyond 3 sigma in 2 of 20 seeds (z up to 3.7; k3 3.9),
  // so their tails are heavier than Gaussian (measured: 5 of 240 k-values
  // beyond 3 sigma, 0.65 expected). The exceedances are printed.
  const char* const kIntrinsicNames[] = {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"};
  auto check = [&](const char* name, auto z_of, int entities) {
    double z2 = 0;
    int n = 0, in3_all = 0;
    for (int e = 0; e < entities; ++e) {
      int in3 = 0;
      for (const auto& f : all) {
        const double z = z_of(f, e);
        in3 += std::abs(z) <= 3.0;
        z2 += z * z;
        ++n;
      }
      in3_all += in3;
      if (in3 < kSeeds) {
        std::printf("  %s of %d beyond 3 sigma:", name, e);
        for (size_t k = 0; k < all.size(); ++k)
          if (std::abs(z_of(all[k], e)) > 3.0) std::printf(" seed %zu z %.2f", k, z_of(all[k], e));
        std::printf("\n");
      }
    }
    EXPECT_GE(in3_all, 0.95 * n) << name;
    const double rms = std::sqrt(z2 / n);
    std::printf("  %-15s RMS z-score %.3f, within 3 sigma %d/%d\n", name, rms, in3_all, n);
    EXPECT_GE(rms, 0.7) << name;
    EXPECT_LE(rms, 1.4) << name;
  };
  std::printf("stage 1 intrinsics vs truth / reported sigma:\n");
  for (int i = 0; i < 9; ++i) {
    check(
        kIntrinsicNames[i], [i](const SeedFigures& f, int cam) { return f.intrinsics_z[cam][i]; }, 4);
  }
  std::printf("stage 2 right_from_left vs truth / reported sigma:\n");
  for (int i = 0; i < kNumStereoParams; ++i) {
    check(
        kStereoParams[i], [i](const SeedFigures& f, int m) { return f.stereo_z[m][i]; }, 2);
  }
  // The rig file's values: stage 3's refined intrinsics and right_from_left
  // against stage 3's ceres::Covariance sigma, by the same rule.
  for (const auto& f : all) {
    ASSERT_EQ(f.refined_intrinsics_z.size(), 4u);
    ASSERT_EQ(f.refined_stereo_z.size(), 2u);
  }
  std::printf("stage 3 refined intrinsics vs truth / reported sigma:\n");
  for (int i = 0; i < 9; ++i) {
    check(
        kIntrinsicNames[i], [i](const SeedFigures& f, int cam) { return f.refined_intrinsics_z[cam][i]; }, 4);
  }
  std::printf("stage 3 refined right_from_left vs truth / reported sigma:\n");
  for (int i = 0; i < kNumStereoParams; ++i) {
    check(
        kStereoParams[i], [i](const SeedFigures& f, int m) { return f.refined_stereo_z[m][i]; }, 2);
  }
}

}  // namespace
}  // namespace stereorig
