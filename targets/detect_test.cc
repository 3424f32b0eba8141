// Detection against ground truth: every image here is rendered by
// synthetic_view.h (an ideal pinhole ray-cast onto Target::IsBlack, 4x4
// samples per pixel, Gaussian blur 0.7 px, 8-bit rounding, no noise unless a
// test says so), and every detected corner is compared with the TRUE
// projection of Target::CornerInFace(id) for the id the detector gave it. A
// wrong id is off by at least one square (> 25 px here), so the accuracy
// bounds also prove every id right.
#include "targets/detect.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <random>

#include "targets/synthetic_view.h"

namespace stereorig {
namespace {

struct Errors {
  double rms_px = 0;
  double max_px = 0;
};

Errors CompareWithTruth(const Target& target, const FaceDetection& det, const PinholeCamera& camera,
                        const Pose& cam_from_face) {
  Errors e;
  for (size_t i = 0; i < det.corner_ids.size(); ++i) {
    const Eigen::Vector2d truth = camera.Project(cam_from_face * target.CornerInFace(det.corner_ids[i]));
    const double d = (det.q_px[i] - truth).norm();
    e.rms_px += d * d;
    e.max_px = std::max(e.max_px, d);
  }
  e.rms_px = std::sqrt(e.rms_px / std::max<size_t>(1, det.corner_ids.size()));
  return e;
}

// Corners whose true projection lies at least `margin_px` inside the image.
int VisibleCorners(const Target& target, const PinholeCamera& camera, const Pose& cam_from_face, double margin_px) {
  int n = 0;
  for (int id = 0; id < target.num_corners(); ++id) {
    const Eigen::Vector2d q = camera.Project(cam_from_face * target.CornerInFace(id));
    if (q.x() >= margin_px && q.y() >= margin_px && q.x() <= camera.width_px - 1 - margin_px &&
        q.y() <= camera.height_px - 1 - margin_px) {
      ++n;
    }
  }
  return n;
}

// Corners the detector can refine: at least a quarter of the local corner
// spacing plus 3 px inside the image (ChessboardGridOptions::
// refine_min_window_fraction, and cornerSubPix's 2 px border).
int RefinableCorners(const Target& target, const PinholeCamera& camera, const Pose& cam_from_face) {
  int n = 0;
  const double s = target.square_size_mm();
  for (int id = 0; id < target.num_corners(); ++id) {
    const Eigen::Vector3d p = target.CornerInFace(id);
    const Eigen::Vector2d q = camera.Project(cam_from_face * p);
    const double spacing = std::min((camera.Project(cam_from_face * (p + Eigen::Vector3d(s, 0, 0))) - q).norm(),
                                    (camera.Project(cam_from_face * (p + Eigen::Vector3d(0, s, 0))) - q).norm());
    const double margin_px = 0.25 * spacing + 3;
    if (q.x() >= margin_px && q.y() >= margin_px && q.x() <= camera.width_px - 1 - margin_px &&
        q.y() <= camera.height_px - 1 - margin_px) {
      ++n;
    }
  }
  return n;
}

// Tags whose four corners' true projections lie at least `margin_px` inside.
int VisibleTags(const Target& target, Face face, const PinholeCamera& camera, const Pose& cam_from_face,
                double margin_px) {
  int n = 0;
  for (const TagPlacement& tag : target.layout().faces[static_cast<int>(face)].tags) {
    bool inside = true;
    for (const Eigen::Vector2d& c : TagCornersInFace(target, tag)) {
      const Eigen::Vector2d q = camera.Project(cam_from_face * Eigen::Vector3d(c.x(), c.y(), 0));
      inside = inside && q.x() >= margin_px && q.y() >= margin_px && q.x() <= camera.width_px - 1 - margin_px &&
               q.y() <= camera.height_px - 1 - margin_px;
    }
    n += inside;
  }
  return n;
}

DetectOptions WithOpenCvGrid() {
  DetectOptions o;
  o.opencv_whole_board = true;
  return o;
}

class DefaultTargetDetection : public ::testing::Test {
 protected:
  const Target target_ = DefaultTarget();
  const PinholeCamera camera_;
  TargetDetector detector_{target_, DetectOptions()};

  // Renders `face` at `cam_from_face`, detects, and checks face, ids and
  // accuracy. Returns the detection.
  FaceDetection DetectAndCheck(Face face, const Pose& cam_from_face, double max_rms_px, double max_err_px) {
    const cv::Mat img = RenderFace(target_, face, camera_, cam_from_face);
    const DetectResult r = detector_.Detect(img);
    EXPECT_EQ(r.reason, RejectReason::kNone) << r.message;
    if (r.faces.size() != 1) {
      ADD_FAILURE() << "no detection";
      return {};
    }
    const FaceDetection& det = r.faces[0];
    EXPECT_EQ(det.face, face);
    const Errors e = CompareWithTruth(target_, det, camera_, cam_from_face);
    EXPECT_LT(e.rms_px, max_rms_px);
    EXPECT_LT(e.max_px, max_err_px);
    EXPECT_TRUE(std::is_sorted(det.corner_ids.begin(), det.corner_ids.end()));
    return det;
  }
};

// libapriltag's corner order and pixel convention, as TagDetector converts
// them, against the true projection of TagCornersInFace().
TEST_F(DefaultTargetDetection, TagCornersSitAtTheirTrueProjection) {
  const Pose cam_from_face = LookAtFace(target_, 280, 15, -20, 30);
  const cv::Mat img = RenderFace(target_, Face::kFront, camera_, cam_from_face);
  const std::vector<TagDetection> tags = TagDetector(target_, {}).Detect(img);
  ASSERT_EQ(VisibleTags(target_, Face::kFront, camera_, cam_from_face, 2), 8);
  ASSERT_EQ(tags.size(), 8u);
  Eigen::Vector2d mean(0, 0);
  for (const TagDetection& t : tags) {
    EXPECT_EQ(t.face, Face::kFront);
    const auto corners = TagCornersInFace(target_, *target_.FindTag(Face::kFront, t.id));
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d truth = camera_.Project(cam_from_face * Eigen::Vector3d(corners[k].x(), corners[k].y(), 0));
      // Tag corners come from fitted edges: a few tenths of a px; a wrong
      // order would be off by a whole tag (~50 px).
      EXPECT_LT((t.q_px[k] - truth).norm(), 0.5) << "tag " << t.id << " corner " << k;
      mean += (t.q_px[k] - truth) / (4.0 * tags.size());
    }
  }
  // No half-pixel convention shift left over.
  EXPECT_LT(mean.norm(), 0.1);
}

// Noise off: RMS < 0.05 px against the truth over a spread of tilts and
// in-plane turns (whole boards), every visible corner and tag found, ids
// right. Measured with these views: 0.03-0.05 px per view; views whose
// edges run nearly along the pixel rows are the worst (aliasing of a 0.6 px
// blur), hence the per-view bound of 0.07 px.
// Both corner sources: grown from the tags (the default) and OpenCV's grid.
void FrontFaceAccuracy(const Target& target, const PinholeCamera& camera, const DetectOptions& options,
                       CornerSource expected_source, int num_poses) {
  const double poses[][4] = {{260, 20, -25, 10},   {280, -30, 15, -40}, {300, 10, 35, 75},
                             {250, -15, -10, 200}, {290, 30, 25, 140},  {270, -5, -30, -110}};
  const TargetDetector detector(target, options);
  double sum_sq = 0;
  int n = 0;
  for (int i = 0; i < num_poses; ++i) {
    const double* p = poses[i];
    SCOPED_TRACE(::testing::Message() << "pose " << p[0] << " " << p[1] << " " << p[2] << " " << p[3]);
    const Pose cam_from_face = LookAtFace(target, p[0], p[1], p[2], p[3]);
    const DetectResult r = detector.Detect(RenderFace(target, Face::kFront, camera, cam_from_face));
    ASSERT_EQ(r.faces.size(), 1u) << r.message;
    const FaceDetection& det = r.faces[0];
    EXPECT_EQ(det.face, Face::kFront);
    EXPECT_EQ(det.quality.source, expected_source);
    EXPECT_EQ(det.quality.num_corners, 99);
    EXPECT_EQ(det.quality.num_tags, VisibleTags(target, Face::kFront, camera, cam_from_face, 2));
    // The local 8-neighbour homography sees only the (tiny) corner error.
    EXPECT_LT(det.quality.local_fit_rms_px, 0.1);
    EXPECT_GT(det.quality.local_fit_count, 50);
    EXPECT_GT(det.quality.sharpness.edge_rise_px, 1.0);  // 0.6-0.7 px blur: a ~2.3 px 10-90% rise
    EXPECT_LT(det.quality.sharpness.edge_rise_px, 3.5);
    const Errors e = CompareWithTruth(target, det, camera, cam_from_face);
    EXPECT_LT(e.rms_px, 0.07);
    EXPECT_LT(e.max_px, 0.2);
    sum_sq += e.rms_px * e.rms_px * det.corner_ids.size();
    n += static_cast<int>(det.corner_ids.size());
  }
  const double rms_px = std::sqrt(sum_sq / std::max(n, 1));
  std::printf("front face, %s: RMS %.4f px over %d corners (noise off)\n", CornerSourceName(expected_source), rms_px,
              n);
  EXPECT_LT(rms_px, 0.05);
}

TEST_F(DefaultTargetDetection, FrontFaceCornersAtTheirTrueProjection) {
  FrontFaceAccuracy(target_, camera_, DetectOptions(), CornerSource::kTagGuided, 6);
}

TEST_F(DefaultTargetDetection, FrontFaceCornersAtTheirTrueProjectionThroughOpenCvsGrid) {
  FrontFaceAccuracy(target_, camera_, WithOpenCvGrid(), CornerSource::kOpenCvGrid, 4);
}

TEST_F(DefaultTargetDetection, UpsideDownAndQuarterTurnedViewsGetTheRightIds) {
  for (double rz : {180.0, 90.0, -90.0}) {
    SCOPED_TRACE(::testing::Message() << "rz " << rz);
    const Pose cam_from_face = LookAtFace(target_, 280, 12, -18, rz + 7);
    const FaceDetection det = DetectAndCheck(Face::kFront, cam_from_face, 0.05, 0.2);
    EXPECT_EQ(det.quality.num_corners, RefinableCorners(target_, camera_, cam_from_face));
  }
}

TEST_F(DefaultTargetDetection, BackFaceIdsAreInTheBackFacesOwnFrame) {
  const Pose cam_from_back = LookAtFace(target_, 260, -20, 20, 160);
  const FaceDetection det = DetectAndCheck(Face::kBack, cam_from_back, 0.05, 0.2);
  EXPECT_EQ(det.quality.num_corners, 99);
  for (int id : det.quality.tag_ids) EXPECT_GE(id, 100);
}

// Part of the board outside the image: the corners in view, with right ids,
// when a single tag is seen.
TEST_F(DefaultTargetDetection, PartialBoardWithOneTagInView) {
  // Slide the board right and down until one tag is left in view.
  Pose cam_from_face;
  bool found = false;
  for (double dx = -40; dx >= -120 && !found; dx -= 10) {
    cam_from_face = LookAtFace(target_, 200, 10, -10, 5, Eigen::Vector2d(dx, 55));
    found = VisibleTags(target_, Face::kFront, camera_, cam_from_face, 3) == 1;
  }
  ASSERT_TRUE(found);
  // Corners near the image's edge are refined in smaller windows (the
  // window must stay inside the image), so the bound is looser than for
  // whole boards: measured 0.054 px RMS here.
  const FaceDetection det = DetectAndCheck(Face::kFront, cam_from_face, 0.07, 0.25);
  EXPECT_LT(VisibleCorners(target_, camera_, cam_from_face, 0), 60);  // it really is partial
  EXPECT_EQ(det.quality.num_tags, 1);
  EXPECT_GE(det.quality.num_corners, RefinableCorners(target_, camera_, cam_from_face));
  EXPECT_LE(det.quality.num_corners, VisibleCorners(target_, camera_, cam_from_face, 0));
}

// A spread of random views like a calibration's (170-290 mm, tilts to 40
// degrees, any turn, shifted so that many boards run out of the image),
// both faces, 1 DN noise: every view with a tag in view is accepted and
// every id is right (a wrong id is off by a square, > 25 px).
TEST_F(DefaultTargetDetection, RandomPartialViewsOfBothFacesGetRightIds) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> distance(170, 290), tilt(-40, 40), turn(-180, 180), shift(-40, 40);
  int accepted = 0, corners = 0;
  for (int i = 0; i < 8; ++i) {
    const Face face = i % 2 ? Face::kBack : Face::kFront;
    const double d = distance(rng), rx = tilt(rng), ry = tilt(rng), rz = turn(rng), sx = shift(rng), sy = shift(rng);
    const Pose cam_from_face = LookAtFace(target_, d, rx, ry, rz, Eigen::Vector2d(sx, sy));
    SCOPED_TRACE(::testing::Message() << "view " << i);
    SyntheticViewOptions noisy;
    noisy.noise_sigma_dn = 1.0;
    noisy.seed = i;
    const DetectResult r = detector_.Detect(RenderFace(target_, face, camera_, cam_from_face, noisy));
    if (VisibleTags(target_, face, camera_, cam_from_face, 3) == 0) continue;
    ASSERT_EQ(r.faces.size(), 1u) << r.message;
    EXPECT_EQ(r.faces[0].face, face);
    const Errors e = CompareWithTruth(target_, r.faces[0], camera_, cam_from_face);
    EXPECT_LT(e.max_px, 0.3);
    EXPECT_GE(r.faces[0].quality.num_corners, RefinableCorners(target_, camera_, cam_from_face));
    for (const Eigen::Vector2d& q : r.faces[0].q_px) {  // never a corner extrapolated out of the image
      EXPECT_TRUE(q.x() >= 2 && q.y() >= 2 && q.x() <= camera_.width_px - 3 && q.y() <= camera_.height_px - 3)
          << q.transpose();
    }
    ++accepted;
    corners += r.faces[0].quality.num_corners;
  }
  EXPECT_GE(accepted, 6);
  std::printf("random views: %d accepted, %d corners\n", accepted, corners);
}

TEST_F(DefaultTargetDetection, MirroredImageIsRejected) {
  const cv::Mat img = RenderFace(target_, Face::kFront, camera_, LookAtFace(target_, 260, 10, -15, 5));
  cv::Mat mirrored;
  cv::flip(img, mirrored, 1);
  const DetectResult r = detector_.Detect(mirrored);
  EXPECT_TRUE(r.faces.empty());
  EXPECT_EQ(r.reason, RejectReason::kMirrored) << r.message;
}

TEST_F(DefaultTargetDetection, BothFacesInOneImageIsRejected) {
  const cv::Mat front = RenderFace(target_, Face::kFront, camera_, LookAtFace(target_, 400, 0, 0, 0, {-80, 0}));
  const cv::Mat back = RenderFace(target_, Face::kBack, camera_, LookAtFace(target_, 400, 0, 0, 0, {80, 0}));
  cv::Mat both = front.clone();
  back.colRange(both.cols / 2, both.cols).copyTo(both.colRange(both.cols / 2, both.cols));
  const DetectResult r = detector_.Detect(both);
  EXPECT_TRUE(r.faces.empty());
  EXPECT_EQ(r.reason, RejectReason::kBothFaces) << r.message;
}

TEST_F(DefaultTargetDetection, WrongFaceNoTagsAndTooFewCornersAreRejected) {
  DetectOptions expect_front;
  expect_front.expected_face = Face::kFront;
  const cv::Mat back = RenderFace(target_, Face::kBack, camera_, LookAtFace(target_, 260, 5, 5, 0));
  EXPECT_EQ(TargetDetector(target_, expect_front).Detect(back).reason, RejectReason::kWrongFace);

  // At 170 mm the tags (in the top and bottom margins) are out of view.
  const cv::Mat close = RenderFace(target_, Face::kFront, camera_, LookAtFace(target_, 170, 0, 5, 0));
  const DetectResult r = detector_.Detect(close);
  EXPECT_EQ(r.reason, RejectReason::kNoTags) << r.message;

  DetectOptions demanding;
  demanding.min_corners = 100;  // more than the board has
  const cv::Mat whole = RenderFace(target_, Face::kFront, camera_, LookAtFace(target_, 260, 5, 5, 0));
  EXPECT_EQ(TargetDetector(target_, demanding).Detect(whole).reason, RejectReason::kTooFewCorners);
  std::string why;
  EXPECT_TRUE(DetectTarget(whole, target_, demanding, &why).empty());
  EXPECT_NE(why.find("corners"), std::string::npos);
}

// Tags that disagree with the target file (here: the file puts front tag 3
// one square to the right of where it is printed) are refused as ambiguous
// rather than trusted.
TEST_F(DefaultTargetDetection, TagsThatDisagreeWithTheTargetFileAreRejected) {
  Target::Layout moved = target_.layout();
  for (TagPlacement& t : moved.faces[0].tags) {
    if (t.id == 3) t.center_x_mm += 9.0;  // still in the top margin, off the squares
  }
  const Target wrong(moved, "moved tag");
  const Pose cam_from_face = LookAtFace(target_, 280, 10, -15, 5);
  ASSERT_EQ(VisibleTags(target_, Face::kFront, camera_, cam_from_face, 2), 8);
  const DetectResult r =
      TargetDetector(wrong, DetectOptions()).Detect(RenderFace(target_, Face::kFront, camera_, cam_from_face));
  EXPECT_TRUE(r.faces.empty());
  EXPECT_EQ(r.reason, RejectReason::kAmbiguous) << r.message;
}

// With sensor noise the error grows, but ids stay right.
TEST_F(DefaultTargetDetection, NoisyImageKeepsIdsRight) {
  SyntheticViewOptions noisy;
  noisy.noise_sigma_dn = 3.0;
  const Pose cam_from_face = LookAtFace(target_, 270, 25, 20, -15);
  const cv::Mat img = RenderFace(target_, Face::kFront, camera_, cam_from_face, noisy);
  const DetectResult r = detector_.Detect(img);
  ASSERT_EQ(r.faces.size(), 1u) << r.message;
  const Errors e = CompareWithTruth(target_, r.faces[0], camera_, cam_from_face);
  // 3 DN on a 190 DN step over a ~2 px edge: a few hundredths of a px per
  // corner; 0.15 px is far below a wrong id (one square, ~35 px).
  EXPECT_LT(e.rms_px, 0.15);
  EXPECT_LT(e.max_px, 0.5);
  EXPECT_EQ(r.faces[0].quality.num_corners, 99);
}

// Plain boards: no tags; the whole board must be seen.
TEST(PlainBoardDetection, ColourAsymmetricBoardGetsTrueIdsInAnyTurn) {
  // 9x6 inner corners: 10x7 squares, whose colours differ after a half turn.
  const Target plain = PlainTarget(9, 6, 12.0);
  const PinholeCamera camera;
  const TargetDetector detector(plain, DetectOptions());
  for (double rz : {0.0, 180.0, 95.0, -80.0}) {
    SCOPED_TRACE(::testing::Message() << "rz " << rz);
    const Pose cam_from_face = LookAtFace(plain, 300, 15, -20, rz + 5);
    const DetectResult r = detector.Detect(RenderFace(plain, Face::kFront, camera, cam_from_face));
    ASSERT_EQ(r.faces.size(), 1u) << r.message;
    EXPECT_EQ(r.faces[0].quality.num_corners, 54);
    const Errors e = CompareWithTruth(plain, r.faces[0], camera, cam_from_face);
    EXPECT_LT(e.rms_px, 0.05);
  }
}

TEST(PlainBoardDetection, SymmetricBoardTakesCornerZeroFromTheImagesUp) {
  // 11x9 inner corners: 12x10 squares look the same after a half turn. The
  // detector then puts the face's x axis to the right of the image, so a
  // board turned by 170 degrees is read as turned by -10: ids are the true
  // ones turned through a half turn (id -> 98 - id).
  Target::Layout l;
  l.corners_x = 11;
  l.corners_y = 9;
  l.square_size_mm = 9.0;
  l.double_sided = false;
  l.margin_mm = 9.0;
  const Target plain(l, "plain 11x9");
  const PinholeCamera camera;
  const TargetDetector detector(plain, DetectOptions());
  for (double rz : {10.0, 170.0}) {
    SCOPED_TRACE(::testing::Message() << "rz " << rz);
    const Pose cam_from_face = LookAtFace(plain, 260, 10, -15, rz);
    const DetectResult r = detector.Detect(RenderFace(plain, Face::kFront, camera, cam_from_face));
    ASSERT_EQ(r.faces.size(), 1u) << r.message;
    FaceDetection det = r.faces[0];
    if (rz > 90) {
      for (int& id : det.corner_ids) id = plain.num_corners() - 1 - id;
    }
    EXPECT_LT(CompareWithTruth(plain, det, camera, cam_from_face).rms_px, 0.05);
  }
}

TEST(PlainBoardDetection, PartlyHiddenPlainBoardIsRejected) {
  const Target plain = PlainTarget(9, 6, 12.0);
  const PinholeCamera camera;
  const cv::Mat img = RenderFace(plain, Face::kFront, camera, LookAtFace(plain, 200, 0, 10, 5, {-70, 0}));
  const DetectResult r = TargetDetector(plain, DetectOptions()).Detect(img);
  EXPECT_TRUE(r.faces.empty());
  EXPECT_EQ(r.reason, RejectReason::kNoChessboard) << r.message;
}

}  // namespace
}  // namespace stereorig
