#include "reconstruct/free_space.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>
#include <optional>

namespace stereorig {
namespace {

// A rectified left camera at `centre_mm` (reference frame) looking at
// `look_at_mm`, y down: f 1000 px, 752 x 582 px, baseline 90 mm, no offset.
FreeSpaceView CameraAt(const Eigen::Vector3d& centre_mm, const Eigen::Vector3d& look_at_mm) {
  const Eigen::Vector3d z = (look_at_mm - centre_mm).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d reference_from_module;
  reference_from_module << x, y, z;
  FreeSpaceView v;
  v.geometry.focal_px = 1000;
  v.geometry.cx_left_px = 376;
  v.geometry.cy_px = 291;
  v.geometry.baseline_mm = 90;
  v.geometry.size = cv::Size(752, 582);
  v.module_from_reference = Pose(reference_from_module, centre_mm).Inverse();
  v.camera_centre_reference_mm = centre_mm;
  return v;
}

// Points of the rectangle z = z_mm, x in [x0, x1), y in [-20, 20) mm, every
// 0.15 mm (~0.75 px at 200 mm: at least one point per pixel), normal n.
void AddPlanePatch(double z_mm, double x0, double x1, const Eigen::Vector3f& n, PointCloud* c) {
  for (double y = -20; y < 20; y += 0.15)
    for (double x = x0; x < x1; x += 0.15) {
      c->xyz_mm.emplace_back(float(x), float(y), float(z_mm));
      c->normal.push_back(n);
      c->intensity.push_back(0);
      c->module.push_back(0);
      c->confidence.push_back(1);
    }
}

// The default rig's pair: module 0 at the origin, module 1 across the
// target at 400 mm, both looking at (0, 0, 200) mm.
std::vector<FreeSpaceView> FacingPair() {
  const Eigen::Vector3d target(0, 0, 200);
  return {CameraAt(Eigen::Vector3d::Zero(), target), CameraAt(Eigen::Vector3d(0, 0, 400), target)};
}

// A ring's pair: module 0 at the origin, module 1 60 deg round the y axis,
// 200 mm from (0, 0, 200) mm, both looking at it.
std::vector<FreeSpaceView> SixtyDegreePair() {
  const Eigen::Vector3d target(0, 0, 200);
  const double a = 60 * M_PI / 180;
  return {CameraAt(Eigen::Vector3d::Zero(), target),
          CameraAt(target + 200 * Eigen::Vector3d(std::sin(a), 0, -std::cos(a)), target)};
}

// How many of [begin, end) the test removes (any verdict but kKept), or,
// with `only`, how many have that verdict.
size_t Count(const std::vector<uint8_t>& verdicts, size_t begin, size_t end,
             std::optional<FreeSpaceVerdict> only = std::nullopt) {
  size_t n = 0;
  for (size_t i = begin; i < end; ++i) n += only ? verdicts[i] == uint8_t(*only) : verdicts[i] != 0;
  return n;
}

// SixtyDegreePair's scene below: module 0 measures the plane z = 200 mm for
// x < 0 and a wrong surface at z = 250 mm for x in [0, wrong_end_mm);
// module 1 the plane for x in [-20, 20) mm. All face both cameras.
struct WrongSurfaceScene {
  std::vector<PointCloud> clouds = std::vector<PointCloud>(2);
  size_t true_points = 0;  // module 0's first points: the true plane; the wrong surface's after
};
WrongSurfaceScene WrongSurfaceBehindThePlane(double wrong_end_mm) {
  const Eigen::Vector3f towards_cameras(0, 0, -1);  // faces both cameras (camera 1 at 60 deg: n.v = 0.5)
  WrongSurfaceScene s;
  AddPlanePatch(200, -20, 0, towards_cameras, &s.clouds[0]);
  s.true_points = s.clouds[0].size();
  AddPlanePatch(250, 0, wrong_end_mm, towards_cameras, &s.clouds[0]);
  AddPlanePatch(200, -20, 20, towards_cameras, &s.clouds[1]);
  return s;
}

// Module 0 looks along +z; module 1 from 60 deg round the y axis, both at
// the plane z = 200 mm. Module 0 measures the left half of the plane right
// and, over the right half, a wrong surface 50 mm behind it (the ring's
// grazed module: ~225 px of disparity off at this range); module 1 measures
// the whole plane. From camera 0, module 1's points lie in front of the
// wrong surface: it goes, and nothing else does.
TEST(FreeSpaceRefuted, RemovesAWrongSurfaceBehindAnotherModulesFacingSurface) {
  const std::vector<FreeSpaceView> views = SixtyDegreePair();
  const auto [clouds, true_points] = WrongSurfaceBehindThePlane(25);  // x up to 25: the ray's spread

  const std::vector<std::vector<uint8_t>> refuted = FreeSpaceRefuted(views, clouds, FreeSpaceOptions());
  ASSERT_EQ(refuted.size(), 2u);
  EXPECT_EQ(Count(refuted[0], 0, true_points), 0u) << "module 0's true surface kept";
  EXPECT_EQ(Count(refuted[1], 0, clouds[1].size()), 0u) << "module 1's surface kept";
  // The wrong surface's points whose rays (from camera 0) cross module 1's
  // patch: x < 20 * 250 / 200 = 25 mm, all of them but its edge's pixels.
  const size_t wrong = clouds[0].size() - true_points;
  size_t behind_patch = 0, removed_behind_patch = 0;
  for (size_t i = true_points; i < clouds[0].size(); ++i) {
    const Eigen::Vector3f& p = clouds[0].xyz_mm[i];
    if (p.x() * 200 / 250 < 19.5 && std::abs(p.y() * 200 / 250) < 19.5) {
      ++behind_patch;
      removed_behind_patch += refuted[0][i];
    }
  }
  EXPECT_GT(behind_patch, wrong / 2);
  EXPECT_EQ(removed_behind_patch, behind_patch) << "the wrong surface behind module 1's is removed";
}

// A wrong surface most of which another module's surface hides goes whole:
// as above, but the wrong surface reaches x = 27 mm, past the rays (x <
// 25 mm) that cross module 1's patch, so ~7 % of it has nothing in front
// and is refuted by nothing. It lies on one surface (neighbouring pixels'
// points 0.2 mm apart), > surface_fraction (0.8) of which is refuted: all
// of it goes.
TEST(FreeSpaceRefuted, ASurfaceMostOfWhichIsSeenThroughGoesWhole) {
  const std::vector<FreeSpaceView> views = SixtyDegreePair();
  const auto [clouds, true_points] = WrongSurfaceBehindThePlane(27);
  const std::vector<std::vector<uint8_t>> refuted = FreeSpaceRefuted(views, clouds, FreeSpaceOptions());
  EXPECT_EQ(Count(refuted[0], 0, true_points), 0u) << "module 0's true surface kept";
  EXPECT_EQ(Count(refuted[0], true_points, clouds[0].size()), clouds[0].size() - true_points)
      << "the whole wrong surface removed, also where nothing lies in front of it";
  // Where nothing hides it (x > 25 mm: ~7 %), said so.
  const size_t on_surface = Count(refuted[0], true_points, clouds[0].size(), FreeSpaceVerdict::kOnSeenThroughSurface);
  EXPECT_GT(on_surface, (clouds[0].size() - true_points) * 5 / 100);
  EXPECT_LT(on_surface, (clouds[0].size() - true_points) * 15 / 100);
  EXPECT_EQ(Count(refuted[1], 0, clouds[1].size()), 0u) << "module 1's surface kept";
}

// A wrong surface refutes nothing once it is found wrong. Module 0 as
// above (the true plane's left half, and the wrong surface at 250 mm
// behind module 1's patch); module 1 also measures a background plane at
// z = 300 mm, x in [-100, -20) mm, which it sees past the plate, and whose
// rays from camera 1 at x in ~[-58, -22) mm cross the wrong surface
// (camera 1 at (173, 0, 100) mm: the ray to (-40, 0, 300) crosses z = 250
// at x = 13 mm). Seen from camera 1 the wrong surface lies in front of that
// part of the background and faces it (n.v ~0.68): the first pass refutes
// ~44 % of the background, and all of the wrong surface. The wrong surface
// is then removed whole, and without it the background stands. (Had the
// wrong surface hidden more than surface_fraction of the background, both
// would have gone: the rule reads which surface is mostly seen through.)
TEST(FreeSpaceRefuted, AWrongSurfaceRefutesNothing) {
  const std::vector<FreeSpaceView> views = SixtyDegreePair();
  const Eigen::Vector3f towards_cameras(0, 0, -1);
  auto [clouds, true_points] = WrongSurfaceBehindThePlane(25);
  const size_t plate_points = clouds[1].size();
  AddPlanePatch(300, -100, -20, towards_cameras, &clouds[1]);
  const std::vector<std::vector<uint8_t>> refuted = FreeSpaceRefuted(views, clouds, FreeSpaceOptions());
  EXPECT_EQ(Count(refuted[0], 0, true_points), 0u) << "module 0's true surface kept";
  EXPECT_EQ(Count(refuted[0], true_points, clouds[0].size()), clouds[0].size() - true_points)
      << "the wrong surface removed";
  EXPECT_EQ(Count(refuted[1], 0, plate_points), 0u) << "module 1's plate kept";
  EXPECT_EQ(Count(refuted[1], plate_points, clouds[1].size()), 0u) << "module 1's background kept";
  // The first pass alone (a wrong surface is a surface all of which is
  // refuted, and it is not: nothing is removed whole) refutes the
  // background behind the wrong surface: what the second pass undoes.
  FreeSpaceOptions whole_only;
  whole_only.surface_fraction = 1;
  std::vector<PointCloud> partial = clouds;
  AddPlanePatch(250, 25, 27, towards_cameras, &partial[0]);  // a strip nothing hides: the surface is not all refuted
  const std::vector<std::vector<uint8_t>> first = FreeSpaceRefuted(views, partial, whole_only);
  EXPECT_GT(Count(first[1], plate_points, partial[1].size()), (partial[1].size() - plate_points) * 3 / 10);  // ~44 %
}

// A rectified pair of module `view` over a textured fronto-parallel plane at
// disparity d_px: a random left image of ~1 px grain (like laser speckle),
// the right one the left shifted by d_px (R(x) = L(x + d)).
void TexturedPairAt(double d_px, FreeSpaceView* view) {
  const cv::Size size = view->geometry.size;
  cv::Mat wide(size.height, size.width + int(std::ceil(d_px)) + 1, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(wide, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(wide, wide, cv::Size(0, 0), 0.6);
  view->left_rectified = wide(cv::Rect(0, 0, size.width, size.height)).clone();
  const cv::Matx23d shift(1, 0, d_px, 0, 1, 0);  // right(x, y) = wide(x + d, y), linearly interpolated
  cv::warpAffine(wide, view->right_rectified, shift, size, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
}

// A refuter module j's own cameras do not see counts for nothing. Module 0
// (baseline 20 mm: disparity 80 px at 250 mm, 100 px at 200 mm) measures a
// background plane at z = 250 mm, x in [-40, 40) mm; module 1 a wrong patch
// at z = 200 mm, x in [-10, 10) mm, facing camera 0, in front of ~31 % of
// the background along camera 0's rays (not enough for the background to
// go whole). Module 0's rectified pair shows the background (the right
// view shifted by 80 px): at the patch's 100 px its window does not
// correlate, and the background stands. The same points with a pair that
// shows the patch (100 px), or with no images, are refuted.
TEST(FreeSpaceRefuted, ARefuterTheModulesOwnCamerasDoNotSeeRefutesNothing) {
  std::vector<FreeSpaceView> views = SixtyDegreePair();
  views[0].geometry.baseline_mm = 20;
  const Eigen::Vector3f towards_cameras(0, 0, -1);
  std::vector<PointCloud> clouds(2);
  AddPlanePatch(250, -40, 40, towards_cameras, &clouds[0]);
  AddPlanePatch(200, -10, 10, towards_cameras, &clouds[1]);
  size_t behind_patch = 0;  // background points on camera 0's rays through the patch, short of its edge pixels
  for (const Eigen::Vector3f& p : clouds[0].xyz_mm) behind_patch += std::abs(p.x() * 200 / 250) < 9.5;

  const std::vector<std::vector<uint8_t>> no_images = FreeSpaceRefuted(views, clouds, FreeSpaceOptions());
  EXPECT_GE(Count(no_images[0], 0, clouds[0].size()), behind_patch) << "without images: geometry alone";
  EXPECT_LT(Count(no_images[0], 0, clouds[0].size()), clouds[0].size() / 2) << "the background is not wrong whole";

  TexturedPairAt(100, &views[0]);
  const std::vector<std::vector<uint8_t>> patch_seen = FreeSpaceRefuted(views, clouds, FreeSpaceOptions());
  EXPECT_GE(Count(patch_seen[0], 0, clouds[0].size()), behind_patch) << "module 0's cameras see the patch";
  // A hiding point is read within +-0.5 px of its disparity (where in its
  // pixel it lies, and its own noise, are not known): a pair showing the
  // patch 0.6 px further still counts.
  TexturedPairAt(100.6, &views[0]);
  const std::vector<std::vector<uint8_t>> patch_seen_off = FreeSpaceRefuted(views, clouds, FreeSpaceOptions());
  EXPECT_GE(Count(patch_seen_off[0], 0, clouds[0].size()), behind_patch) << "the patch, 0.6 px off";

  TexturedPairAt(80, &views[0]);
  const std::vector<std::vector<uint8_t>> background_seen = FreeSpaceRefuted(views, clouds, FreeSpaceOptions());
  // The check is statistical, as the matcher's own min_zncc: a window at a
  // wrong shift can correlate >= 0.8 by chance. At this grain (and this
  // fixed seed) none does; blurred to a ~2.5 px grain (sigma 1.2 px), 7.8 %
  // of the points behind the patch kept a refutation.
  EXPECT_EQ(Count(background_seen[0], 0, clouds[0].size()), 0u) << "module 0's cameras see the background";
  EXPECT_EQ(Count(background_seen[1], 0, clouds[1].size()), 0u);

  // A blank pair (as the rows outside a module's rectified band): no window
  // can be read, the check cannot tell, and geometry decides.
  views[0].left_rectified.setTo(0), views[0].right_rectified.setTo(0);
  const std::vector<std::vector<uint8_t>> blank = FreeSpaceRefuted(views, clouds, FreeSpaceOptions());
  EXPECT_GE(Count(blank[0], 0, clouds[0].size()), behind_patch) << "a blank pair: geometry alone";
}

// Where module j's RIGHT camera grazes the hiding surface, j's pair cannot
// correlate it even where it is there, and it counts on geometry alone.
// Module 0 (baseline 90 mm, a wide image so that every window fits) sees
// a background plane at z = 250 mm, its pair showing the background (360
// px); module 1 measured a plane through (0, 0, 200) mm turned 65 deg from
// camera 0's axis (n.v = 0.42 > min_facing_cos), x in [-5, 5) mm: in module
// 0's image its disparity steps by 0.45 tan 65 = 0.97 px/px, so 1 - dd/dx =
// 0.03 < 0.3: module 0's right camera sees it edge-on. The background
// behind it goes.
TEST(FreeSpaceRefuted, ASurfaceTheModulesRightCameraGrazesCountsOnGeometry) {
  std::vector<FreeSpaceView> views = SixtyDegreePair();
  views[0].geometry.size = cv::Size(1500, 582);
  views[0].geometry.cx_left_px = 1000;
  const double tilt = -65 * M_PI / 180;
  const Eigen::Vector3f n(float(std::sin(tilt)), 0, float(-std::cos(tilt)));  // faces camera 0 (n.v = cos 65 deg)
  std::vector<PointCloud> clouds(2);
  AddPlanePatch(250, -40, 40, Eigen::Vector3f(0, 0, -1), &clouds[0]);
  for (double y = -20; y < 20; y += 0.15)
    for (double x = -5; x < 5; x += 0.1) {
      clouds[1].xyz_mm.emplace_back(float(x), float(y), float(200 + x * std::tan(-tilt)));  // n.(X - (0,0,200)) = 0
      clouds[1].normal.push_back(n);
      clouds[1].intensity.push_back(0);
      clouds[1].module.push_back(0);
      clouds[1].confidence.push_back(1);
    }
  TexturedPairAt(360, &views[0]);
  size_t behind = 0;  // background points on camera 0's rays through the plane's middle
  for (const Eigen::Vector3f& p : clouds[0].xyz_mm) behind += std::abs(p.x()) < 3 && std::abs(p.y()) < 19;
  const std::vector<std::vector<uint8_t>> refuted = FreeSpaceRefuted(views, clouds, FreeSpaceOptions());
  size_t removed_behind = 0;
  for (size_t i = 0; i < clouds[0].size(); ++i) {
    const Eigen::Vector3f& p = clouds[0].xyz_mm[i];
    removed_behind += refuted[0][i] && std::abs(p.x()) < 3 && std::abs(p.y()) < 19;
  }
  EXPECT_GT(behind, 1000u);
  EXPECT_EQ(removed_behind, behind);
  EXPECT_LT(Count(refuted[0], 0, clouds[0].size()), clouds[0].size() / 2) << "the background is not wrong whole";
}

// The default rig's pair: two modules facing each other across a 2 mm
// plate, each measuring its own face. From either camera the other
// module's points lie behind its own surface (and face away): nothing is
// removed. Also with the facing test off (min_facing_cos 0 still needs
// n.v > 0) and a 1 px margin.
TEST(FreeSpaceRefuted, RemovesNothingFromAFacingPairsPlate) {
  const std::vector<FreeSpaceView> views = FacingPair();
  std::vector<PointCloud> clouds(2);
  AddPlanePatch(199, -20, 20, Eigen::Vector3f(0, 0, -1), &clouds[0]);
  AddPlanePatch(201, -20, 20, Eigen::Vector3f(0, 0, 1), &clouds[1]);
  FreeSpaceOptions loose;
  loose.margin_px = 1.0, loose.window_radius_px = 1, loose.min_support = 1, loose.min_facing_cos = 0.0;
  for (const FreeSpaceOptions& o : {FreeSpaceOptions(), loose}) {
    const std::vector<std::vector<uint8_t>> refuted = FreeSpaceRefuted(views, clouds, o);
    EXPECT_EQ(Count(refuted[0], 0, clouds[0].size()), 0u);
    EXPECT_EQ(Count(refuted[1], 0, clouds[1].size()), 0u);
  }
}

// A point behind another module's surface that faces AWAY from the camera
// (its back face, which the camera cannot see anyway) is not refuted: only
// surfaces facing the camera block its view. Module 1, across the plate,
// measured the plate's far face; module 0 a point 5 mm behind it.
TEST(FreeSpaceRefuted, ABackFacingSurfaceRefutesNothing) {
  const std::vector<FreeSpaceView> views = FacingPair();
  std::vector<PointCloud> clouds(2);
  AddPlanePatch(205, -5, 5, Eigen::Vector3f(0, 0, -1), &clouds[0]);
  AddPlanePatch(200, -20, 20, Eigen::Vector3f(0, 0, 1), &clouds[1]);
  const std::vector<std::vector<uint8_t>> refuted = FreeSpaceRefuted(views, clouds, FreeSpaceOptions());
  EXPECT_EQ(Count(refuted[0], 0, clouds[0].size()), 0u);
}

// Only what lies in FRONT refutes: module 0 measures a small plate at
// 200 mm, module 1 (60 deg round) a background plate at 230 mm that faces
// camera 0 too and spans its view behind the small plate. Every module-1
// point near module 0's rays lies 30 mm (~70 px) behind: nothing of module
// 0 goes.
TEST(FreeSpaceRefuted, ASurfaceBehindFromTheCamerasViewRefutesNothing) {
  const std::vector<FreeSpaceView> views = SixtyDegreePair();
  std::vector<PointCloud> clouds(2);
  AddPlanePatch(200, -5, 5, Eigen::Vector3f(0, 0, -1), &clouds[0]);
  AddPlanePatch(230, -20, 20, Eigen::Vector3f(0, 0, -1), &clouds[1]);
  const std::vector<std::vector<uint8_t>> refuted = FreeSpaceRefuted(views, clouds, FreeSpaceOptions());
  EXPECT_EQ(Count(refuted[0], 0, clouds[0].size()), 0u);
}

// A steep surface both modules measure: the plane through (0, 0, 200) mm
// turned 70 deg from camera 0's axis (towards module 1, which sees it
// nearly face on). In camera 0's image its disparity steps by ~1.2 px/px,
// so another module's correct points two px away read ~2.5 px nearer than
// the point: the test compares them with the point's own plane (its
// normal), and nothing is removed, also at a 2 px margin (where, compared
// with the point's own disparity, the window's far columns would refute it).
TEST(FreeSpaceRefuted, KeepsASteepSurfaceBothModulesMeasure) {
  const Eigen::Vector3d target(0, 0, 200);
  const double tilt = 70 * M_PI / 180;
  const std::vector<FreeSpaceView> views = SixtyDegreePair();
  const Eigen::Vector3f n(float(std::sin(tilt)), 0, float(-std::cos(tilt)));     // faces both cameras
  const Eigen::Vector3f along(float(std::cos(tilt)), 0, float(std::sin(tilt)));  // in the plane, across y
  std::vector<PointCloud> clouds(2);
  for (PointCloud& c : clouds)
    for (double y = -20; y < 20; y += 0.15)
      for (double s = -20; s < 20; s += 0.15) {
        c.xyz_mm.push_back(target.cast<float>() + float(s) * along + Eigen::Vector3f(0, float(y), 0));
        c.normal.push_back(n);
        c.intensity.push_back(0);
        c.module.push_back(0);
        c.confidence.push_back(1);
      }
  for (const double margin_px : {4.0, 2.0}) {
    FreeSpaceOptions o;
    o.margin_px = margin_px;
    const std::vector<std::vector<uint8_t>> refuted = FreeSpaceRefuted(views, clouds, o);
    EXPECT_EQ(Count(refuted[0], 0, clouds[0].size()), 0u) << margin_px << " px";
    EXPECT_EQ(Count(refuted[1], 0, clouds[1].size()), 0u) << margin_px << " px";
  }
}

}  // namespace
}  // namespace stereorig
