// Stage 1 on synthetic captures of the default rig (corners projected through
// the true cameras, 0.2 px Gaussian noise per coordinate), judged against the
// truth. The statistical versions over many seeds are in calibrate_test.cc.
#include "calib/intrinsics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <string>

#include "calib/calib_test_util.h"
#include "calib/core/input_error.h"
#include "calib/pinhole_seed.h"
#include "calib/stereo.h"

namespace stereorig {
namespace {

// True cam_from_face of one view (its capture and the face seen).
Pose TrueCamFromFace(const testing::DefaultScene& s, int cam, int capture, Face face) {
  const Pose face_from_front = face == Face::kFront ? Pose::Identity() : s.true_back_from_front;
  return s.truth.rig.CamFromReference(cam) * s.data.ref_from_front[capture] * face_from_front.Inverse();
}

// True cam_from_face of each view the solve used.
std::vector<Pose> TrueCamFromFace(const testing::DefaultScene& s, int cam, const IntrinsicsResult& r) {
  std::vector<Pose> out;
  for (size_t k = 0; k < r.captures.size(); ++k) out.push_back(TrueCamFromFace(s, cam, r.captures[k], r.faces[k]));
  return out;
}

// The largest board tilt among `views` posed by PnP through `seed`: what
// stage 1's tilt test holds a seed to before solving from it.
double MaxSeedTiltDeg(const std::vector<const BoardObservation*>& views, const TargetGeometry& target,
                      const PinholeSeed& seed) {
  double max_deg = 0;
  for (const BoardObservation* v : views) {
    const std::optional<Pose> pose = PinholeBoardPose(CornersOfView(*v, target), seed);
    if (pose) max_deg = std::max(max_deg, TiltDeg(*pose));
  }
  return max_deg;
}

// The largest tilt among board poses, deg.
double MaxTiltDeg(const std::vector<Pose>& cam_from_face) {
  double max_deg = 0;
  for (const Pose& pose : cam_from_face) max_deg = std::max(max_deg, TiltDeg(pose));
  return max_deg;
}

// The default scene with 20 captures of the board flat in the volume (tilt 0;
// roll as by default), its centre up to `lateral_mm` off the volume's axis
// and `depth_mm` along it.
testing::DefaultScene FlatBoardScene(unsigned seed, double noise_px, double lateral_mm, double depth_mm) {
  testing::DefaultScene s = testing::MakeDefaultScene(seed, 20, noise_px);
  SyntheticOptions o;
  o.seed = seed;
  o.num_captures = 20;
  o.noise_px = noise_px;
  o.max_tilt_deg = 0.0;
  o.lateral_mm = lateral_mm;
  o.depth_mm = depth_mm;
  s.data = MakeSyntheticCaptures(s.truth.rig, s.data.input.target, s.true_back_from_front, s.ref_from_volume, o);
  return s;
}

// Camera `cam`'s views of scene `s`, and stage 1's ranked pinhole seeds
// for them.
struct ViewsAndSeeds {
  std::vector<const BoardObservation*> views;
  std::vector<PinholeSeed> pinhole_seeds;
};
ViewsAndSeeds ViewsAndSeedsOf(const testing::DefaultScene& s, int cam, const IntrinsicsOptions& options) {
  ViewsAndSeeds v{testing::ViewsOf(s.data.input, cam), {}};
  const CameraImager& spec = s.data.input.cameras[cam];
  v.pinhole_seeds =
      RankedPinholeSeeds(v.views, s.data.input.target, spec.width_px, spec.height_px, options.seed_focal_px);
  return v;
}

// Asserts that `views` of camera `cam` are flat in truth (every board tilted
// under half of min_tilt_deg) and that the first of `pinhole_seeds` poses
// them under min_tilt_deg: stage 1 refuses it before solving.
void AssertFlatAndTheFirstSeedRefused(const testing::DefaultScene& s, int cam,
                                      const std::vector<const BoardObservation*>& views,
                                      const std::vector<PinholeSeed>& pinhole_seeds, const IntrinsicsOptions& options) {
  for (const BoardObservation* v : views) {
    ASSERT_LT(TiltDeg(TrueCamFromFace(s, cam, v->capture, v->face)), 0.5 * options.min_tilt_deg)
        << "capture " << v->capture;
  }
  ASSERT_LT(MaxSeedTiltDeg(views, s.data.input.target, pinhole_seeds[0]), options.min_tilt_deg)
      << "the first seed is not refused";
}

TEST(Intrinsics, Opencv8RecoversTheTruthWithinItsUncertainty) {
  const double noise = 0.2;
  for (unsigned seed : {11u, 12u}) {
    const auto s = testing::MakeDefaultScene(seed, 20, noise);
    for (int cam : {0, 3}) {
      const auto r = CalibrateIntrinsics(cam, s.data.input.cameras[cam], s.data.input.target,
                                         testing::ViewsOf(s.data.input, cam), IntrinsicsOptions(), "test");
      // Residual RMS per coordinate: the noise, less the fitted dof; 10%.
      EXPECT_NEAR(r.report.rms_px, noise, 0.1 * noise) << seed << " cam " << cam;
      EXPECT_EQ(r.report.num_outliers, 0);
      ASSERT_EQ(r.report.uncertainty.size(), 5u);
      // Projection at the image centre against the truth: within 4 sigma of
      // the predicted uncertainty (2D: |e|^2 / sigma^2 ~ chi2(2) / 2 scaled).
      const auto truth = TrueCamFromFace(s, cam, r);
      const Eigen::Vector2d e =
          testing::MeanFramesProjectionError(s.truth.rig.camera(cam), truth, r.camera, r.cam_from_face,
                                             r.report.uncertainty[0].q_px, r.report.uncertainty_range_mm);
      EXPECT_LT(e.norm(), 4.0 * std::sqrt(2.0) * r.report.uncertainty[0].rms_stdev_px) << seed << " cam " << cam;
      EXPECT_LT(r.report.uncertainty[0].rms_stdev_px, 0.2);  // the centre is well covered
      EXPECT_GT(r.report.coverage_fraction, 0.2);
    }
  }
}

// The projection uncertainty is reported at the board's median distance
// from the camera (the default, uncertainty_range_mm 0): the true poses'
// median, within what 0.2 px of corner noise moves a solved pose's depth
// (~0.1 mm at ~200 mm; 0.5 mm allowed). A given range is used as given.
TEST(Intrinsics, UncertaintyIsReportedWhereTheBoardWas) {
  const auto s = testing::MakeDefaultScene(13, 20, 0.2);
  for (int cam : {0, 3}) {
    const auto r = CalibrateIntrinsics(cam, s.data.input.cameras[cam], s.data.input.target,
                                       testing::ViewsOf(s.data.input, cam), IntrinsicsOptions(), "test");
    const TargetGeometry& g = s.data.input.target;
    const Eigen::Vector3d centre(0.5 * (g.corners_x - 1) * g.square_size_mm, 0.5 * (g.corners_y - 1) * g.square_size_mm,
                                 0);
    std::vector<double> true_mm;
    for (const Pose& cam_from_face : TrueCamFromFace(s, cam, r)) true_mm.push_back((cam_from_face * centre).norm());
    std::nth_element(true_mm.begin(), true_mm.begin() + true_mm.size() / 2, true_mm.end());
    const double median_mm = true_mm[true_mm.size() / 2];
    std::printf("cam %d: uncertainty at %.2f mm, the true poses' median %.2f mm\n", cam, r.report.uncertainty_range_mm,
                median_mm);
    EXPECT_NEAR(r.report.uncertainty_range_mm, median_mm, 0.5) << "cam " << cam;
    EXPECT_GT(median_mm, 150);  // the default scene holds the board ~200 mm away: not a degenerate 0
  }
  IntrinsicsOptions at_300;
  at_300.uncertainty_range_mm = 300;
  const auto r300 = CalibrateIntrinsics(0, s.data.input.cameras[0], s.data.input.target,
                                        testing::ViewsOf(s.data.input, 0), at_300, "test");
  EXPECT_EQ(r300.report.uncertainty_range_mm, 300);
}

// Stage 2 too (the report the rig file's uncertainties come from): each
// camera's range is its own median board distance, against the truth, as in
// stage 1. The right camera sits at its extrinsics from the left one; on
// this nearly symmetric rig its median happens to equal the left camera's
// (202.69 mm both), so this pins the values, not the frame they are taken
// in (the second reading checked that by hand: 215.34 against 215.33 mm).
TEST(Intrinsics, Stage2ReportsEachCamerasUncertaintyWhereTheBoardWasFromIt) {
  const auto s = testing::MakeDefaultScene(14, 12, 0.2);
  const CalibrationInput& in = s.data.input;
  const IntrinsicsOptions opt;
  const auto l = CalibrateIntrinsics(0, in.cameras[0], in.target, testing::ViewsOf(in, 0), opt, "test");
  const auto r = CalibrateIntrinsics(1, in.cameras[1], in.target, testing::ViewsOf(in, 1), opt, "test");
  const StereoResult st = CalibrateStereo(0, in.modules[0], l, r, testing::ViewsOf(in, 0), testing::ViewsOf(in, 1), in,
                                          StereoOptions(), opt);
  const Eigen::Vector3d centre(0.5 * (in.target.corners_x - 1) * in.target.square_size_mm,
                               0.5 * (in.target.corners_y - 1) * in.target.square_size_mm, 0);
  for (const int cam : {0, 1}) {
    std::vector<double> true_mm;
    for (const mrcal_observation_board_t& o : st.problem.observations) {
      if (o.icam.intrinsics != cam) continue;
      const Pose face_from_front = st.faces[o.iframe] == Face::kFront ? Pose::Identity() : s.true_back_from_front;
      const Pose cam_from_face =
          s.truth.rig.CamFromReference(cam) * s.data.ref_from_front[st.captures[o.iframe]] * face_from_front.Inverse();
      true_mm.push_back((cam_from_face * centre).norm());
    }
    ASSERT_FALSE(true_mm.empty());
    std::nth_element(true_mm.begin(), true_mm.begin() + true_mm.size() / 2, true_mm.end());
    const double median_mm = true_mm[true_mm.size() / 2];
    const IntrinsicsReport& report = cam == 0 ? st.report.left : st.report.right;
    std::printf("stage 2, cam %d: uncertainty at %.2f mm, the true poses' median %.2f mm\n", cam,
                report.uncertainty_range_mm, median_mm);
    EXPECT_NEAR(report.uncertainty_range_mm, median_mm, 0.5) << "cam " << cam;
  }
}

TEST(Intrinsics, LensModelsAreSelectable) {
  const auto s = testing::MakeDefaultScene(21, 20, 0.2);
  for (const std::string model :
       {"LENSMODEL_OPENCV5", "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=8_Ny=6_fov_x_deg=45"}) {
    IntrinsicsOptions opt;
    opt.lensmodel = model;
    const auto r = CalibrateIntrinsics(0, s.data.input.cameras[0], s.data.input.target,
                                       testing::ViewsOf(s.data.input, 0), opt, "test");
    EXPECT_EQ(r.camera.lensmodel_name(), model);
    // Both models can represent this mild OPENCV8 lens within noise here.
    EXPECT_NEAR(r.report.rms_px, 0.2, 0.03) << model;
  }
}

TEST(Intrinsics, RejectsAnOutlierCorner) {
  auto s = testing::MakeDefaultScene(31, 20, 0.2);
  // Move one corner by 8 px: a bad detection.
  for (auto& o : s.data.input.observations) {
    if (o.camera == 0) {
      o.q_px[3] += Eigen::Vector2d(8, -6);
      break;
    }
  }
  const auto r = CalibrateIntrinsics(0, s.data.input.cameras[0], s.data.input.target, testing::ViewsOf(s.data.input, 0),
                                     IntrinsicsOptions(), "test");
  EXPECT_GE(r.report.num_outliers, 1);
  EXPECT_NEAR(r.report.rms_px, 0.2, 0.02);
}

// A view whose corners mrcal's outlier rejection mostly throws out (a grazing
// view's corners misdetected) would keep a board pose that its few inliers do
// not determine: J'J singular, the projection uncertainty NaN (which the rig
// file's reader refuses; seen on a simulated three-module ring's grazing
// views). Such a view is dropped and the rest solved again.
TEST(Intrinsics, DropsAViewThatOutlierRejectionLeavesUndetermined) {
  auto s = testing::MakeDefaultScene(32, 20, 0.2);
  std::mt19937 rng(3);
  std::normal_distribution<double> bad(0.0, 6.0);
  int capture = -1;
  for (auto& o : s.data.input.observations) {
    if (o.camera != 0) continue;
    // All but two corners misdetected by several px.
    for (size_t i = 2; i < o.q_px.size(); ++i) o.q_px[i] += Eigen::Vector2d(bad(rng), bad(rng));
    capture = o.capture;
    break;
  }
  ASSERT_GE(capture, 0);
  const auto r = CalibrateIntrinsics(0, s.data.input.cameras[0], s.data.input.target, testing::ViewsOf(s.data.input, 0),
                                     IntrinsicsOptions(), "test");
  EXPECT_EQ(std::find(r.captures.begin(), r.captures.end(), capture), r.captures.end());
  EXPECT_EQ(r.report.num_views_dropped, 1);
  ASSERT_EQ(r.report.uncertainty.size(), 5u);
  for (const PixelUncertainty& u : r.report.uncertainty) {
    EXPECT_TRUE(std::isfinite(u.rms_stdev_px)) << u.where;
    EXPECT_LT(u.rms_stdev_px, 1.0) << u.where;  // 0.2 px noise: a few tenths at the image corners
  }
  for (double sigma : r.report.intrinsics_sigma) EXPECT_TRUE(std::isfinite(sigma));
  EXPECT_NEAR(r.report.rms_px, 0.2, 0.02);
}

// Refused from every seed, the first's refusal given. This set reaches the
// solved-pose check too (the 12032 px seed poses it 10.9 deg and solves to
// fx 0.23 px at rms 0.193 px): without it the test fails; the next test is
// the one built and checked to reach it.
TEST(Intrinsics, RefusesFrontoParallelViews) {
  auto s = testing::MakeDefaultScene(41, 20, 0.2);
  SyntheticOptions o;
  o.max_tilt_deg = 0.0;
  o.max_roll_deg = 20.0;
  s.data = MakeSyntheticCaptures(s.truth.rig, s.data.input.target, s.true_back_from_front, s.ref_from_volume, o);
  try {
    CalibrateIntrinsics(0, s.data.input.cameras[0], s.data.input.target, testing::ViewsOf(s.data.input, 0),
                        IntrinsicsOptions(), "test");
    FAIL() << "fronto-parallel views accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fronto-parallel"), std::string::npos) << e.what();
  }
}

// Stage 1 holds a later seed's SOLVED board poses to the tilt test as well
// (intrinsics.cc). The views are fronto-parallel in truth: the board flat in
// the default volume (170-230 mm from the rig, its centre up to 25 mm off
// the volume's axis, turned up to 20 deg about its normal), which camera 0,
// verged 3 deg, sees tilted 3.0 deg, under a third of min_tilt_deg (10 deg).
// The first seed poses them at most ~5 deg and is refused; the ladder's far
// focal lengths (8508 and 12032 px for the true 1025) pose them 10.1-10.9
// deg, past the test, so they are solved from, and fronto-parallel views fit
// a wrong focal length as well as the right one. Measured on the captures
// drawn with seeds 41 and 48, 0.2 px of noise: from 8508 px both solves end
// at a negative focal length (refused); from 12032 px 41's at fx 2599 px,
// rms 0.193 px, its poses back at 7.7 deg, and 48's at fx 0.07 px, rms
// 0.192 px, poses at 0.0 deg.
// Without the solved-pose check stage 1 returned those cameras.
// No threshold here follows from the noise, and that is the point: the
// wrong minima fit at the noise (rms 0.19-0.22 px at 0.2 px of noise,
// 0.48-0.52 px at 0.5 px, under 0.14 px without noise; captures 41-50), under
// max_rms_px (1 px) and the retry's limit, so no rms test refuses them; and
// the seed poses' tilts are the geometry's (without noise within 0.2 deg of
// these). Each set is checked to be that case, the first pinhole seed refused
// and a later one solved, so that a change of the seed ladder cannot leave this
// test passing without reaching the check.
TEST(Intrinsics, RefusesFrontoParallelViewsThatAFarSeedPosesTilted) {
  const double noise_px = 0.2;
  const int cam = 0;
  const IntrinsicsOptions options;
  for (const unsigned seed : {41u, 48u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const SyntheticOptions volume;  // the default depths, offsets and roll
    const testing::DefaultScene s = FlatBoardScene(seed, noise_px, volume.lateral_mm, volume.depth_mm);
    const TargetGeometry& target = s.data.input.target;
    const CameraImager& spec = s.data.input.cameras[cam];
    const auto [views, pinhole_seeds] = ViewsAndSeedsOf(s, cam, options);
    ASSERT_NO_FATAL_FAILURE(AssertFlatAndTheFirstSeedRefused(s, cam, views, pinhole_seeds, options));
    double later_seed_deg = 0;
    for (size_t c = 1; c < pinhole_seeds.size(); ++c)
      later_seed_deg = std::max(later_seed_deg, MaxSeedTiltDeg(views, target, pinhole_seeds[c]));
    ASSERT_GE(later_seed_deg, options.min_tilt_deg) << "no later seed is solved from: the check is not reached";

    try {
      const IntrinsicsResult r = CalibrateIntrinsics(cam, spec, target, views, options, "test");
      ADD_FAILURE() << "fronto-parallel views accepted: rms " << r.report.rms_px << " px, fx " << r.report.intrinsics[0]
                    << " px (truth " << s.truth.rig.camera(cam).intrinsics()[0] << ")";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("all " + std::to_string(views.size()) + " are fronto-parallel"),
                std::string::npos)
          << e.what();
    }
  }
}

// The same flat board over a wider volume: its centre up to 40 mm off the
// volume's axis and 60 mm along it (captures seed 43, 0.2 px of noise; camera
// 0 still sees it tilted 3.0 deg). Here the far seeds' solves passed the
// solved-pose tilt test: from 6016, 8508 and 12032 px all three ended at one
// minimum, fx 4617 +- 824 px (truth 1025), rms 0.192 px, its poses tilted
// 13.44 deg, and stage 1 returned that camera. Near fronto-parallel, the
// solved tilt grows with the solved focal length (tan(13.44) / tan(3.0) =
// 4617 / 1025), so the test is now held at the focal length 3 sigma lower:
// 6.3 deg (intrinsics.cc: SolvedTiltLowerBoundDeg). Of 20 such sets (seeds
// 40-59) this was the one the old test accepted at 0.2 px of noise, none at
// 0.5 px; the others' solves ended anywhere from fx 0.03 to 3000 px (poses
// at 0-8.7 deg), the noise and the seed deciding where along that valley
// (from the true 1025 px, tilt test off, it ended at 4617 px; from 1024.98
// px at a negative fx). Checked to be that case: from the far seed, tilt
// test off, the solve is wrong with poses tilted past min_tilt_deg.
TEST(Intrinsics, RefusesFlatViewsWhoseSolvedPosesTiltWithTheirFocalLength) {
  const double noise_px = 0.2;
  const int cam = 0;
  const IntrinsicsOptions options;
  const testing::DefaultScene s = FlatBoardScene(43, noise_px, 40.0, 60.0);
  const TargetGeometry& target = s.data.input.target;
  const CameraImager& spec = s.data.input.cameras[cam];
  const auto [views, pinhole_seeds] = ViewsAndSeedsOf(s, cam, options);
  ASSERT_NO_FATAL_FAILURE(AssertFlatAndTheFirstSeedRefused(s, cam, views, pinhole_seeds, options));

  const double true_fx_px = s.truth.rig.camera(cam).intrinsics()[0];
  IntrinsicsOptions from_far;
  for (const PinholeSeed& seed : pinhole_seeds)
    from_far.seed_focal_px = std::max(from_far.seed_focal_px, seed.focal_px);
  from_far.min_tilt_deg = 0;
  const IntrinsicsResult far = CalibrateIntrinsics(cam, spec, target, views, from_far, "test");
  ASSERT_GT(far.report.intrinsics[0], 2 * true_fx_px) << "the far seed's solve is not wrong: the case is not reached";
  ASSERT_GE(MaxTiltDeg(far.cam_from_face), options.min_tilt_deg) << "its poses fail the plain tilt test";

  try {
    const IntrinsicsResult r = CalibrateIntrinsics(cam, spec, target, views, options, "test");
    ADD_FAILURE() << "fronto-parallel views accepted: rms " << r.report.rms_px << " px, fx " << r.report.intrinsics[0]
                  << " px (truth " << true_fx_px << "), solved tilt " << MaxTiltDeg(r.cam_from_face) << " deg";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("all " + std::to_string(views.size()) + " are fronto-parallel"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("tilt the board"), std::string::npos) << e.what();
  }
}

TEST(Intrinsics, RefusesTooFewViews) {
  const auto s = testing::MakeDefaultScene(51, 3, 0.2);
  EXPECT_THROW(CalibrateIntrinsics(0, s.data.input.cameras[0], s.data.input.target, testing::ViewsOf(s.data.input, 0),
                                   IntrinsicsOptions(), "test"),
               InputError);
}

}  // namespace
}  // namespace stereorig

namespace stereorig {
namespace {

// A view whose corners lie on one board row or column has no pose (PnP on
// collinear points fails); such views are dropped before seeding.
TEST(Intrinsics, CollinearCornersDoNotSpanAPlane) {
  EXPECT_FALSE(CornersSpanAPlane({0, 1, 2, 3, 4, 5, 6, 7, 8}, 9));  // the first row of a 9-wide board
  EXPECT_FALSE(CornersSpanAPlane({4, 13, 22, 31, 40, 49, 58}, 9));  // one column
  EXPECT_TRUE(CornersSpanAPlane({0, 1, 2, 3, 4, 5, 6, 7, 17}, 9));  // one corner off the row
  EXPECT_FALSE(CornersSpanAPlane({}, 9));
}

}  // namespace
}  // namespace stereorig

namespace stereorig {
namespace {

// A copy of `view` as capture `capture`.
BoardObservation Renumbered(const BoardObservation& view, int capture) {
  BoardObservation copy = view;
  copy.capture = capture;
  return copy;
}

// Copies of one view (a trigger delivering one frame again) count as one
// board pose: eight copies of one capture calibrated, exit 0, with fx 7 %
// and the baseline 10.8 mm off, as if eight poses had been seen.
TEST(Intrinsics, RefusesCopiesOfOneViewAsTooFewDistinctPoses) {
  const auto s = testing::MakeDefaultScene(61, 20, 0.2);
  const std::vector<const BoardObservation*> views = testing::ViewsOf(s.data.input, 0);
  std::vector<BoardObservation> copies;
  for (int c = 0; c < 8; ++c) copies.push_back(Renumbered(*views[0], c));
  std::vector<const BoardObservation*> copy_views;
  for (const BoardObservation& v : copies) copy_views.push_back(&v);
  try {
    CalibrateIntrinsics(0, s.data.input.cameras[0], s.data.input.target, copy_views, IntrinsicsOptions(), "test");
    FAIL() << "eight copies of one view calibrated";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("camera 0 (" + s.data.input.cameras[0].name +
                        "): too few distinct board poses: its 8 usable "
                        "views show 1, need at least 5; repeated: captures 0, 1, 2, 3, 4, 5, 6 and 7"),
              std::string::npos)
        << what;
  }
}

// A board left still between two captures is seen again with fresh noise:
// two detections then differ by sqrt(2) x the noise per coordinate (0.28 px
// here), well within SamePoseRmsPx (1.41 px at the default max_rms_px). Each
// of 20 poses seen twice so: enough distinct poses to calibrate, and the
// report names the 20 pairs (calibrate warns of them); the scene alone
// repeats none.
TEST(Intrinsics, ReportsViewsThatRepeatAPoseWithFreshNoise) {
  const double noise_px = 0.2;
  const auto s = testing::MakeDefaultScene(62, 20, noise_px);
  const std::vector<const BoardObservation*> views = testing::ViewsOf(s.data.input, 0);
  ASSERT_GE(views.size(), 10u);
  const IntrinsicsOptions options;
  const auto alone = CalibrateIntrinsics(0, s.data.input.cameras[0], s.data.input.target, views, options, "test");
  EXPECT_TRUE(alone.report.repeated_pose_captures.empty());

  std::mt19937 rng(62);
  std::normal_distribution<double> again(0.0, std::sqrt(2.0) * noise_px);  // the difference of two detections
  std::vector<BoardObservation> twice;
  for (const BoardObservation* v : views) twice.push_back(*v);
  const int first_copy = 1000;
  for (const BoardObservation* v : views) {
    BoardObservation copy = Renumbered(*v, first_copy + v->capture);
    for (Eigen::Vector2d& q : copy.q_px) q += Eigen::Vector2d(again(rng), again(rng));
    twice.push_back(copy);
  }
  std::vector<const BoardObservation*> twice_views;
  for (const BoardObservation& v : twice) twice_views.push_back(&v);
  const auto r = CalibrateIntrinsics(0, s.data.input.cameras[0], s.data.input.target, twice_views, options, "test");
  ASSERT_EQ(r.report.repeated_pose_captures.size(), views.size());
  for (size_t k = 0; k < views.size(); ++k)
    EXPECT_EQ(r.report.repeated_pose_captures[k],
              (std::vector<int>{views[k]->capture, first_copy + views[k]->capture}));
}

// Noise-free copies moved by a known amount: a board moved by (d, d) px is
// another pose, however small d (nothing but noise may tell two views of
// one pose apart), and beyond the ceiling SamePoseRmsPx nothing is one pose.
TEST(Intrinsics, ViewsMovedAreAnotherPoseAndIdenticalOnesOne) {
  const auto s = testing::MakeDefaultScene(63, 2, 0.2);
  const BoardObservation& view = *testing::ViewsOf(s.data.input, 0)[0];
  const int corners_x = s.data.input.target.corners_x;
  const double threshold_px = SamePoseRmsPx(1.0);
  EXPECT_DOUBLE_EQ(threshold_px, std::sqrt(2.0));
  auto moved = [&](double d_px) {
    BoardObservation copy = Renumbered(view, 1);
    for (Eigen::Vector2d& q : copy.q_px) q += Eigen::Vector2d(d_px, d_px);
    return copy;
  };
  const BoardObservation same = moved(0.0), near = moved(0.1), far = moved(1.1 * threshold_px);
  EXPECT_EQ(BoardPoseGroups({&view, &same}, corners_x, threshold_px).size(), 1u);
  EXPECT_EQ(BoardPoseGroups({&view, &near}, corners_x, threshold_px).size(), 2u);
  EXPECT_EQ(BoardPoseGroups({&view, &far}, corners_x, threshold_px).size(), 2u);
  // The other face at the same pixels is another pose.
  BoardObservation back = Renumbered(view, 2);
  back.face = view.face == Face::kFront ? Face::kBack : Face::kFront;
  EXPECT_EQ(BoardPoseGroups({&view, &back}, corners_x, threshold_px).size(), 2u);
}

// The demo board (11 x 9 inner corners, 9 mm squares) seen by a 1025 px
// pinhole at `distance_mm`, turned `tilt_deg` about its vertical axis, each
// corner's coordinates with Gaussian noise of `noise_px`.
BoardObservation TiltedDemoBoard(double distance_mm, double tilt_deg, double noise_px, std::mt19937* rng, int capture) {
  constexpr int kCornersX = 11, kCornersY = 9;
  constexpr double kSquareMm = 9.0, kFocalPx = 1025.0;
  const Eigen::Vector2d centre_px(640.0, 400.0);
  std::normal_distribution<double> noise(0.0, noise_px);
  const double t = tilt_deg * M_PI / 180.0;
  BoardObservation o{capture, 0, Face::kFront, {}, {}};
  for (int j = 0; j < kCornersY; ++j)
    for (int i = 0; i < kCornersX; ++i) {
      const double x = (i - (kCornersX - 1) / 2.0) * kSquareMm, y = (j - (kCornersY - 1) / 2.0) * kSquareMm;
      const Eigen::Vector3d p(x * std::cos(t), y, distance_mm + x * std::sin(t));
      o.corner_ids.push_back(j * kCornersX + i);
      o.q_px.push_back(centre_px + kFocalPx * p.head<2>() / p.z() + Eigen::Vector2d(noise(*rng), noise(*rng)));
    }
  return o;
}

// The same-pose test held the corners to a fixed 1.41 px RMS (sqrt(2) x
// --max-rms-px): the demo board tilted +34 and -34 deg at 800 mm (corners
// 1.4 px RMS apart) read as one pose, and a set of mirrored tilts, the
// views that pin the focal length, was refused as too few distinct poses.
// Now only noise may tell two views of one pose apart: tilts of +-5, 16
// and 34 deg at 800 mm are two poses under 0.03 px corner noise (the
// detector's on rendered images; +-5 deg puts them 0.2 px apart, 5x the
// 0.04 px of two detections), +-34 deg under 0.2 px too (1.4 px against
// 0.28). A pose seen twice with fresh noise is one, at either noise, 50
// times each: the whole difference then reads ~1x the noise left after
// its smooth part (at most ~1.06x at 99.9 % for 99 corners), against the
// 1.5x allowed.
TEST(Intrinsics, MirroredTiltsOfASmallBoardAreTwoPosesAndRepeatsOne) {
  constexpr int kCornersX = 11;
  const double ceiling_px = SamePoseRmsPx(IntrinsicsOptions().max_rms_px);
  std::mt19937 rng(64);
  for (const double noise_px : {0.03, 0.2}) {
    for (const double tilt_deg : {5.0, 16.0, 34.0}) {
      if (noise_px > 0.1 && tilt_deg < 30) continue;  // below what that noise can tell
      const BoardObservation plus = TiltedDemoBoard(800, tilt_deg, noise_px, &rng, 0);
      const BoardObservation minus = TiltedDemoBoard(800, -tilt_deg, noise_px, &rng, 1);
      EXPECT_EQ(BoardPoseGroups({&plus, &minus}, kCornersX, ceiling_px).size(), 2u)
          << "+-" << tilt_deg << " deg, noise " << noise_px << " px";
    }
    for (int k = 0; k < 50; ++k) {
      const double tilt_deg = -40.0 + 2.0 * k * 40.0 / 49.0;
      const BoardObservation first = TiltedDemoBoard(800, tilt_deg, noise_px, &rng, 0);
      const BoardObservation again = TiltedDemoBoard(800, tilt_deg, noise_px, &rng, 1);
      EXPECT_EQ(BoardPoseGroups({&first, &again}, kCornersX, ceiling_px).size(), 1u)
          << tilt_deg << " deg, noise " << noise_px << " px";
    }
  }
}

}  // namespace
}  // namespace stereorig
