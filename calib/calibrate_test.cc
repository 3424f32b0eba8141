// End to end: the engine on synthetic captures of the default rig (and of a
// 1-module and a 3-module rig), judged against the truth by the users' own
// figures, over many seeds. Noise: 0.2 px Gaussian per corner coordinate;
// 25 captures of a 9x7, 12 mm double-sided board.
#include "calib/calibrate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "calib/calib_test_util.h"
#include "calib/core/input_error.h"
#include "calib/core/mrcal_c.h"
#include "calib/core/rig_file.h"

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
  double seconds = 0;
};

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
    const Eigen::Vector2d e = testing::MeanFramesProjectionError(truth.camera(cam), true_cam_from_face, s1.camera,
                                                                 s1.cam_from_face, u.q_px, 200.0);
    f.e2_centre.push_back(e.squaredNorm() / 2.0);
    f.s2_centre.push_back(u.rms_stdev_px * u.rms_stdev_px);
    // The four image corners too (extrapolated beyond most of the corners seen).
    for (size_t k = 1; k < s1.report.uncertainty.size(); ++k) {
      const PixelUncertainty& uk = s1.report.uncertainty[k];
      const Eigen::Vector2d ek = testing::MeanFramesProjectionError(truth.camera(cam), true_cam_from_face, s1.camera,
                                                                    s1.cam_from_face, uk.q_px, 200.0);
      f.e2_corners.push_back(ek.squaredNorm() / 2.0);
      f.s2_corners.push_back(uk.rms_stdev_px * uk.rms_stdev_px);
    }
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
}

}  // namespace
}  // namespace stereorig

namespace stereorig {
namespace {

// The same engine, no code change, on 1 and 3 modules. One seed each (the
// statistics are the default rig's, above); tolerances as there.
void CheckRig(const SimulatedRig& rig, unsigned seed) {
  const auto scene = testing::MakeScene(rig, seed, kCaptures, kNoisePx);
  const CalibrationResult r = Calibrate(scene.data.input, CalibrationOptions());
  const int M = rig.rig.num_modules();
  ASSERT_EQ(r.rig.num_modules(), M);
  ASSERT_EQ(static_cast<int>(r.rig.S().size()), M);
  std::string why;
  EXPECT_TRUE(r.rig.CheckS(&why)) << why;
  for (const IntrinsicsReport& ir : r.report.intrinsics) EXPECT_NEAR(ir.rms_px, kNoisePx, 0.1 * kNoisePx);
  const auto points = VolumePoints(scene.ref_from_volume, Eigen::Vector3d(75, 75, 50), 500, seed);
  for (int k = 0; k < M; ++k) {
    std::vector<Eigen::Vector3d> pc, pt;
    testing::TriangulateThroughModule(rig.rig, r.rig, k, points, &pc, &pt);
    ASSERT_GT(pc.size(), 100u);
    EXPECT_LT(testing::RigidAlignedRms(pt, pc), 0.05) << "module " << k;
  }
  for (int i = 0; i < M; ++i)
    for (int j = i + 1; j < M; ++j) {
      const double a = testing::ModuleAgreementRms(rig.rig, r.rig, r.rig.S(i, j), i, j, points);
      std::printf("M=%d agreement %d-%d: %.4f mm\n", M, i, j, a);
      EXPECT_LT(a, 0.05) << i << "-" << j;
    }
}

// The targets library's default board (11x9 corners of 9 mm) through the
// adapter, on the default rig: the same figures hold.
TEST(CalibrateE2E, DefaultTargetOfTheTargetsLibrary) {
  const SimulatedRig rig = MakeDefaultRig();
  const Pose volume = testing::DefaultVolume(rig.world_from_module0);
  const TargetGeometry target = TargetGeometryFromTarget(DefaultTarget());
  SyntheticOptions o;
  o.seed = 8;
  o.num_captures = kCaptures;
  o.noise_px = kNoisePx;
  const SyntheticData data = MakeSyntheticCaptures(rig.rig, target, target.back_from_front, volume, o);
  const CalibrationResult r = Calibrate(data.input, CalibrationOptions());
  for (const IntrinsicsReport& ir : r.report.intrinsics) EXPECT_NEAR(ir.rms_px, kNoisePx, 0.1 * kNoisePx);
  const auto points = VolumePoints(volume, Eigen::Vector3d(75, 75, 50), 500, 8);
  const double a = testing::ModuleAgreementRms(rig.rig, r.rig, r.rig.S(0, 1), 0, 1, points);
  std::printf("default target: agreement %.4f mm\n", a);
  EXPECT_LT(a, 0.05);
}

TEST(CalibrateE2E, OneModuleRig) { CheckRig(testing::MakeOneModuleRig(), 7); }

// A plain one-sided chessboard (what most labs own) serves stages 1 and 2 of
// a one-module rig.
TEST(CalibrateE2E, PlainBoardOneModule) {
  const SimulatedRig rig = testing::MakeOneModuleRig();
  TargetGeometry plain = DefaultTestTarget();
  plain.double_sided = false;
  SyntheticOptions o;
  o.seed = 9;
  o.num_captures = kCaptures;
  o.noise_px = kNoisePx;
  const Pose volume = testing::DefaultVolume(rig.world_from_module0);
  const SyntheticData data = MakeSyntheticCaptures(rig.rig, plain, plain.back_from_front, volume, o);
  const CalibrationResult r = Calibrate(data.input, CalibrationOptions());
  for (const IntrinsicsReport& ir : r.report.intrinsics) EXPECT_NEAR(ir.rms_px, kNoisePx, 0.1 * kNoisePx);
  std::vector<Eigen::Vector3d> pc, pt;
  testing::TriangulateThroughModule(rig.rig, r.rig, 0, VolumePoints(volume, Eigen::Vector3d(75, 75, 50), 500, 9), &pc,
                                    &pt);
  EXPECT_LT(testing::RigidAlignedRms(pt, pc), 0.05);
}
TEST(CalibrateE2E, ThreeModuleRig) { CheckRig(testing::MakeThreeModuleRig(), 7); }

// ---- Refusals: each an InputError naming the problem.
void ExpectRefused(const CalibrationInput& in, const std::string& needle) {
  try {
    Calibrate(in, CalibrationOptions());
    FAIL() << "accepted; expected a refusal mentioning '" << needle << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(CalibrateRefuses, CameraThatNeverSeesTheBoard) {
  auto s = testing::MakeDefaultScene(61, 10, kNoisePx);
  auto& obs = s.data.input.observations;
  obs.erase(std::remove_if(obs.begin(), obs.end(), [](const BoardObservation& o) { return o.camera == 2; }), obs.end());
  ExpectRefused(s.data.input, "never sees the board");
}

TEST(CalibrateRefuses, FaceSeenByTheWrongModule) {
  auto s = testing::MakeDefaultScene(62, 10, kNoisePx);
  s.data.input.modules[0].face = Face::kFront;
  s.data.input.modules[1].face = Face::kBack;
  for (auto& o : s.data.input.observations) {
    if (o.camera == 2) {
      o.face = Face::kFront;
      break;
    }
  }
  ExpectRefused(s.data.input, "wrong module");
}

TEST(CalibrateRefuses, CornerOutsideTheImager) {
  auto s = testing::MakeDefaultScene(63, 10, kNoisePx);
  s.data.input.cameras[1].width_px = 300;  // images of the wrong size
  ExpectRefused(s.data.input, "outside the 300x582 imager");
}

TEST(CalibrateRefuses, TooFewViews) {
  auto s = testing::MakeDefaultScene(64, 3, kNoisePx);
  ExpectRefused(s.data.input, "too few views");
}

TEST(CalibrateRefuses, AllViewsFrontoParallel) {
  auto s = testing::MakeDefaultScene(65, 10, kNoisePx);
  SyntheticOptions o;
  o.max_tilt_deg = 0.0;
  s.data = MakeSyntheticCaptures(s.truth.rig, s.data.input.target, s.true_back_from_front, s.ref_from_volume, o);
  ExpectRefused(s.data.input, "fronto-parallel");
}

TEST(CalibrateReport, ExportsCameramodelsThatMrcalReads) {
  const auto s = testing::MakeDefaultScene(67, 12, kNoisePx);
  const CalibrationResult r = Calibrate(s.data.input, CalibrationOptions());
  const std::string dir = ::testing::TempDir();
  const auto paths = ExportCameramodels(r.rig, dir);
  ASSERT_EQ(paths.size(), 4u);
  for (int c = 0; c < 4; ++c) {
    mrcal_cameramodel_t* m = mrcal_read_cameramodel_file(paths[c].c_str());
    ASSERT_NE(m, nullptr) << paths[c];
    const Camera read(r.rig.camera(c).lensmodel_name(),
                      std::vector<double>(m->intrinsics, m->intrinsics + r.rig.camera(c).intrinsics().size()),
                      m->imagersize[0], m->imagersize[1]);
    const Eigen::Vector3d p(10, -20, 210);
    EXPECT_LT((read.Project(p) - r.rig.camera(c).Project(p)).norm(), 1e-9);
    const Pose cam_from_ref = r.rig.CamFromReference(c);
    EXPECT_NEAR(m->rt_cam_ref[3], cam_from_ref.translation_mm().x(), 1e-9);
    mrcal_free_cameramodel(&m);
  }
}

TEST(CalibrateReport, JsonHoldsEveryStage) {
  const auto s = testing::MakeDefaultScene(66, 12, kNoisePx);
  const CalibrationResult r = Calibrate(s.data.input, CalibrationOptions());
  const std::string j = r.report.ToJson();
  std::printf("%s", SummaryText(r.report).c_str());
  // The rig file and report round-trip: the rig file reads back with its S.
  const std::string dir = ::testing::TempDir();
  WriteCalibrationOutputs(r, dir + "/rig.yaml", dir + "/report.json");
  const Rig back = ReadRigFile(dir + "/rig.yaml");
  EXPECT_LT((back.S(0, 1).Inverse() * r.rig.S(0, 1)).DistanceMm(), 1e-9);
  EXPECT_EQ(back.provenance().residuals.count("cam0_rms_px"), 1u);
  EXPECT_EQ(back.provenance().uncertainties.count("S_0_1_translation_mm"), 1u);
  for (const char* key : {"stage1_intrinsics", "projection_uncertainty", "coverage", "worst_views", "stage2_stereo",
                          "rectified_row_rms_px", "baseline_mm", "stage3_system", "horn_only", "refined", "sigma_S_0_k",
                          "back_from_front_refined"}) {
    EXPECT_NE(j.find(std::string("\"") + key + "\""), std::string::npos) << key;
  }
  // The stereo figures against the truth: 90 mm baseline, 6 deg verging.
  ASSERT_EQ(r.report.stereo.size(), 2u);
  for (const StereoReport& st : r.report.stereo) {
    EXPECT_NEAR(st.baseline_mm, s.truth.rig.module(st.module).right_from_left.DistanceMm(), 0.3);
    EXPECT_NEAR(st.rotation_deg, s.truth.rig.module(st.module).right_from_left.AngleDeg(), 0.3);
    // Rectified rows of matching corners differ by the corner noise of two
    // cameras: sqrt(2) * 0.2 px, less the fit; within 25%.
    EXPECT_NEAR(st.rectified_row_rms_px, std::sqrt(2.0) * kNoisePx, 0.25 * std::sqrt(2.0) * kNoisePx);
  }
}

}  // namespace
}  // namespace stereorig

namespace stereorig {
namespace {

// Judges a calibrated rig file against a simulated dataset's truth (not run
// by default: it needs a dataset from `stereorig simulate` and a rig from
// `stereorig calibrate` on it):
//   STEREORIG_TRUTH_RIG=data/truth/rig.yaml STEREORIG_CALIBRATED_RIG=rig.yaml
//     calib_e2e_test --gtest_also_run_disabled_tests --gtest_filter='*AgainstTruth*'
TEST(CalibrateDataset, DISABLED_AgainstTruth) {
  const char* truth_path = std::getenv("STEREORIG_TRUTH_RIG");
  const char* cal_path = std::getenv("STEREORIG_CALIBRATED_RIG");
  ASSERT_TRUE(truth_path && cal_path) << "set STEREORIG_TRUTH_RIG and STEREORIG_CALIBRATED_RIG";
  const Rig truth = ReadRigFile(truth_path);
  const Rig cal = ReadRigFile(cal_path);
  // The default volume: the world origin, 200 mm in front of module 0's nominal frame.
  const Pose ref_from_volume = testing::DefaultVolume(MakeDefaultRig().world_from_module0);
  const auto points = VolumePoints(ref_from_volume, Eigen::Vector3d(75, 75, 50), 2000, 1);
  for (int k = 0; k < truth.num_modules(); ++k) {
    std::vector<Eigen::Vector3d> pc, pt;
    testing::TriangulateThroughModule(truth, cal, k, points, &pc, &pt);
    const double e = testing::RigidAlignedRms(pt, pc);
    std::printf("module %d: 3D error after rigid alignment %.4f mm over %zu points; baseline %.4f mm (truth %.4f)\n", k,
                e, pc.size(), cal.module(k).right_from_left.DistanceMm(), truth.module(k).right_from_left.DistanceMm());
    EXPECT_LT(e, 0.05);
  }
  for (int i = 0; i < truth.num_modules(); ++i)
    for (int j = i + 1; j < truth.num_modules(); ++j) {
      const double a = testing::ModuleAgreementRms(truth, cal, cal.S(i, j), i, j, points);
      std::printf("modules %d-%d: agreement through S %.4f mm\n", i, j, a);
      EXPECT_LT(a, 0.05);
    }
}

}  // namespace
}  // namespace stereorig
