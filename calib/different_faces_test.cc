// A module whose two cameras see different faces of the double-sided target in
// one capture: the board nearly edge-on to the module, its plane passing
// between the two cameras. Not bad input: the rig is calibrated, the capture
// is set aside for that module's stages 2 and 3 (one board pose per capture
// there, and a face misread by the detector would look the same) and counted
// in the report. Synthetic corners of the default rig, 0.2 px noise.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>

#include "calib/calib_test_util.h"
#include "calib/calibrate.h"

namespace stereorig {
namespace {

constexpr double kNoisePx = 0.2;
constexpr int kCaptures = 20;

// The default scene plus one capture whose board plane holds the midpoint of
// module 0's cameras and the volume's centre (and the reference's y axis): the
// left camera sees one face, the right camera the other, each at about 13 deg
// from the board's plane.
testing::DefaultScene SceneWithAnEdgeOnCapture(unsigned seed) {
  testing::DefaultScene s = testing::MakeDefaultScene(seed, kCaptures, kNoisePx);
  const Rig& rig = s.truth.rig;
  const TargetGeometry& target = s.data.input.target;
  const Eigen::Vector3d c_left = rig.CamFromReference(rig.module(0).left_camera).Inverse().translation_mm();
  const Eigen::Vector3d c_right = rig.CamFromReference(rig.module(0).right_camera).Inverse().translation_mm();
  const Eigen::Vector3d centre = s.ref_from_volume.translation_mm();
  const Eigen::Vector3d x = (centre - 0.5 * (c_left + c_right)).normalized();
  const Eigen::Vector3d y = (Eigen::Vector3d::UnitY() - x * x.y()).normalized();
  Eigen::Matrix3d R;
  R << x, y, x.cross(y);
  const double sq = target.square_size_mm;
  const Eigen::Vector3d board_centre(0.5 * (target.corners_x - 1) * sq, 0.5 * (target.corners_y - 1) * sq, 0);
  std::vector<Pose> ref_from_front = s.data.ref_from_front;
  ref_from_front.push_back(Pose(R, centre - R * board_centre));
  SyntheticOptions o;
  o.seed = seed;
  o.noise_px = kNoisePx;
  const Pose front_from_back = s.true_back_from_front.Inverse();
  s.data = ObserveBoards(
      rig, target, ref_from_front,
      [&](Face face, int id) {
        const Eigen::Vector3d p = target.CornerInFace(id);
        return face == Face::kFront ? p : front_from_back * p;
      },
      o);
  return s;
}

const BoardObservation* Find(const CalibrationInput& in, int capture, int camera) {
  for (const BoardObservation& o : in.observations)
    if (o.capture == capture && o.camera == camera) return &o;
  return nullptr;
}

// Module 0's 3D error and the modules' agreement through S, against the truth.
void ExpectAccurate(const testing::DefaultScene& s, const CalibrationResult& r) {
  const auto points = VolumePoints(s.ref_from_volume, Eigen::Vector3d(75, 75, 50), 500, 5);
  for (int k = 0; k < 2; ++k) {
    std::vector<Eigen::Vector3d> pc, pt;
    testing::TriangulateThroughModule(s.truth.rig, r.rig, k, points, &pc, &pt);
    ASSERT_GT(pc.size(), 100u);
    EXPECT_LT(testing::RigidAlignedRms(pt, pc), 0.05) << "module " << k;
  }
  EXPECT_LT(testing::ModuleAgreementRms(s.truth.rig, r.rig, r.rig.S(0, 1), 0, 1, points), 0.05);
}

TEST(CalibrateDifferentFaces, AModuleWhoseCamerasSawDifferentFacesIsCalibratedAndTheCaptureSetAside) {
  const testing::DefaultScene s = SceneWithAnEdgeOnCapture(5);
  const CalibrationInput& in = s.data.input;
  const int edge_on = kCaptures;  // the capture added last
  const BoardObservation* l = Find(in, edge_on, 0);
  const BoardObservation* r = Find(in, edge_on, 1);
  ASSERT_TRUE(l && r) << "both cameras of module 0 must see the edge-on board";
  ASSERT_NE(l->face, r->face);
  ASSERT_GE(l->corner_ids.size(), 20u);
  ASSERT_GE(r->corner_ids.size(), 20u);
  // The truth's geometry: the edge-on capture is the only one whose board
  // plane passes between module 0's cameras.
  ASSERT_EQ(testing::CapturesWhoseBoardPlaneSeparates(s.truth.rig, s.data.ref_from_front, in, 0, 1),
            std::vector<int>{edge_on});

  const CalibrationResult res = Calibrate(in, CalibrationOptions());
  // Stage 1 used both views as they are.
  for (int cam : {0, 1}) {
    const std::vector<int>& used = res.stage1[cam].captures;
    EXPECT_NE(std::find(used.begin(), used.end(), edge_on), used.end()) << "camera " << cam;
  }
  // Stage 2 set the capture aside: not a shared view, not a frame of the joint solve.
  const StereoReport& st = res.report.stereo[0];
  EXPECT_EQ(st.different_face_captures, std::vector<int>{edge_on});
  const std::vector<int>& frames = res.stage2[0].captures;
  EXPECT_EQ(std::find(frames.begin(), frames.end(), edge_on), frames.end());
  int shared = 0;
  for (int c = 0; c < kCaptures; ++c) shared += Find(in, c, 0) && Find(in, c, 1);
  EXPECT_EQ(st.num_shared_views, shared);
  // ... and the report says so, per module.
  const nlohmann::json json = nlohmann::json::parse(res.report.ToJson());
  EXPECT_EQ(json["stage2_stereo"][0]["different_face_captures"], nlohmann::json::array({edge_on}));
  // Module 1 faces module 0: the same plane may pass between its cameras
  // too; what the truth's geometry says, the report lists.
  EXPECT_EQ(json["stage2_stereo"][1]["different_face_captures"],
            nlohmann::json(testing::CapturesWhoseBoardPlaneSeparates(s.truth.rig, s.data.ref_from_front, in, 2, 3)));
  EXPECT_NE(SummaryText(res.report).find("1 capture(s) set aside in stage 2 and 3"), std::string::npos);
  ExpectAccurate(s, res);
}

// A face misread by the detector in one camera (corners right, face wrong)
// looks like the edge-on case: set aside for stages 2 and 3, it does not
// reach back_from_front, right_from_left or S.
TEST(CalibrateDifferentFaces, AFaceMisreadInOneCameraDoesNotPoisonTheSolve) {
  testing::DefaultScene s = testing::MakeDefaultScene(6, kCaptures, kNoisePx);
  int misread = -1;
  for (BoardObservation& o : s.data.input.observations) {
    if (o.camera == 3 && Find(s.data.input, o.capture, 2)) {
      o.face = o.face == Face::kFront ? Face::kBack : Face::kFront;
      misread = o.capture;
      break;
    }
  }
  ASSERT_GE(misread, 0);
  const CalibrationResult res = Calibrate(s.data.input, CalibrationOptions());
  EXPECT_TRUE(res.report.stereo[0].different_face_captures.empty());
  EXPECT_EQ(res.report.stereo[1].different_face_captures, std::vector<int>{misread});
  ExpectAccurate(s, res);
}

// A view stage 1 dropped (here cut to 5 corners, under the 8 a view needs)
// still says which face its camera saw: its partner's view of the capture,
// misread, is set aside with it, in stage 2 and stage 3. Counting only the
// views stage 1 kept would let the misread face into stage 3, checked by
// nothing (the module poses no board there).
TEST(CalibrateDifferentFaces, AViewStageOneDroppedStillSetsItsCaptureAside) {
  testing::DefaultScene s = testing::MakeDefaultScene(6, kCaptures, kNoisePx);
  CalibrationInput& in = s.data.input;
  int misread = -1;
  for (BoardObservation& o : in.observations) {
    if (o.camera == 3 && Find(in, o.capture, 2) && Find(in, o.capture, 0) && Find(in, o.capture, 1)) {
      o.face = o.face == Face::kFront ? Face::kBack : Face::kFront;
      misread = o.capture;
      break;
    }
  }
  ASSERT_GE(misread, 0);
  for (BoardObservation& o : in.observations) {
    if (o.capture == misread && o.camera == 2) {
      o.corner_ids.resize(5);
      o.q_px.resize(5);
    }
  }
  const CalibrationResult res = Calibrate(in, CalibrationOptions());
  const std::vector<int>& used = res.stage1[2].captures;
  ASSERT_EQ(std::find(used.begin(), used.end(), misread), used.end()) << "stage 1 must drop camera 2's view";
  EXPECT_EQ(res.report.stereo[1].different_face_captures, std::vector<int>{misread});
  const std::vector<int>& frames = res.stage2[1].captures;
  EXPECT_EQ(std::find(frames.begin(), frames.end(), misread), frames.end());
  ExpectAccurate(s, res);
}

}  // namespace
}  // namespace stereorig
