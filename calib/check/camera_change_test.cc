// ExplainCameraChange on synthetic corners: the default rig's camera 0 sees
// the target's front face in eight poses 170 to 230 mm away, tilted, through
// its lens after a change (a new pose, a new lens, both, its distortion).
// The board poses are the true ones, as the other cameras would give them.
//
// Corner noise 0.03 px per axis, Gaussian (a calibrated rig's rendered
// corners, docs/verify-and-check.md). Threshold 0.036 px = 1.2 sigma: a fit
// of the right model leaves residuals whose per-axis RMS is sigma within
// 1/sqrt(4N) of itself (N = 792 corners: 1.8 %), so it passes by 11 of its
// standard errors; a fit of the wrong model fails once its misfit adds
// sqrt(1.2^2 - 1) = 0.66 sigma (0.02 px) in quadrature to the noise, and the
// wrong fits below leave 0.075 to 0.24 px (measured: each test prints both
// fits).
#include "calib/check/camera_change.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "calib/check/shared_lens_change.h"
#include "calib/core/lens_drift.h"
#include "datasets/default_rig.h"

namespace stereorig {
namespace {

constexpr double kNoisePx = 0.03;
constexpr double kThresholdPx = 1.2 * kNoisePx;
constexpr int kCamera = 0;

struct Change {
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();  // camera-frame rotation vector of new_from_old
  LensDrift lens;                                          // its focal length and principal point
  double k1_change = 0;                                    // added to its first radial distortion coefficient
};

// The camera's views after `change`, each with its true board pose.
struct Scene {
  std::vector<BoardObservation> views;
  std::vector<Pose> ref_from_front;
  std::vector<PosedView> Posed() const {
    std::vector<PosedView> posed;
    for (size_t i = 0; i < views.size(); ++i) posed.push_back({&views[i], ref_from_front[i]});
    return posed;
  }
};

Scene Observe(const Rig& rig, const Target& target, const Change& change) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, kNoisePx);
  std::vector<double> intrinsics = WithLensDrift(rig.camera(kCamera), change.lens).intrinsics();
  intrinsics[4] += change.k1_change;  // OPENCV8: fx fy cx cy k1 ...
  const Camera& stored = rig.camera(kCamera);
  const Camera seen(stored.lensmodel_name(), intrinsics, stored.imager_width_px(), stored.imager_height_px());
  const Pose cam_from_ref = rig.CamFromReference(kCamera);
  const Pose new_from_old = Pose::FromRotationVector(change.rotation_deg * M_PI / 180, Eigen::Vector3d::Zero());
  const Eigen::Vector3d center((target.corners_x() - 1) * 0.5 * target.square_size_mm(),
                               (target.corners_y() - 1) * 0.5 * target.square_size_mm(), 0);
  Scene scene;
  for (int k = 0; k < 8; ++k) {
    // Depths 170..230 mm (a focal change is no shift along the axis),
    // tilted by up to 0.35 rad about alternating axes.
    const double tilt = 0.35 * ((k % 3) - 1);
    const Pose cam_from_front =
        Pose::FromRotationVector(Eigen::Vector3d(k % 2 ? tilt : 0, k % 2 ? 0 : tilt, 0.1 * k),
                                 Eigen::Vector3d(5.0 * (k % 3 - 1), 4.0 * (k % 2), 170 + 60.0 * k / 7)) *
        Pose(Eigen::Matrix3d::Identity(), -center);
    BoardObservation view{k, kCamera, Face::kFront, {}, {}};
    for (int id = 0; id < target.num_corners(); ++id) {
      const Eigen::Vector3d p = new_from_old * (cam_from_front * target.CornerInFace(id));
      const Eigen::Vector2d q = seen.Project(p) + Eigen::Vector2d(noise(rng), noise(rng));
      if (q.x() < 0 || q.y() < 0 || q.x() > seen.imager_width_px() - 1 || q.y() > seen.imager_height_px() - 1) continue;
      view.corner_ids.push_back(id);
      view.q_px.push_back(q);
    }
    scene.views.push_back(view);
    scene.ref_from_front.push_back(cam_from_ref.Inverse() * cam_from_front);
  }
  return scene;
}

CameraChange Explain(const Change& change) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Scene scene = Observe(truth.rig, target, change);
  const CameraChange explained = ExplainCameraChange(truth.rig, target, kCamera, scene.Posed(), kThresholdPx);
  std::printf("%s: %d corners, pose fit %.4f px, lens fit %.4f px\n", explained.Describe().c_str(), explained.corners,
              explained.moved_rms_px, explained.lens_rms_px);
  return explained;
}

// A turn about the optical axis: no focal length or principal point mimics it.
TEST(CameraChange, ATurnAboutTheAxisIsAMotion) {
  Change change;
  change.rotation_deg = {0, 0, 0.1};
  const CameraChange c = Explain(change);
  EXPECT_EQ(c.kind, CameraChangeKind::kMoved);
  // The pose fit's motion: the turn about the camera's own centre. At
  // 0.03 px on 792 corners ~1000 px focal length its standard error is
  // ~0.03 / (1000 sqrt(792)) rad, 6e-5 deg, and the centre's ~200 mm times
  // that over the turn/shift correlation, a few um: bounds of 0.001 deg and
  // 0.01 mm.
  EXPECT_NEAR(c.turned_deg, 0.1, 0.001);
  EXPECT_NEAR(c.shifted_mm, 0.0, 0.01);
  char expected[128];
  std::snprintf(expected, sizeof expected, "camera 0 moved: turned %.3f deg, shifted %.3f mm [module 0's left camera]",
                c.turned_deg, c.shifted_mm);
  EXPECT_EQ(c.Describe(), expected);
  EXPECT_STREQ(CameraChangeKindName(c.kind), "moved");
}

// A focal change with the boards at several depths: no pose mimics it.
TEST(CameraChange, AFocalDriftSeenAtSeveralDepthsIsALensChange) {
  Change change;
  change.lens.focal_percent = 0.5;
  const CameraChange c = Explain(change);
  EXPECT_EQ(c.kind, CameraChangeKind::kLens);
  // Its standard error sigma / sqrt(sum |q - c|^2) is 0.0005 % (792
  // corners ~200 px from the centre): within 6 of them.
  EXPECT_NEAR(c.focal_percent, 0.5, 0.003);
  EXPECT_STREQ(CameraChangeKindName(c.kind), "lens");
}

// A principal point moved 0.2 px is, to first order, a turn of 0.2 / 1024
// rad: both fits explain the corners, and the check says it cannot tell.
TEST(CameraChange, APrincipalPointShiftIsAMotionOrALensChange) {
  Change change;
  change.lens.principal_point_px = {0.2, 0};
  const CameraChange c = Explain(change);
  EXPECT_EQ(c.kind, CameraChangeKind::kMovedOrLens);
  // Both fits' sizes said: the turn 0.2 / 1024 rad (0.0112 deg; the
  // lever of the board's depth adds a shift), or the shift itself, each
  // read within ~0.001 of its unit through 0.03 px noise on 792 corners.
  EXPECT_EQ(c.Describe().rfind("camera 0 moved or its lens changed (either explains its corners): turned 0.01", 0), 0u)
      << c.Describe();
  EXPECT_NEAR(c.turned_deg, 0.0112, 0.002);
  EXPECT_NE(c.Describe().find(" %, principal point +0.20, +0.00 px [module 0's left camera]"), std::string::npos)
      << c.Describe();
  EXPECT_NEAR(c.focal_percent, 0, 0.003);
  EXPECT_STREQ(CameraChangeKindName(c.kind), "moved_or_lens");
}

// Neither fit explains a camera that turned AND whose lens changed, nor one
// whose distortion changed: the check says so, not "moved or its lens
// changed", which claims that one of them alone would explain it.
TEST(CameraChange, NeitherAloneIsSaidSoWhenItMovedAndItsLensChanged) {
  Change change;
  change.rotation_deg = {0, 0, 0.1};
  change.lens.focal_percent = 0.5;
  const CameraChange c = Explain(change);
  EXPECT_EQ(c.kind, CameraChangeKind::kUnexplained);
  EXPECT_GT(c.moved_rms_px, kThresholdPx);
  EXPECT_GT(c.lens_rms_px, kThresholdPx);
  char expected[256];
  std::snprintf(expected, sizeof expected,
                "camera 0 changed: neither a new pose nor a new lens alone explains its corners (residual %.3f px "
                "with a new pose, %.3f px with a new lens, against 0.036 px) [module 0's left camera]",
                c.moved_rms_px, c.lens_rms_px);
  EXPECT_EQ(c.Describe(), expected);
  EXPECT_STREQ(CameraChangeKindName(c.kind), "unexplained");
}

TEST(CameraChange, NeitherAloneIsSaidSoWhenItsDistortionChanged) {
  Change change;
  change.k1_change = 0.02;
  const CameraChange c = Explain(change);
  EXPECT_EQ(c.kind, CameraChangeKind::kUnexplained);
  EXPECT_NE(c.Describe().find("neither a new pose nor a new lens alone explains its corners"), std::string::npos);
}

// Too few corners to fit: no fit (NaN, null in the report), and the words
// say only that the camera changed, not how.
TEST(CameraChange, TooFewCornersAreNotFitted) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  Scene scene = Observe(truth.rig, target, Change());
  scene.views.resize(1);
  scene.views[0].corner_ids.resize(kMinCornersToFit - 1);
  scene.views[0].q_px.resize(kMinCornersToFit - 1);
  const CameraChange c = ExplainCameraChange(truth.rig, target, kCamera, scene.Posed(), kThresholdPx);
  EXPECT_EQ(c.kind, CameraChangeKind::kNotFitted);
  EXPECT_EQ(c.corners, kMinCornersToFit - 1);
  EXPECT_TRUE(std::isnan(c.moved_rms_px));
  EXPECT_TRUE(std::isnan(c.lens_rms_px));
  EXPECT_EQ(c.Describe(),
            "camera 0 changed: too few corners (5) to fit a new pose or a new lens [module 0's left camera]");
  EXPECT_TRUE(std::isnan(c.turned_deg));  // no fit, no motion
  EXPECT_STREQ(CameraChangeKindName(c.kind), "not_fitted");
}

// A shared change's principal point printed as +0.01 px reads as a turn of
// a few ten-thousandths of a degree: the line said "or every camera turned
// alike by 0.000 deg". The turn is said only where it shows at the
// precision printed.
TEST(SharedLensChange, ATurnThatPrintsAsZeroIsNotSaid) {
  SharedLensChange shared;
  shared.fitted = true;
  shared.focal_percent = 0.1;
  shared.principal_point_px = {0.01, 0};
  shared.turn_equivalent_deg = 0.0004;  // 0.01 px over a focal length of ~1000 px
  EXPECT_EQ(shared.Describe(),
            "every camera's lens changed alike: focal length +0.100 %, principal point +0.01, +0.00 px");
  shared.principal_point_px = {0.5, 0};
  shared.turn_equivalent_deg = 0.028;
  EXPECT_EQ(shared.Describe(),
            "every camera's lens changed alike: focal length +0.100 %, principal point +0.50, +0.00 px, or every "
            "camera turned alike by 0.028 deg, as which that shift reads");
}

}  // namespace
}  // namespace stereorig
