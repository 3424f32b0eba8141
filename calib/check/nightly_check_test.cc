// The nightly check on synthetic corner observations: the true default rig
// plays an ideal calibration (provenance RMS = the injected noise), and the
// "morning after" cameras are the true ones, optionally bumped. Corner noise
// 0.2 px per axis, Gaussian, as the simulator's detections show.
//
// Judged as issue 6 asks: over 20 seeds, no false alarm unbumped; a bump of
// 0.05 deg of one camera's rotation, or 0.1 mm of one module's translation,
// flagged in >= 19 of 20 seeds, with the right camera or module named. And
// one camera's lens drifted (focal length, principal point): flagged, the
// camera named, and never said to have merely moved.
#include "calib/check/nightly_check.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <utility>

#include "calib/check/board_pose.h"
#include "calib/check/board_scale.h"
#include "calib/check/check_target.h"
#include "calib/core/input_error.h"
#include "calib/core/lens_drift.h"
#include "datasets/default_rig.h"

namespace stereorig {
namespace {

constexpr double kNoisePx = 0.2;
constexpr double kRenderedNoisePx =
    0.03;  // what the simulator's rendered corners read in a night (tests/check_cli_test.cc)
constexpr int kCaptures = 8;

// How many named cameras the check said each CameraChangeKind of.
using KindCounts = std::array<int, static_cast<int>(CameraChangeKind::kNotFitted) + 1>;
int Said(const KindCounts& said, CameraChangeKind kind) { return said[static_cast<int>(kind)]; }

struct Bump {
  int camera = -1;            // rotate this camera ...
  double rotation_deg = 0;    // ... by this much about a random axis
  int module = -1;            // shift this module's cameras ...
  double translation_mm = 0;  // ... by this much in a random direction
  int shifted_camera = -1;    // or only this camera, by translation_mm
  int opposite_camera = -1;   // and this one too, the opposite way (a baseline stretched)
  LensDrift lens;             // the bumped camera's lens drifted (focal length, principal point)
  bool every_lens = false;    // every camera's lens drifted so, alike
};

bool ModuleOfCameraIsZero(const Rig& rig, int c) {
  return rig.module(0).left_camera == c || rig.module(0).right_camera == c;
}

Rig StoredRig(const SimulatedRig& truth, double noise_px = kNoisePx) {
  Rig rig = truth.rig;
  for (int c = 0; c < rig.num_cameras(); ++c)
    rig.provenance().residuals["cam" + std::to_string(c) + "_rms_px"] = noise_px;
  return rig;
}

// `rig` whose calibration puts an error of `u_px` (1 sigma) on each
// camera's projections (provenance.uncertainties).
Rig WithProjectionUncertainty(Rig rig, double u_px) {
  for (int c = 0; c < rig.num_cameras(); ++c)
    rig.provenance().uncertainties["cam" + std::to_string(c) + "_projection_center_px"] = u_px;
  return rig;
}

// The corners of `v`'s face that `cam` sees through `cam_from_face`, each
// with Gaussian noise drawn from `noise` (two draws a corner in front of the
// camera, in corner order), those inside the image.
void SeeCorners(const Camera& cam, const Pose& cam_from_face, const Target& target,
                std::normal_distribution<double>& noise, std::mt19937& rng, BoardObservation* v) {
  for (int id = 0; id < target.num_corners(); ++id) {
    const Eigen::Vector3d p = cam_from_face * target.CornerInFace(id);
    if (p.z() <= 0) continue;
    const Eigen::Vector2d q = cam.Project(p) + Eigen::Vector2d(noise(rng), noise(rng));
    if (q.x() < 0 || q.y() < 0 || q.x() > cam.imager_width_px() - 1 || q.y() > cam.imager_height_px() - 1) continue;
    v->corner_ids.push_back(id);
    v->q_px.push_back(q);
  }
}

// Detections of `kCaptures` target poses between the modules, seen by the
// (possibly bumped) true cameras.
std::vector<BoardObservation> Observe(const SimulatedRig& truth, const Target& target, const Bump& bump, unsigned seed,
                                      double noise_px = kNoisePx) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, noise_px);
  std::uniform_real_distribution<double> u(-1, 1);
  const Rig& rig = truth.rig;
  std::vector<Pose> cam_from_ref(rig.num_cameras());
  for (int c = 0; c < rig.num_cameras(); ++c) cam_from_ref[c] = rig.CamFromReference(c);
  if (bump.camera >= 0) {
    const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    cam_from_ref[bump.camera] =
        Pose::FromRotationVector(axis * bump.rotation_deg * M_PI / 180, Eigen::Vector3d::Zero()) *
        cam_from_ref[bump.camera];
  }
  if (bump.module >= 0) {
    const Eigen::Vector3d dir = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const Pose moved_from_ref(Eigen::Matrix3d::Identity(), dir * bump.translation_mm);
    for (int c : {rig.module(bump.module).left_camera, rig.module(bump.module).right_camera})
      cam_from_ref[c] = cam_from_ref[c] * moved_from_ref.Inverse();
  }
  if (bump.shifted_camera >= 0) {
    const Eigen::Vector3d dir = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const Pose moved_from_ref(Eigen::Matrix3d::Identity(), dir * bump.translation_mm);
    cam_from_ref[bump.shifted_camera] = cam_from_ref[bump.shifted_camera] * moved_from_ref.Inverse();
    if (bump.opposite_camera >= 0)
      cam_from_ref[bump.opposite_camera] = cam_from_ref[bump.opposite_camera] * moved_from_ref;
  }
  const Eigen::Vector3d center((target.corners_x() - 1) * 0.5 * target.square_size_mm(),
                               (target.corners_y() - 1) * 0.5 * target.square_size_mm(), 0);
  std::vector<BoardObservation> views;
  for (int k = 0; k < kCaptures; ++k) {
    // The board near the world origin, front face towards module 0, tilted.
    const Pose world_from_front = Pose::FromRotationVector(Eigen::Vector3d(0.35 * u(rng), 0.35 * u(rng), 0.3 * u(rng)),
                                                           Eigen::Vector3d(15 * u(rng), 15 * u(rng), 20 * u(rng))) *
                                  Pose(Eigen::Matrix3d::Identity(), -center);
    const Pose ref_from_front = truth.world_from_module0.Inverse() * world_from_front;
    for (int c = 0; c < rig.num_cameras(); ++c) {
      const Face face = ModuleOfCameraIsZero(rig, c) ? Face::kFront : Face::kBack;
      BoardObservation v{k, c, face, {}, {}};
      const Pose face_from_front = face == Face::kFront ? Pose::Identity() : target.back_from_front();
      const Pose cam_from_face = cam_from_ref[c] * ref_from_front * face_from_front.Inverse();
      const Camera cam = c == bump.camera || bump.every_lens ? WithLensDrift(rig.camera(c), bump.lens) : rig.camera(c);
      SeeCorners(cam, cam_from_face, target, noise, rng, &v);
      if (v.corner_ids.size() >= 6) views.push_back(v);
    }
  }
  return views;
}

TEST(NightlyCheck, NoFalseAlarmOnTheUnbumpedRigOverTwentySeeds) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(truth);
  int alarms = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const CheckResult r = RunNightlyCheck(stored, target, Observe(truth, target, {}, seed), CheckOptions(), "test");
    if (!r.ok()) {
      ++alarms;
      for (const auto& f : r.figures)
        if (!f.pass) ADD_FAILURE() << "seed " << seed << ": " << f.name << " " << f.value << " > " << f.threshold;
    }
  }
  EXPECT_EQ(alarms, 0);
}

// An unmoved night one capture of which is noisier than the rest, as a
// capture seen nearly edge-on is (the walkthrough's seed 502: both of module
// 0's views of capture 006 at 0.035 px about their own poses, the night's
// 0.024 px, and module 0's stereo figure failed). Corners at the rendered
// 0.03 px; in capture 0 cam1 sees only the board's first three rows (at most
// 33 corners: a weak one-camera pose, as the walkthrough's 28) and both of
// module 0's views are at twice the noise, as is cam0's view of capture 1
// (twice stays under the slip bound, 2.5 times the camera's). Judged with one
// sigma per camera for the night, cam0's view of capture 0 read through
// cam1's weak pose was expected as if both were at the night's noise, and
// capture 1's view raising cam0's sigma let it through the skip rule:
// module0_stereo_consistency_rms_px failed on 4 of these 40 nights. With
// each view's own noise, none: each threshold is meant to let an unchanged
// rig through but ~2e-3 of the time (k = 3.5), 0.08 of 40 nights, as the
// unbumped test above asks of its 20. And the same nights with camera 0's
// principal point moved 0.05 px (the smallest drift the study catches on 20
// of 20 nights, docs/verify-and-check.md) are still flagged with camera 0
// named on 19 of 20 or more, the study's bar.
std::vector<BoardObservation> WithOneNoisyCapture(std::vector<BoardObservation> views, const Target& target,
                                                  unsigned seed) {
  std::mt19937 rng(seed + 1000);
  // Added to the corners' kRenderedNoisePx, twice it in all.
  std::normal_distribution<double> more(0, kRenderedNoisePx * std::sqrt(3.0));
  for (BoardObservation& v : views) {
    if (v.capture == 0 && v.camera == 1) {
      BoardObservation rows = v;
      rows.corner_ids.clear(), rows.q_px.clear();
      for (size_t i = 0; i < v.corner_ids.size(); ++i)
        if (v.corner_ids[i] / target.corners_x() < 3)
          rows.corner_ids.push_back(v.corner_ids[i]), rows.q_px.push_back(v.q_px[i]);
      v = rows;
    }
    if ((v.capture == 0 && (v.camera == 0 || v.camera == 1)) || (v.capture == 1 && v.camera == 0))
      for (Eigen::Vector2d& q : v.q_px) q += Eigen::Vector2d(more(rng), more(rng));
  }
  return views;
}

TEST(NightlyCheck, ACaptureNoisierThanItsNightIsJudgedByItsOwnNoise) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(truth, kRenderedNoisePx);
  int alarms = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    const CheckResult r = RunNightlyCheck(
        stored, target, WithOneNoisyCapture(Observe(truth, target, {}, seed, kRenderedNoisePx), target, seed),
        CheckOptions(), "test");
    if (r.ok()) continue;
    ++alarms;
    for (const auto& f : r.figures)
      if (!f.pass) ADD_FAILURE() << "seed " << seed << ": " << f.name << " " << f.value << " > " << f.threshold;
  }
  EXPECT_EQ(alarms, 0);
  int flagged = 0, named = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    Bump drift;
    drift.camera = 0;
    drift.lens.principal_point_px = {0.05, 0.0};
    const CheckResult r = RunNightlyCheck(
        stored, target, WithOneNoisyCapture(Observe(truth, target, drift, seed, kRenderedNoisePx), target, seed),
        CheckOptions(), "test");
    flagged += !r.ok();
    named += r.FlaggedCameras() == std::vector<int>{0};
  }
  EXPECT_GE(flagged, 19);
  EXPECT_GE(named, 19);
}

// The board's back_from_front as the calibration ended with it (stage 3
// refines the target file's jointly with S; check_target.h). A target file
// off by 1.5 of its own stated sigma in each axis (0.015 mm of the default's
// 0.01 mm; 0.026 mm in all), the rig stored as a calibration that refined it
// to the truth (`stereorig calibrate` on the demo's captures recovered a file
// off by 0.022 mm to 0.0003 mm; CalibrateE2E.DefaultTargetOfTheTargetsLibrary
// one off by 0.026 mm to 0.004-0.010 mm at 0.2 px corners), corners at the
// 0.03 px the simulator's rendered ones read (at 0.2 px the closure's
// threshold is wide enough to hide the file's error on 13 of 20 nights).
// Measured with the file's, the unmoved rig's closure reads the file's error
// beyond its threshold on every night (20 of 20; `stereorig check` on the
// demo's unmoved night: 0.019 mm against 0.015); with the rig file's record
// it reads the noise: no false alarm over 20 seeds, as the unbumped rig above.
TEST(NightlyCheck, TheClosureUsesTheBoardAsCalibratedNotTheTargetFile) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target board = DefaultTarget();
  Target::Layout layout = board.layout();
  layout.back_from_front =
      Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.015, -0.015, 0.015)) * board.back_from_front();
  const Target file(layout, "file");
  Rig stored = StoredRig(truth, kRenderedNoisePx);
  CalibrationTarget& rec = stored.provenance().target.emplace();
  rec.file = "target.yaml";
  rec.corners_x = board.corners_x();
  rec.corners_y = board.corners_y();
  rec.square_size_mm = board.square_size_mm();
  rec.double_sided = true;
  rec.back_from_front = board.back_from_front();
  rec.back_from_front_file = file.back_from_front();
  rec.back_from_front_sigma_file = file.back_from_front_sigma();
  const CheckTarget used = TargetForCheck(stored, file, "target.yaml");
  ASSERT_TRUE(used.as_calibrated);
  EXPECT_TRUE(used.note.empty()) << used.note;
  EXPECT_NEAR(used.calibrated_vs_file_mm, 0.015 * std::sqrt(3.0), 1e-12);
  EXPECT_EQ(used.target.back_from_front().ToMatrix4(), board.back_from_front().ToMatrix4());
  int alarms_with_file = 0, alarms_as_calibrated = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const std::vector<BoardObservation> views = Observe(truth, board, {}, seed, kRenderedNoisePx);
    alarms_with_file += !RunNightlyCheck(stored, file, views, CheckOptions(), "test").ok();
    const CheckResult r = RunNightlyCheck(stored, used.target, views, CheckOptions(), "test");
    if (!r.ok()) {
      ++alarms_as_calibrated;
      for (const auto& f : r.figures)
        if (!f.pass) ADD_FAILURE() << "seed " << seed << ": " << f.name << " " << f.value << " > " << f.threshold;
    }
  }
  std::printf("back_from_front off 0.026 mm: alarms with the target file's %d of 20, as calibrated %d of 20\n",
              alarms_with_file, alarms_as_calibrated);
  EXPECT_GE(alarms_with_file, 19);  // the file's error is what the record removes
  EXPECT_EQ(alarms_as_calibrated, 0);
}

// A detection slip that no pose explains: every other corner of one view
// taken 2 px off along the rows (corners assigned to the wrong squares where the
// board is seen nearly edge-on do so; on a simulated three-module ring such
// views fitted their own pose to 0.44-0.81 px, and through the all-camera
// pose spoiled their whole capture: 8 of 10 unmoved nights flagged). The
// view must be set aside whole, named, and the unbumped rig pass, over 20
// seeds; every other view kept. Its own fit leaves ~0.7 px per axis (its
// corners 1 px either side of the fit along x), over 2.5x the 0.2 px noise.
TEST(NightlyCheck, AViewWhoseCornersFitNoPoseIsSetAsideNotReadAsAChange) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(truth);
  int alarms = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::vector<BoardObservation> views = Observe(truth, target, {}, seed);
    BoardObservation* slipped = nullptr;
    for (BoardObservation& v : views)
      if (v.capture == 3 && v.camera == 1 && v.corner_ids.size() >= 20) slipped = &v;
    ASSERT_NE(slipped, nullptr) << "seed " << seed;
    for (size_t k = 0; k < slipped->q_px.size(); k += 2) slipped->q_px[k].x() += 2.0;
    const CheckResult r = RunNightlyCheck(stored, target, views, CheckOptions(), "test");
    alarms += !r.ok();
    if (!r.ok()) std::printf("seed %u: %s\n", seed, r.Explanation().c_str());
    ASSERT_EQ(r.views_set_aside.size(), 1u) << "seed " << seed;
    EXPECT_EQ(r.views_set_aside[0].capture, 3);
    EXPECT_EQ(r.views_set_aside[0].camera, 1);
    EXPECT_GT(r.views_set_aside[0].jump_rms_px, r.views_set_aside[0].bound_px);
    // 2.5x the larger of the stored noise and the lower median of the camera's
    // other views tonight: their jumps between neighbouring corners read
    // ~sigma (independent noise), each scattering by ~sigma / sqrt(4 pairs)
    // (~4% at ~150 pairs, more for views of fewer corners), so the bound
    // lies at 2.5 sigma or within 10% above it.
    EXPECT_GE(r.views_set_aside[0].bound_px, 2.5 * kNoisePx);
    EXPECT_LT(r.views_set_aside[0].bound_px, 2.5 * 1.1 * kNoisePx);
  }
  EXPECT_EQ(alarms, 0);
}

// The same slip where its camera has only two views tonight: the bound comes
// from the other view (a median over both took the slipped view's own RMS
// and could never set it aside, a second reading found). And a lens change
// is not a slip: one camera's distortion drifted (every corner moved
// outward by 1.5 px (r / 400 px)^3, r from the image centre: a smooth
// field, ~1.5 px at the image's corners) leaves a smooth field of
// residuals about each view's own pose, whose neighbouring corners barely
// differ, and the check keeps every view (the own-pose RMS alone set a
// distortion change aside as a slip, a second reading found).
TEST(NightlyCheck, ASlipIsSetAsideWithTwoViewsAndASmoothLensChangeIsNot) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(truth);
  for (unsigned seed = 1; seed <= 5; ++seed) {
    std::vector<BoardObservation> all = Observe(truth, target, {}, seed), views;
    for (const BoardObservation& v : all)
      if (v.camera != 1 || v.capture == 3 || v.capture == 5) views.push_back(v);
    for (BoardObservation& v : views) {
      if (v.camera != 1 || v.capture != 3) continue;
      for (size_t k = 0; k < v.q_px.size(); k += 2) v.q_px[k].x() += 2.0;
    }
    const CheckResult r = RunNightlyCheck(stored, target, views, CheckOptions(), "test");
    ASSERT_EQ(r.views_set_aside.size(), 1u) << "seed " << seed;
    EXPECT_EQ(r.views_set_aside[0].capture, 3);
    EXPECT_EQ(r.views_set_aside[0].camera, 1);
  }
  int flagged = 0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    std::vector<BoardObservation> views = Observe(truth, target, {}, seed);
    const Camera& cam = truth.rig.camera(2);
    const Eigen::Vector2d centre(0.5 * (cam.imager_width_px() - 1), 0.5 * (cam.imager_height_px() - 1));
    for (BoardObservation& v : views) {
      if (v.camera != 2) continue;
      for (Eigen::Vector2d& q : v.q_px) {
        const Eigen::Vector2d d = q - centre;
        q += 1.5 * std::pow(d.norm() / 400.0, 3) * d.normalized();
      }
    }
    const CheckResult r = RunNightlyCheck(stored, target, views, CheckOptions(), "test");
    EXPECT_TRUE(r.views_set_aside.empty()) << "seed " << seed << ": " << r.views_set_aside.size();
    flagged += !r.ok();
  }
  EXPECT_EQ(flagged, 5);  // and the change is seen
}

// Over seeds 1..20, in how many the check flags the rig bumped by
// bump_for(seed), and in how many it names exactly what the figures can tell
// of the bump (its camera; for a module, both modules of the default rig,
// whose one closure cannot tell which of the two changed; nothing else); a
// seed it misnames is printed with every figure.
struct BumpReading {
  int flagged = 0, named = 0;
  std::vector<double> turn_errors_deg = {};      // turned_deg - the bump's, the bumped camera's `moved` readings
  KindCounts said = {};                          // named cameras by kind
  std::map<std::string, int> explanations = {};  // seeds by the verdict's words
};
BumpReading ReadBumps(const std::function<Bump(unsigned)>& bump_for, double noise_px = kNoisePx) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(truth, noise_px);
  BumpReading reading;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Bump bump = bump_for(seed);
    const CheckResult r =
        RunNightlyCheck(stored, target, Observe(truth, target, bump, seed, noise_px), CheckOptions(), "test");
    reading.flagged += !r.ok();
    // A bumped camera's views still fit their own pose: none is set aside.
    EXPECT_TRUE(r.views_set_aside.empty()) << "seed " << seed << ": " << r.views_set_aside.size();
    const std::vector<int> cameras = bump.camera >= 0 ? std::vector<int>{bump.camera} : std::vector<int>{};
    const std::vector<int> modules = bump.module >= 0 ? std::vector<int>{0, 1} : std::vector<int>{};
    for (const CameraChange& c : r.camera_changes) {
      ++reading.said[static_cast<int>(c.kind)];
      if (c.camera == bump.camera && c.kind == CameraChangeKind::kMoved && bump.rotation_deg > 0)
        reading.turn_errors_deg.push_back(c.turned_deg - bump.rotation_deg);
    }
    ++reading.explanations[r.Explanation()];
    if (r.FlaggedCameras() == cameras && r.FlaggedModules() == modules) {
      ++reading.named;
    } else {
      std::string figures;
      for (const auto& f : r.figures)
        figures += f.name + "=" + std::to_string(f.value) + "/" + std::to_string(f.threshold) + " ";
      std::printf("seed %u bump camera %d module %d: %s | %s\n", seed, bump.camera, bump.module,
                  r.Explanation().c_str(), figures.c_str());
    }
  }
  return reading;
}

TEST(NightlyCheck, FlagsAndNamesACameraRotatedByFiveHundredthsOfADegree) {
  const BumpReading r = ReadBumps([](unsigned seed) {
    Bump bump;
    bump.camera = static_cast<int>(seed % 4);
    bump.rotation_deg = 0.05;
    return bump;
  });
  EXPECT_GE(r.flagged, 19);
  EXPECT_GE(r.named, 19);
  // Its new pose fits: never blamed on the lens alone, nor said to be
  // explained by neither.
  EXPECT_EQ(Said(r.said, CameraChangeKind::kLens), 0);
  EXPECT_EQ(Said(r.said, CameraChangeKind::kUnexplained), 0);
}

// Either module of the two shifted 0.1 mm: flagged, and both modules named
// as disagreeing, since their closure cannot tell which one changed (module 0
// only defines the reference frame) nor a motion from a lens drift. A shift
// of module 0 read "module 1 moved or a lens changed": the module that did
// not change.
TEST(NightlyCheck, FlagsAModuleShiftedByATenthOfAMillimetreAndSaysWhichPairDisagrees) {
  for (int module : {0, 1}) {
    BumpReading r = ReadBumps([module](unsigned) {
      Bump bump;
      bump.module = module;
      bump.translation_mm = 0.1;
      return bump;
    });
    EXPECT_GE(r.flagged, 19) << "module " << module;
    EXPECT_GE(r.named, 19) << "module " << module;
    EXPECT_GE(r.explanations["module 0 and module 1 disagree: one moved or a lens changed"], 19) << "module " << module;
  }
}

// A knock, not a drift: a camera turned 1 or 3 degrees, a module shifted
// 2 mm. The knocked camera or module pulls the pose every other camera
// implies, so no camera fitted the others within 2 px and the night was
// refused as "captures of another rig" (exit 2, no history) where a smaller
// bump was named (a user's walkthrough). Named as the small ones are.
TEST(NightlyCheck, AKnockOfDegreesOrMillimetresIsNamedNotRefusedAsAnotherRig) {
  for (double deg : {1.0, 3.0}) {
    const BumpReading r = ReadBumps([deg](unsigned seed) {
      Bump bump;
      bump.camera = static_cast<int>(seed % 4);
      bump.rotation_deg = deg;
      return bump;
    });
    EXPECT_EQ(r.flagged, 20) << deg << " deg";
    // As the small bumps are (FlagsAndNamesACameraRotatedBy...: 19 of 20,
    // the bound of a check whose thresholds sit at k = 3 sigma).
    EXPECT_GE(r.named, 19) << deg << " deg";
    // The named camera's fitted turn (CameraChange::turned_deg) is the
    // bump's: over the seeds its error averages to zero within 3 standard
    // errors of its own spread (at kNoisePx, 0.2 px, the spread is ~0.006
    // deg, the worst of 20 seeds 0.014 deg; rendered nights at ~0.03 px read
    // to 0.001 deg, docs/verify-and-check.md). Reporting no turn, or twice
    // it, fails by hundreds of standard errors.
    const std::vector<double>& err = r.turn_errors_deg;
    ASSERT_GE(err.size(), 19u) << deg << " deg";
    double mean = 0, var = 0;
    for (double e : err) mean += e / double(err.size());
    for (double e : err) var += (e - mean) * (e - mean) / double(err.size() - 1);
    EXPECT_LT(std::abs(mean), 3 * std::sqrt(var / double(err.size()))) << deg << " deg, spread " << std::sqrt(var);
  }
  BumpReading r = ReadBumps([](unsigned seed) {
    Bump bump;
    bump.module = static_cast<int>(seed % 2);
    bump.translation_mm = 2.0;
    return bump;
  });
  EXPECT_EQ(r.flagged, 20);
  EXPECT_GE(r.explanations["module 0 and module 1 disagree: one moved or a lens changed"], 19);
}

// The same knock on a rig of one module (two cameras), which has no rest of
// the rig to agree with: a camera turned 1 or 3 degrees failed both
// cameras' figures, each through the other's board poses, and every night
// was refused as "captures of another rig" (exit 2, no history), 20 of 20
// seeds. Judged now: each camera's corners still fit its own lens about
// board poses of their own (nightly_check.cc, fits_own_lens), and the turned
// camera is named, since read as its partner's motion the same night needs
// a shift of the partner by |turn x baseline| (up to 1.6 mm per degree;
// TurnedCameraOfModule). Another rig's captures are still refused:
// its right camera 30 mm and 5 degrees elsewhere and both focal lengths
// 20 % off (on seed 1, about their own poses 0.60-0.80 px against 0.25-0.29
// px of noise read from neighbour jumps), or only 5 % off (0.25-0.27 px against
// 0.20-0.21 px: a mean square 1.5-1.8 times the noise's, where the bound at
// a fixed 3 sigma over ~1400 residuals and about as many neighbour pairs is
// ~1.2 times). A camera shifted 2 mm alone
// shifts in either reading: flagged, its module named. The module shifted
// as a whole changes nothing a one-module rig can see (the board's pose is
// free each night): not flagged.
TEST(NightlyCheck, AKnockOfAOneModuleRigIsNamedAndAnotherRigsCapturesAreStillRefused) {
  const SimulatedRig two = MakeDefaultRig();
  const SimulatedRig one{
      Rig({two.rig.camera(0), two.rig.camera(1)}, {"cam0", "cam1"}, {two.rig.module(0)}, {Pose::Identity()}),
      two.world_from_module0};
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(one);
  for (double deg : {1.0, 3.0}) {
    int flagged = 0, named = 0;
    std::vector<double> turn_errors_deg;
    for (unsigned seed = 1; seed <= 20; ++seed) {
      Bump bump;
      bump.camera = static_cast<int>(seed % 2);
      bump.rotation_deg = deg;
      CheckResult r;
      try {
        r = RunNightlyCheck(stored, target, Observe(one, target, bump, seed), CheckOptions(), "test");
      } catch (const InputError& e) {
        ADD_FAILURE() << deg << " deg, seed " << seed << ": refused: " << e.what();
        continue;
      }
      flagged += !r.ok();
      if (r.FlaggedCameras() == std::vector<int>{bump.camera} && r.FlaggedModules().empty()) {
        ++named;
        EXPECT_EQ(r.camera_changes[0].kind, CameraChangeKind::kMoved) << r.Explanation();
        turn_errors_deg.push_back(r.camera_changes[0].turned_deg - deg);
      } else {
        std::printf("%g deg, seed %u, camera %d: %s\n", deg, seed, bump.camera, r.Explanation().c_str());
      }
    }
    EXPECT_EQ(flagged, 20) << deg << " deg";
    EXPECT_GE(named, 19) << deg << " deg";
    // The fitted turn is the knock's: its error averages to zero within 3
    // standard errors of its own spread over the seeds (as the four-camera
    // rig's, AKnockOfDegreesOrMillimetresIsNamedNotRefusedAsAnotherRig).
    ASSERT_GE(turn_errors_deg.size(), 2u);
    const double n = static_cast<double>(turn_errors_deg.size());
    double mean = 0, var = 0;
    for (double e : turn_errors_deg) mean += e / n;
    for (double e : turn_errors_deg) var += (e - mean) * (e - mean) / (n - 1);
    EXPECT_LT(std::abs(mean), 3 * std::sqrt(var / n)) << deg << " deg, spread " << std::sqrt(var);
  }
  {
    int flagged = 0, module_named = 0, whole_ok = 0;
    for (unsigned seed = 1; seed <= 20; ++seed) {
      Bump camera_shift;
      camera_shift.shifted_camera = static_cast<int>(seed % 2);
      camera_shift.translation_mm = 2.0;
      const CheckResult r =
          RunNightlyCheck(stored, target, Observe(one, target, camera_shift, seed), CheckOptions(), "test");
      flagged += !r.ok();
      module_named += r.split_modules == std::vector<int>{0};
      Bump module_shift;
      module_shift.module = 0;
      module_shift.translation_mm = 2.0;
      whole_ok +=
          RunNightlyCheck(stored, target, Observe(one, target, module_shift, seed), CheckOptions(), "test").ok();
    }
    EXPECT_EQ(flagged, 20);
    EXPECT_GE(module_named, 19);
    EXPECT_GE(whole_ok, 19);  // as an unbumped rig: NoFalseAlarmOnTheUnbumpedRigOverTwentySeeds
  }
  for (double focal_percent : {20.0, -20.0, 5.0}) {
    SimulatedRig other = one;
    std::vector<Camera> cameras;
    for (int c = 0; c < 2; ++c) {
      LensDrift lens;
      lens.focal_percent = focal_percent;
      cameras.push_back(WithLensDrift(one.rig.camera(c), lens));
    }
    StereoModule module = one.rig.module(0);
    module.right_from_left = Pose::FromRotationVector({0, 0.09, 0}, {30, 0, 0}) * module.right_from_left;
    other.rig = Rig(cameras, one.rig.camera_names(), {module}, {Pose::Identity()});
    // The own-lens gate is at a fixed 3 sigma: --k-sigma 10 refuses them too.
    for (unsigned seed = 1; seed <= 10; ++seed) {
      CheckOptions options;
      options.k_sigma = seed <= 5 ? options.k_sigma : 10.0;
      try {
        RunNightlyCheck(stored, target, Observe(other, target, {}, (seed - 1) % 5 + 1), options, "captures");
        ADD_FAILURE() << "another rig's captures (focal lengths " << focal_percent << " % off), seed "
                      << (seed - 1) % 5 + 1 << ", k " << options.k_sigma << ", were judged";
      } catch (const InputError& e) {
        if (seed == 1) std::printf("focal lengths %+g %%: %s\n", focal_percent, e.what());
        EXPECT_NE(std::string(e.what()).find("captures: the captures do not fit this rig at all (each camera is off "
                                             "by > 2 px through the other's board poses; cam"),
                  std::string::npos)
            << e.what();
      }
    }
  }
}

SimulatedRig OneModuleRig() {
  const SimulatedRig two = MakeDefaultRig();
  return {Rig({two.rig.camera(0), two.rig.camera(1)}, {"cam0", "cam1"}, {two.rig.module(0)}, {Pose::Identity()}),
          two.world_from_module0};
}

// A one-module rig's captures of a board whose squares are not the target
// file's (2 % larger or smaller, each view's own board pose absorbing the
// similarity) fit every camera's lens about the views' own poses as a
// knock's do, and read "module 0's cameras disagree" (exit 1, a history
// row) once the own-lens rule judged them. Refused again, as before it,
// naming the board: the pair's stored baseline measures the board's size,
// and on a board of that size both cameras agree. Seeds 1-3 each way.
TEST(NightlyCheck, AOneModuleRigsCapturesOfABoardOfAnotherSizeAreRefusedNamingTheBoard) {
  const SimulatedRig one = OneModuleRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(one);
  for (double square_mm : {9.18, 8.82}) {
    const Target board = DoubleSidedTarget(11, 9, square_mm);
    for (unsigned seed = 1; seed <= 3; ++seed) {
      try {
        const CheckResult r =
            RunNightlyCheck(stored, target, Observe(one, board, {}, seed), CheckOptions(), "captures");
        ADD_FAILURE() << "squares of " << square_mm << " mm, seed " << seed << ", judged: " << r.Explanation();
      } catch (const InputError& e) {
        if (seed == 1) std::printf("squares of %g mm: %s\n", square_mm, e.what());
        const std::string what = e.what();
        const std::string head = "captures: the captures do not fit this rig's board: module 0 measures the board ";
        ASSERT_EQ(what.substr(0, head.size()), head) << what;
        // The size as printed, within 0.1 % of the truth (noise 0.2 px over
        // 8 captures reads the size to a few 0.01 %: AWrongTargetFileIsNamed...).
        EXPECT_NEAR(std::stod(what.substr(head.size())), 100 * std::abs(square_mm / 9.0 - 1), 0.1) << what;
        EXPECT_NE(what.find(std::string(square_mm > 9 ? "% larger" : "% smaller") + " than squares of 9.000 mm"),
                  std::string::npos)
            << what;
      }
    }
  }
}

// The own-lens rule against a calibration whose lens model misses the real
// lens: the true cameras' k1 is off the stored one's by 0.025 (a radial
// misfit of ~0.11 px about each view's own pose, smooth: the neighbour
// jumps do not see it), which the calibration's RMS records (provenance
// residual: the stored lens's own-pose RMS on an unbumped night of 8
// captures, noise 0.2 px injected: 0.227 and 0.232 px). A camera turned 1
// degree is judged (flagged, not refused) on seeds 1-10 (tonight's
// own-pose RMS 0.219-0.241 px against jumps of 0.195-0.207 px); compared
// with the jump noise alone the misfit read as another rig's lens and 9 of
// the 10 nights were refused. (k1 off by 0.035: 0.25-0.26 px at
// calibration, and the turned camera's views, elsewhere in the image, can
// show more of the misfit than the calibration night did: one seed of 10
// refused.)
TEST(NightlyCheck, AOneModuleKnockIsJudgedWhenTheStoredLensMissesTheTruthByItsCalibrationRms) {
  const SimulatedRig stored_one = OneModuleRig();
  const Target target = DefaultTarget();
  SimulatedRig truth = stored_one;
  {
    std::vector<Camera> cameras;
    for (int c = 0; c < 2; ++c) {
      std::vector<double> x = stored_one.rig.camera(c).intrinsics();
      x[4] += 0.025;  // k1
      cameras.emplace_back(stored_one.rig.camera(c).lensmodel_name(), x, stored_one.rig.camera(c).imager_width_px(),
                           stored_one.rig.camera(c).imager_height_px());
    }
    truth.rig = Rig(cameras, stored_one.rig.camera_names(), {stored_one.rig.module(0)}, {Pose::Identity()});
  }
  Rig stored = StoredRig(stored_one);
  {
    // What the calibration would have reported: the stored lens's RMS per
    // axis about each view's own pose, unbumped.
    std::vector<double> ss(2, 0.0), dof(2, 0.0);
    for (const BoardObservation& v : Observe(truth, target, {}, 100)) {
      const BoardPoseEstimate own = EstimateBoardPose(stored, target, {&v});
      if (!own.ok) continue;
      for (const Eigen::Vector2d& e : ReprojectionErrors(stored, target, v, own.ref_from_front))
        ss[v.camera] += e.squaredNorm();
      dof[v.camera] += 2.0 * v.corner_ids.size() - 6;
    }
    for (int c = 0; c < 2; ++c) {
      const double rms = std::sqrt(ss[c] / dof[c]);
      std::printf("cam%d: the stored lens's own-pose RMS %.3f px (noise %.3f px)\n", c, rms, kNoisePx);
      EXPECT_GT(rms, 1.1 * kNoisePx) << "the misfit must show";
      stored.provenance().residuals["cam" + std::to_string(c) + "_rms_px"] = rms;
    }
  }
  for (unsigned seed = 1; seed <= 10; ++seed) {
    Bump bump;
    bump.camera = static_cast<int>(seed % 2);
    bump.rotation_deg = 1.0;
    try {
      const CheckResult r = RunNightlyCheck(stored, target, Observe(truth, target, bump, seed), CheckOptions(), "c");
      EXPECT_FALSE(r.ok()) << "seed " << seed;
      std::printf("seed %u, camera %d turned 1 deg: %s\n", seed, bump.camera, r.Explanation().c_str());
    } catch (const InputError& e) {
      ADD_FAILURE() << "seed " << seed << ": refused: " << e.what();
    }
  }
}

// A lens drift of camera seed % 4 over seeds 1..`seeds`: how often it is
// flagged, the camera named alone, and what the check said changed; the
// worst focal-length estimate error in units of its own standard error.
//
// That standard error, from the injected noise: the lens fit
// (calib/check/camera_change.cc) regresses the corners' offsets on
// (q - c) s + d, so s has the standard error sigma / sqrt(sum |q - c|^2) over
// the camera's corners (the board poses the other cameras give add less:
// three cameras of about as many corners each). At 0.2 px and ~450 corners
// some 200 px from the centre that is 0.005 %.
struct LensDriftReading {
  int flagged = 0, named = 0;
  KindCounts said = {};             // over the named seeds
  double worst_focal_error_sd = 0;  // max |estimate - truth| / its standard error
};
LensDriftReading ReadLensDrifts(const LensDrift& drift, double noise_px, unsigned seeds) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(truth, noise_px);
  LensDriftReading reading;
  for (unsigned seed = 1; seed <= seeds; ++seed) {
    Bump bump;
    bump.camera = static_cast<int>(seed % 4);
    bump.lens = drift;
    const std::vector<BoardObservation> views = Observe(truth, target, bump, seed, noise_px);
    const CheckResult r = RunNightlyCheck(stored, target, views, CheckOptions(), "test");
    reading.flagged += !r.ok();
    if (r.FlaggedCameras() != std::vector<int>{bump.camera} || !r.FlaggedModules().empty()) {
      std::printf("seed %u lens of camera %d: %s\n", seed, bump.camera, r.Explanation().c_str());
      continue;
    }
    ++reading.named;
    const CameraChange& change = r.camera_changes.at(0);
    ++reading.said[static_cast<int>(change.kind)];
    const Camera& cam = truth.rig.camera(bump.camera);
    double sum_r2 = 0;
    for (const BoardObservation& v : views)
      if (v.camera == bump.camera)
        for (const Eigen::Vector2d& q : v.q_px) sum_r2 += (q - Eigen::Vector2d(cam.cx(), cam.cy())).squaredNorm();
    const double sd_percent = 100.0 * noise_px / std::sqrt(sum_r2);
    reading.worst_focal_error_sd =
        std::max(reading.worst_focal_error_sd, std::abs(change.focal_percent - drift.focal_percent) / sd_percent);
  }
  std::printf("said: moved %d, lens %d, moved or lens %d, unexplained %d, not fitted %d\n", reading.said[0],
              reading.said[1], reading.said[2], reading.said[3], reading.said[4]);
  return reading;
}

// 0.1 % of focal length (fx, fy), at 0.2 px corner noise: flagged and the
// camera named, never as merely "moved". End to end, 0.1 % moves a module's
// points up to 0.17 mm at 200 mm (docs/verify-and-check.md). At this noise
// the check names the camera from 0.1 % on (0.05 %: 2 seeds of 20; a
// calibrated rig's 0.03 px detections name 0.02 %), and a shift of the
// camera along its axis fits its corners about as well, so "moved or its
// lens changed" is what it may say. The estimate is within 4 standard
// errors (above) of the truth: measured 0.005 % RMS, worst 0.011 %.
TEST(NightlyCheck, FlagsAndNamesACameraWhoseFocalLengthDriftedATenthOfAPercent) {
  LensDrift drift;
  drift.focal_percent = 0.1;
  const LensDriftReading r = ReadLensDrifts(drift, kNoisePx, 20);
  EXPECT_GE(r.flagged, 19);
  EXPECT_GE(r.named, 19);
  EXPECT_EQ(Said(r.said, CameraChangeKind::kMoved), 0);
  EXPECT_EQ(Said(r.said, CameraChangeKind::kUnexplained), 0);  // the lens fit frees just what drifted
  EXPECT_LE(r.worst_focal_error_sd, 4.0);
}

// With sharp corners (0.03 px, what a calibrated rig's rendered captures
// show: its stage-1 RMS 0.022 px, tonight's 0.03 px) a 0.5 % drift is told
// from a motion: no pose of the camera fits corners whose boards stand at
// different depths (0.5 %: 20 of 20 seeds; 0.2 %: 17).
TEST(NightlyCheck, TellsALensDriftFromAMotionWhenTheCornersAreSharp) {
  LensDrift drift;
  drift.focal_percent = 0.5;
  const LensDriftReading r = ReadLensDrifts(drift, 0.03, 10);
  EXPECT_EQ(r.flagged, 10);
  EXPECT_EQ(r.named, 10);
  EXPECT_EQ(Said(r.said, CameraChangeKind::kLens), 10);
  EXPECT_LE(r.worst_focal_error_sd, 4.0);
}

// A principal point moved by 0.5 px (0.2 px corner noise) is flagged and the
// camera named; to first order it is a turn of 0.5 / 1024 rad, so the check
// may not call it a lens change alone, nor a motion alone.
TEST(NightlyCheck, FlagsAndNamesACameraWhosePrincipalPointMoved) {
  LensDrift drift;
  drift.principal_point_px = {0.5, 0.0};
  const LensDriftReading r = ReadLensDrifts(drift, kNoisePx, 20);
  EXPECT_GE(r.flagged, 19);
  EXPECT_GE(r.named, 19);
  EXPECT_EQ(Said(r.said, CameraChangeKind::kMoved), 0);
  EXPECT_EQ(Said(r.said, CameraChangeKind::kUnexplained), 0);
}

// The verdict says no more than the figures tell: a closure cannot tell a
// module's motion from a lens drift, a module whose own cameras disagree did
// not move as a whole, and a camera's change reads as its fits found it.
TEST(NightlyCheck, ExplanationSaysNoMoreThanTheFiguresTell) {
  CheckResult r;
  r.figures = {{"pair_0_1_closure_mm", 0.1, 0.01, false, 8}};
  r.closure_modules = {0, 1};  // two modules
  r.closure_which_unknown = true;
  EXPECT_EQ(r.Explanation(), "module 0 and module 1 disagree: one moved or a lens changed");
  EXPECT_EQ(r.FlaggedModules(), (std::vector<int>{0, 1}));
  // What the board measured with says ends a failing night's explanation.
  r.target_note = "the rig file records no calibration target ...";
  EXPECT_EQ(r.Explanation(), "module 0 and module 1 disagree: one moved or a lens changed; " + r.target_note);
  r.target_note.clear();
  r.closure_modules = {2};  // three or more: the module in the most failing pairs
  r.closure_which_unknown = false;
  EXPECT_EQ(r.Explanation(), "module 2 moved or a lens changed");
  r.closure_modules.clear();
  r.split_modules = {1};
  EXPECT_EQ(r.Explanation(), "module 1's cameras disagree: one moved or its lens changed");
  EXPECT_EQ(r.FlaggedModules(), std::vector<int>{1});
  r.split_modules.clear();
  CameraChange lens;
  lens.camera = 2;
  lens.kind = CameraChangeKind::kLens;
  lens.focal_percent = 0.1;
  lens.principal_point_px = {-0.001, 0.25};
  r.camera_changes = {lens};
  EXPECT_EQ(r.Explanation(), "camera 2's lens changed: focal length +0.100 %, principal point +0.00, +0.25 px");
  EXPECT_EQ(r.FlaggedCameras(), std::vector<int>{2});
  r.camera_changes[0].kind = CameraChangeKind::kMovedOrLens;  // both fits' sizes said
  r.camera_changes[0].turned_deg = 0.0141;
  r.camera_changes[0].shifted_mm = 0.0004;
  EXPECT_EQ(r.Explanation(),
            "camera 2 moved or its lens changed (either explains its corners): turned 0.014 deg, shifted 0.000 mm, "
            "or focal length +0.100 %, principal point +0.00, +0.25 px");
  r.camera_changes[0].kind = CameraChangeKind::kUnexplained;
  r.camera_changes[0].moved_rms_px = std::numeric_limits<double>::infinity();  // its solve failed
  r.camera_changes[0].lens_rms_px = 0.0812;
  r.camera_changes[0].threshold_px = 0.0405;
  EXPECT_EQ(r.Explanation(),
            "camera 2 changed: neither a new pose nor a new lens alone explains its corners (the pose fit's solve "
            "failed, residual 0.081 px with a new lens, against 0.041 px)");
  r.camera_changes[0].kind = CameraChangeKind::kNotFitted;
  r.camera_changes[0].corners = 4;
  EXPECT_EQ(r.Explanation(), "camera 2 changed: too few corners (4) to fit a new pose or a new lens");
  r.camera_changes[0].kind = CameraChangeKind::kMoved;
  r.camera_changes[0].turned_deg = 0.0504, r.camera_changes[0].shifted_mm = 0.0031;
  r.camera_changes[0].role = "module 1's left camera";
  EXPECT_EQ(r.Explanation(), "camera 2 moved: turned 0.050 deg, shifted 0.003 mm [module 1's left camera]");
  r.target_note = "the target file's back_from_front is ...";  // any failing night's
  EXPECT_EQ(r.Explanation(),
            "camera 2 moved: turned 0.050 deg, shifted 0.003 mm [module 1's left camera]; " + r.target_note);
  r.figures[0].pass = true;  // and not a night that passes
  r.camera_changes.clear();
  EXPECT_EQ(r.Explanation(), "every figure within its threshold");
}

// Which modules failing closures name, from each module's count of failing
// pairs: one module alone only when it is in more failing pairs than any
// other; a single failing pair or a tie names the modules and says they
// disagree. Before, a rig of three or more modules named every module tied
// at the top as "moved or a lens changed" (a ring whose three pairs all
// fail: each of the three), and nothing when a single pair failed.
TEST(NightlyCheck, ClosuresNameOneModuleOnlyWhenItIsInTheMostFailingPairs) {
  auto named = [](const std::map<int, int>& counts) {
    const ClosureNaming n = NameClosureModules(counts);
    CheckResult r;
    r.figures = {{"pair_closure_mm", 1, 0.1, false, 8}};
    r.closure_modules = n.modules;
    r.closure_which_unknown = n.which_unknown;
    return r.Explanation();
  };
  EXPECT_EQ(named({{0, 1}, {1, 1}}), "module 0 and module 1 disagree: one moved or a lens changed");  // two modules
  EXPECT_EQ(named({{0, 1}, {1, 2}, {2, 1}}), "module 1 moved or a lens changed");  // a ring, module 1 moved
  EXPECT_EQ(named({{0, 2}, {1, 2}, {2, 2}}), "modules 0, 1 and 2 disagree: one or more moved or a lens changed");
  EXPECT_EQ(named({{1, 1}, {2, 1}}), "module 1 and module 2 disagree: one moved or a lens changed");  // one pair of 3
  // Four modules, 2 and 3 moved together: all four pairs across fail, a tie.
  EXPECT_EQ(named({{0, 2}, {1, 2}, {2, 2}, {3, 2}}),
            "modules 0, 1, 2 and 3 disagree: one or more moved or a lens changed");
  EXPECT_TRUE(NameClosureModules({}).modules.empty());
  EXPECT_FALSE(NameClosureModules({}).which_unknown);
}

// A single failing pair of three or more modules, read with the pairs
// judged: where one of its modules agrees with a third and the other's pair
// with that third was not judged, the other is the odd one, named alone.
// Not where the failing closure is within twice the agreeing pair's
// threshold (that pair might have let the same change of its module pass),
// nor where the third agrees with both, thirds point at each, or no third
// agrees with either: the pair is named as before. Two modules have no third.
TEST(NightlyCheck, ASingleFailingPairNamesItsModuleWhoseOtherPairIsNotJudgedWhereItsPartnerAgrees) {
  auto named = [](const std::map<int, int>& counts, const std::map<std::pair<int, int>, JudgedClosure>& judged) {
    const ClosureNaming n = NameClosureModules(counts, judged);
    CheckResult r;
    r.figures = {{"pair_closure_mm", 1, 0.1, false, 8}};
    r.closure_modules = n.modules;
    r.closure_which_unknown = n.which_unknown;
    return r.Explanation();
  };
  const JudgedClosure fails{0.1, 0.01, 0.001, 0.01}, holds{0.002, 0.01, 0.001, 0.01};
  const JudgedClosure holds_loosely{0.002, 0.06, 0.001, 0.01};  // 0.1 mm is within twice its threshold
  const JudgedClosure turn_fails{0.001, 0.01, 0.1, 0.01};       // a turn's, the same
  const std::string pair01 = "module 0 and module 1 disagree: one moved or a lens changed";
  const std::map<int, int> one_pair = {{0, 1}, {1, 1}};
  EXPECT_EQ(named(one_pair, {{{0, 1}, fails}}), pair01);  // two modules
  EXPECT_EQ(named(one_pair, {{{0, 1}, fails}, {{0, 2}, holds}}), "module 1 moved or a lens changed");
  EXPECT_EQ(named(one_pair, {{{0, 1}, turn_fails}, {{0, 2}, holds}}), "module 1 moved or a lens changed");
  EXPECT_EQ(named(one_pair, {{{0, 1}, fails}, {{1, 2}, holds}}), "module 0 moved or a lens changed");
  EXPECT_EQ(named(one_pair, {{{0, 1}, fails}, {{0, 2}, holds_loosely}}), pair01);
  EXPECT_EQ(named(one_pair, {{{0, 1}, fails}, {{0, 2}, holds}, {{1, 2}, holds}}), pair01);  // 2 agrees with both
  EXPECT_EQ(named(one_pair, {{{0, 1}, fails}, {{0, 2}, holds}, {{1, 3}, holds}}), pair01);  // thirds point at each
  EXPECT_EQ(named(one_pair, {{{0, 1}, fails}, {{2, 3}, holds}}), pair01);  // no third agrees with either
  EXPECT_EQ(named(one_pair, {{{0, 2}, holds}}), pair01);  // a shifted module's pair: no closure to size it by
  EXPECT_EQ(named({{1, 1}, {2, 1}}, {{{1, 2}, fails}, {{0, 2}, holds}, {{2, 3}, holds}}),
            "module 1 moved or a lens changed");
  // A module in the most pairs, and ties, as before.
  EXPECT_EQ(named({{0, 1}, {1, 2}, {2, 1}}, {{{0, 1}, fails}, {{1, 2}, fails}}), "module 1 moved or a lens changed");
  EXPECT_EQ(named({{0, 1}, {1, 1}, {2, 1}, {3, 1}}, {{{0, 1}, fails}, {{2, 3}, fails}, {{0, 2}, holds}}),
            "modules 0, 1, 2 and 3 disagree: one or more moved or a lens changed");
}

TEST(NightlyCheck, BadInputIsRefused) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const auto views = Observe(truth, target, {}, 1);
  // The truth rig has no calibration residuals to set thresholds from.
  EXPECT_THROW(RunNightlyCheck(truth.rig, target, views, CheckOptions(), "rig.yaml"), InputError);
  // Too few captures.
  std::vector<BoardObservation> few;
  for (const auto& v : views)
    if (v.capture < 3) few.push_back(v);
  EXPECT_THROW(RunNightlyCheck(StoredRig(truth), target, few, CheckOptions(), "captures"), InputError);
  // Captures of another rig: the cameras are 30 mm and 5 degrees elsewhere.
  SimulatedRig other = truth;
  std::vector<Pose> m0_from_m = {Pose::Identity(),
                                 Pose::FromRotationVector({0, 0.09, 0}, {30, 0, 0}) * truth.rig.S(0, 1)};
  other.rig = Rig(truth.rig.cameras(), truth.rig.camera_names(), truth.rig.modules(), m0_from_m);
  auto foreign = Observe(other, target, {}, 2);
  for (auto& v : foreign)
    for (auto& q : v.q_px) q.x() += 40;  // and another lens centre
  EXPECT_THROW(RunNightlyCheck(StoredRig(truth), target, foreign, CheckOptions(), "captures"), InputError);
  // Captures that show the board to one camera alone check nothing: camera 0
  // turned by a whole degree read "ok" with no figure at all (a second
  // reading found it). So does a rig of which one camera saw nothing.
  std::vector<BoardObservation> alone = Observe(
      truth, target,
      [] {
        Bump b;
        b.camera = 0;
        b.rotation_deg = 1.0;
        return b;
      }(),
      3);
  std::erase_if(alone, [](const BoardObservation& v) { return v.camera != 0; });
  ASSERT_GE(alone.size(), 3u);  // the check's minimum of captures
  std::vector<BoardObservation> without_3 = views;
  try {
    RunNightlyCheck(StoredRig(truth), target, alone, CheckOptions(), "captures");
    ADD_FAILURE() << "captures only camera 0 saw were judged";
  } catch (const InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("camera(s) 0, 1, 2, 3 saw the board in no capture where another camera saw it too"),
        std::string::npos)
        << e.what();
  }
  std::erase_if(without_3, [](const BoardObservation& v) { return v.camera == 3; });
  try {
    RunNightlyCheck(StoredRig(truth), target, without_3, CheckOptions(), "captures");
    ADD_FAILURE() << "captures camera 3 never saw were judged";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("camera(s) 3 saw"), std::string::npos) << e.what();
  }
}

// The board against the target file (board_scale.h). Truth: the default
// board (9 mm squares) observed by the true rig; the check given a target
// file with 9.18 mm squares (2% larger: the board measures 9 / 9.18 - 1 =
// -1.96%) or 8.91 mm (+1.01%) says so at the end of its explanation,
// naming each module's reading (within 0.1% of it); given the right file,
// every module reads the board within 0.1% of its size (noise 0.2 px over
// ~8 captures of ~99 corners: a few 0.01%) and nothing is said. A camera
// turned 0.5 deg, a module shifted 1 mm or a lens drifted 1% moves one
// module's reading at most: judged (recalibrate), nothing said of the
// board. Before, the wrong file read as every camera changed, with no word
// of the board (a user's walkthrough). It is said, not refused: every
// module's cameras turned alike would read the same (a second reading).
TEST(NightlyCheck, AWrongTargetFileIsNamedAndABumpIsNot) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target board = DefaultTarget();
  const Rig stored = StoredRig(truth);
  double worst_right = 0;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    const std::vector<BoardObservation> views = Observe(truth, board, {}, seed);
    const CheckResult right = RunNightlyCheck(stored, board, views, CheckOptions(), "captures");
    EXPECT_TRUE(right.board_size_note.empty()) << right.board_size_note;
    ASSERT_EQ(right.board_scales.size(), 2u);
    for (const ModuleBoardScale& m : right.board_scales) {
      worst_right = std::max(worst_right, std::abs(m.scale - 1));
      EXPECT_GE(m.captures, 3) << "seed " << seed;
    }
    for (const auto& [square_mm, expected] : {std::pair{9.18, "smaller"}, std::pair{8.91, "larger"}}) {
      const CheckResult r = RunNightlyCheck(stored, DoubleSidedTarget(11, 9, square_mm), views, CheckOptions(), "c");
      const std::string note = r.board_size_note;
      EXPECT_NE(note.find(std::string("every module measures the board ") + expected), std::string::npos) << note;
      char squares[48];  // the squares it measured with: the target file's here (the stored rig has no record)
      std::snprintf(squares, sizeof squares, "than squares of %.3f mm (", square_mm);
      EXPECT_NE(note.find(squares), std::string::npos) << note;
      EXPECT_EQ(r.Explanation().substr(r.Explanation().size() - note.size()), note) << r.Explanation();
      // Each module's reading as printed, within 0.1% of 9 / square_mm - 1.
      for (const char* module : {"module 0 ", "module 1 "}) {
        const size_t at = note.find(module);
        ASSERT_NE(at, std::string::npos) << note;
        EXPECT_NEAR(std::stod(note.substr(at + 9)), 100 * (9.0 / square_mm - 1), 0.1) << note;
      }
    }
  }
  EXPECT_LT(worst_right, 0.001);
  std::printf("board scale, right target file: worst |s - 1| %.4f%%\n", 100 * worst_right);
  const std::vector<Bump> bumps = [&] {
    Bump turned, shifted, lens;
    turned.camera = 1;
    turned.rotation_deg = 0.5;
    shifted.module = 1;
    shifted.translation_mm = 1.0;
    lens.camera = 2;
    lens.lens.focal_percent = 1.0;
    return std::vector<Bump>{turned, shifted, lens};
  }();
  for (const Bump& bump : bumps) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
      const CheckResult r = RunNightlyCheck(stored, board, Observe(truth, board, bump, seed), CheckOptions(), "c");
      std::string readings;
      for (const ModuleBoardScale& m : r.board_scales)
        readings += " module " + std::to_string(m.module) + " " + std::to_string(100 * (m.scale - 1)) + "%";
      std::printf("bump camera %d module %d focal %.1f%%, seed %u:%s\n", bump.camera, bump.module,
                  bump.lens.focal_percent, seed, readings.c_str());
      EXPECT_FALSE(r.ok()) << readings;
      EXPECT_TRUE(r.board_size_note.empty()) << readings;
    }
  }
}

// min_captures holds for the captures left once views are set aside, not
// only for those given: five captures, one of which shows the board to
// camera 1 alone in a view with every other corner slipped 2 px along the
// row (a jump far beyond any bound), was judged on four before.
// A camera loose in its mount, its rows off by a different amount in every
// capture (1, 2, ... 8 px: module 1's right camera): the rectified-row
// figure's spread term once took the captures' spread as it came, and that
// spread (per-capture mean squares 1 to 64 px^2) raised the threshold above
// the figure itself (~5 px read against ~5.6 px: "yes"). Capped at the most
// an unchanged rig's noise and calibration error allow (every error of a
// capture one shared draw: sqrt(2 / 8) of ~0.08 px^2 at 0.2 px corners), it
// stays near the noise (under 1 px) and the figure fails.
TEST(NightlyCheck, ASpreadBetweenCapturesNoNoiseExplainsDoesNotLoosenTheRowFigure) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(truth);
  const int loose = stored.module(1).right_camera;
  std::vector<BoardObservation> views = Observe(truth, target, {}, 5);
  for (BoardObservation& v : views)
    if (v.camera == loose)
      for (Eigen::Vector2d& q : v.q_px) q.y() += 1.0 + v.capture;
  const CheckResult r = RunNightlyCheck(stored, target, views, CheckOptions(), "test");
  const auto row = std::find_if(r.figures.begin(), r.figures.end(),
                                [](const CheckFigure& f) { return f.name == "module1_rectified_row_rms_px"; });
  ASSERT_NE(row, r.figures.end());
  EXPECT_GT(row->value, 3.0);  // the rows' 1-8 px offsets
  EXPECT_LT(row->threshold, 1.0) << "the captures' spread loosened the threshold";
  EXPECT_FALSE(row->pass);
  EXPECT_FALSE(r.ok());
}

// A camera knocked during the night, its last 3 of 8 captures turned 0.5 deg:
// each of those views is off the rest of its capture, and, the lower median
// of the camera's readings still the unmoved captures', each read as "taken
// at another moment" and set aside, leaving an unmoved night: "ok". A
// camera off in more than one capture is judged, not set aside.
TEST(NightlyCheck, ACameraKnockedDuringTheNightIsJudgedNotSetAsideAsFramesOfAnotherMoment) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  Bump knock;
  knock.camera = 1;
  knock.rotation_deg = 0.5;
  std::vector<BoardObservation> views;
  for (const BoardObservation& v : Observe(truth, target, {}, 6))
    if (v.capture < 5) views.push_back(v);
  for (const BoardObservation& v : Observe(truth, target, knock, 6))
    if (v.capture >= 5) views.push_back(v);
  const CheckResult r = RunNightlyCheck(StoredRig(truth), target, views, CheckOptions(), "test");
  for (const SetAsideView& aside : r.views_set_aside)
    ADD_FAILURE() << "capture " << aside.capture << " cam" << aside.camera << " set aside";
  EXPECT_FALSE(r.ok());
  ASSERT_FALSE(r.camera_changes.empty());
  EXPECT_EQ(r.camera_changes.front().camera, 1);
}

// Two captures' module-0 views taken at another moment (those of another
// capture: the two views agree with each other, so neither is set aside,
// and two such captures are judged, not set aside whole:
// OneCaptureWhoseModulesWereTakenAtDifferentMomentsIsSetAsideAndNamed),
// the rest unchanged. The closure's spread between captures once set its
// threshold (15.5 mm read against 47 mm on the demo's night: "yes"); capped
// at the most an unchanged rig lets a closure scatter (ClosureSpreadBound:
// the corners' noise and the calibration's error, here 0.2 and 0.05 px, the
// latter taken as shared by every corner of a pose) it stays at the
// noise's scale and the closure fails. The cap is an upper bound: on
// twenty unmoved nights with the same stored rig no figure fails.
TEST(NightlyCheck, AClosureSpreadNoNoiseExplainsDoesNotLoosenItsThreshold) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = WithProjectionUncertainty(StoredRig(truth), 0.05);
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const CheckResult r = RunNightlyCheck(stored, target, Observe(truth, target, {}, seed), CheckOptions(), "test");
    for (const auto& f : r.figures)
      if (!f.pass)
        ADD_FAILURE() << "unmoved, seed " << seed << ": " << f.name << " " << f.value << " > " << f.threshold;
  }
  std::vector<BoardObservation> views;
  for (const BoardObservation& v : Observe(truth, target, {}, 7)) {
    const bool module0 = ModuleOfCameraIsZero(stored, v.camera);
    if ((v.capture == 1 || v.capture == 3) && module0) continue;  // replaced by capture 6's below
    views.push_back(v);
    if (v.capture == 6 && module0)
      for (int slipped : {1, 3}) {
        views.push_back(v);
        views.back().capture = slipped;
      }
  }
  const CheckResult r = RunNightlyCheck(stored, target, views, CheckOptions(), "test");
  const auto closure = std::find_if(r.figures.begin(), r.figures.end(),
                                    [](const CheckFigure& f) { return f.name == "pair_0_1_closure_mm"; });
  ASSERT_NE(closure, r.figures.end());
  EXPECT_GT(closure->value, 1.0);  // captures 1 and 3's board poses ~tens of mm apart, over 8 captures
  EXPECT_LT(closure->threshold, 0.5) << "the captures' spread loosened the threshold";
  EXPECT_FALSE(closure->pass);
  EXPECT_FALSE(r.ok());
}

TEST(NightlyCheck, TooFewCapturesLeftOnceAViewIsSetAsideIsRefused) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  std::vector<BoardObservation> views;
  std::set<int> captures;
  for (const BoardObservation& v : Observe(truth, target, {}, 4)) {
    if (!captures.count(v.capture) && captures.size() == 5) continue;
    captures.insert(v.capture);
    views.push_back(v);
  }
  ASSERT_EQ(captures.size(), 5u);
  const int lone = *captures.rbegin();
  std::erase_if(views, [&](const BoardObservation& v) { return v.capture == lone && v.camera != 1; });
  ASSERT_EQ(std::count_if(views.begin(), views.end(), [&](const BoardObservation& v) { return v.capture == lone; }), 1);
  // Unslipped, the five captures are enough.
  EXPECT_NO_THROW(RunNightlyCheck(StoredRig(truth), target, views, CheckOptions(), "captures"));
  for (BoardObservation& v : views) {
    if (v.capture != lone) continue;
    for (size_t k = 0; k < v.q_px.size(); k += 2) v.q_px[k].x() += 2.0;
  }
  try {
    RunNightlyCheck(StoredRig(truth), target, views, CheckOptions(), "captures");
    ADD_FAILURE() << "four captures were judged";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(
        what.find("only 4 of 5 captures are left to check: capture " + std::to_string(lone) + ": cam1's corners jump "),
        std::string::npos)
        << what;
    EXPECT_NE(what.find("(set aside); the check needs 5"), std::string::npos) << what;
  }
  // Named by its folder's name where the caller gives one.
  try {
    RunNightlyCheck(StoredRig(truth), target, views, CheckOptions(), "captures", {{lone, "night-capture-x"}});
    ADD_FAILURE() << "four captures were judged";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("capture night-capture-x: cam1's"), std::string::npos) << e.what();
  }
}

// A ring of three modules 120 deg apart around the object, as
// datasets/specs/ring3.yaml (the three-module study of
// docs/verify-and-check.md): the default rig's modules 0 and 1, module 1
// turned about the world's vertical through the object to 120 deg and
// 240 deg from module 0 (cameras 2-3 and 4-5, both of module 1's lenses).
SimulatedRig RingRig() {
  const SimulatedRig two = MakeDefaultRig();
  std::vector<Camera> cameras = two.rig.cameras();
  cameras.push_back(two.rig.camera(2));
  cameras.push_back(two.rig.camera(3));
  std::vector<std::string> names;
  for (int c = 0; c < 6; ++c) names.push_back("cam" + std::to_string(c));
  const Pose right_from_left = two.rig.module(0).right_from_left;
  std::vector<StereoModule> modules = {
      {"module0", 0, 1, right_from_left}, {"module1", 2, 3, right_from_left}, {"module2", 4, 5, right_from_left}};
  std::vector<Pose> module0_from_module;
  for (double turn_deg : {0.0, 120.0, -120.0}) {
    const Pose world_from_turned(Eigen::AngleAxisd(turn_deg * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                                 Eigen::Vector3d::Zero());
    module0_from_module.push_back(two.world_from_module0.Inverse() * world_from_turned * two.world_from_module0);
  }
  return {Rig(std::move(cameras), std::move(names), std::move(modules), module0_from_module), two.world_from_module0};
}

// The board at the object, turned `turn_deg` about the world's vertical and
// `pitch_deg` about its horizontal, as the ring's true cameras see it: each
// camera the face that faces it, corners at `noise_px`, those in the image.
std::vector<BoardObservation> RingCapture(const SimulatedRig& ring, const Target& target, int capture, double turn_deg,
                                          double pitch_deg, std::mt19937& rng, double noise_px) {
  std::normal_distribution<double> noise(0, noise_px);
  const Eigen::Vector3d center((target.corners_x() - 1) * 0.5 * target.square_size_mm(),
                               (target.corners_y() - 1) * 0.5 * target.square_size_mm(), 0);
  const Eigen::Matrix3d turned = (Eigen::AngleAxisd(turn_deg * M_PI / 180, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(pitch_deg * M_PI / 180, Eigen::Vector3d::UnitX()))
                                     .toRotationMatrix();
  const Pose ref_from_front = ring.world_from_module0.Inverse() * Pose(turned, Eigen::Vector3d::Zero()) *
                              Pose(Eigen::Matrix3d::Identity(), -center);
  std::vector<BoardObservation> views;
  for (int c = 0; c < ring.rig.num_cameras(); ++c) {
    const Pose cam_from_front = ring.rig.CamFromReference(c) * ref_from_front;
    // A face's z points into the board, away from whoever looks at it.
    const Face face = cam_from_front.rotation()(2, 2) > 0 ? Face::kFront : Face::kBack;
    const Pose cam_from_face =
        face == Face::kFront ? cam_from_front : cam_from_front * target.back_from_front().Inverse();
    BoardObservation v{capture, c, face, {}, {}};
    SeeCorners(ring.rig.camera(c), cam_from_face, target, noise, rng, &v);
    if (v.corner_ids.size() >= 6) views.push_back(v);
  }
  return views;
}

// The true tilt of the board from face-on in camera c of a RingCapture
// (TiltDeg: its normal against the optical axis).
double RingTiltDeg(const SimulatedRig& ring, int c, double turn_deg, double pitch_deg) {
  const Eigen::Matrix3d turned = (Eigen::AngleAxisd(turn_deg * M_PI / 180, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(pitch_deg * M_PI / 180, Eigen::Vector3d::UnitX()))
                                     .toRotationMatrix();
  const Eigen::Matrix3d cam_from_front =
      ring.rig.CamFromReference(c).rotation() * ring.world_from_module0.rotation().transpose() * turned;
  return std::acos(std::min(1.0, std::abs(cam_from_front(2, 2)))) * 180 / M_PI;
}

// A ring night of 8 captures at the rendered corners' 0.03 px, capture k's
// board turned and pitched (deg) as `turn_pitch_deg(k, draw)` says, `draw`
// uniform in [-1, 1] from the night's seed.
using TurnPitchDeg = std::function<std::pair<double, double>(int, const std::function<double()>&)>;
std::vector<BoardObservation> RingNight(const SimulatedRig& ring, const Target& target, unsigned seed,
                                        const TurnPitchDeg& turn_pitch_deg) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const std::function<double()> draw = [&] { return u(rng); };
  std::vector<BoardObservation> views;
  for (int k = 0; k < kCaptures; ++k) {
    const auto [turn_deg, pitch_deg] = turn_pitch_deg(k, draw);
    for (const BoardObservation& v : RingCapture(ring, target, k, turn_deg, pitch_deg, rng, kRenderedNoisePx))
      views.push_back(v);
  }
  return views;
}

// An unmoved ring night (RingNight): the board turned up to 4 deg about the
// vertical and 8 deg about the horizontal from facing module 0, so modules 1
// and 2 see its back face 53-68 deg from face-on; capture 6 turned `turn6_deg`. Cam5's view of
// capture 6 shifted whole by (-0.10, -0.25) px (0.27 px): the error measured
// on the three-module ring (seed 209, nothing moved, capture 006 cam5 seen
// 80 deg from face-on: its 28 corners off the simulator's truth by 0.27 px,
// nearly all of it that one shift, docs/verify-and-check.md).
std::vector<BoardObservation> RingNightWithCam5Shifted(const SimulatedRig& ring, const Target& target, unsigned seed,
                                                       double turn6_deg) {
  std::vector<BoardObservation> views =
      RingNight(ring, target, seed, [turn6_deg](int k, const std::function<double()>& draw) {
        if (k == 6) return std::pair{turn6_deg, 0.0};
        const double turn_deg = 4 * draw();
        return std::pair{turn_deg, 8 * draw()};
      });
  for (BoardObservation& v : views)
    if (v.capture == 6 && v.camera == 5)
      for (Eigen::Vector2d& q : v.q_px) q += Eigen::Vector2d(-0.10, -0.25);
  return views;
}

// A view seen nearly edge-on whose corners share one error: such a view
// fits its own pose (which absorbs the shift) and its corners do not jump,
// so no screen of its own residuals sets it aside, and through the other
// cameras' pose the shift read as camera 5 changed (seed 209: cameras 4, 5
// and module 2 failed). Set aside, first and whole, by the board's tilt from
// face-on (at or beyond the calibration's kEdgeOnTiltDeg, 70 deg): the night
// reads ok, every view set aside one seen edge-on (cam4 and cam5 of capture
// 6, module 2's cameras 6 deg apart). The same shift where cam5 sees the
// board ~60 deg from face-on is kept and flagged, camera 5 or module 2
// named: the screen is by the tilt, not a silencer of shifted views. The
// shift is 9 times the corners' noise, and a view of ~99 corners. The tilt
// read from each set-aside view's own pose, shift and 0.03 px noise
// included, was 0.0063 deg off the truth's at most over seeds 1-5
// (measured); it is held to 0.05 deg, 8 times that.
TEST(NightlyCheck, AViewSeenEdgeOnIsSetAsideByItsTiltAndTheSameShiftFacingMoreIsFlagged) {
  const SimulatedRig ring = RingRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(ring, kRenderedNoisePx);
  // Capture 6 turned towards module 1 until cam5 sees it 80 deg from face-on
  // (module 2 then sees it edge-on, module 1 ~40 deg and module 0 ~20 deg).
  double edge_on_turn_deg = 0;
  while (RingTiltDeg(ring, 5, edge_on_turn_deg, 0) < 80) edge_on_turn_deg -= 0.1;
  ASSERT_GT(edge_on_turn_deg, -30);
  ASSERT_GE(RingTiltDeg(ring, 4, edge_on_turn_deg, 0), 70.5) << "module 2's cameras both edge-on";
  ASSERT_LT(RingTiltDeg(ring, 3, edge_on_turn_deg, 0), 65) << "module 1 not";
  const double facing_turn_deg = 0;
  const double facing_tilt_deg = RingTiltDeg(ring, 5, facing_turn_deg, 0);
  ASSERT_NEAR(facing_tilt_deg, 60, 4);
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const CheckResult edge_on = RunNightlyCheck(
        stored, target, RingNightWithCam5Shifted(ring, target, seed, edge_on_turn_deg), CheckOptions(), "test");
    EXPECT_EQ(edge_on.Verdict(), "ok") << "seed " << seed << ": " << edge_on.Explanation();
    std::set<int> cameras_set_aside;
    for (const SetAsideView& v : edge_on.views_set_aside) {
      EXPECT_EQ(v.why, SetAsideWhy::kEdgeOn) << "seed " << seed << ": capture " << v.capture << " cam" << v.camera;
      EXPECT_EQ(v.capture, 6) << "seed " << seed << " cam" << v.camera;
      EXPECT_NEAR(v.tilt_deg, RingTiltDeg(ring, v.camera, edge_on_turn_deg, 0), 0.05) << "seed " << seed;
      cameras_set_aside.insert(v.camera);
    }
    EXPECT_EQ(cameras_set_aside, (std::set<int>{4, 5})) << "seed " << seed;

    const CheckResult facing = RunNightlyCheck(
        stored, target, RingNightWithCam5Shifted(ring, target, seed, facing_turn_deg), CheckOptions(), "test");
    EXPECT_TRUE(facing.views_set_aside.empty()) << "seed " << seed << ": " << facing.views_set_aside.size();
    EXPECT_EQ(facing.Verdict(), "recalibrate") << "seed " << seed;
    const std::vector<int> cameras = facing.FlaggedCameras(), modules = facing.FlaggedModules();
    EXPECT_TRUE(std::count(cameras.begin(), cameras.end(), 5) || std::count(modules.begin(), modules.end(), 2))
        << "seed " << seed << ": " << facing.Explanation();
  }
}

// A camera that sees the board only edge-on tonight has no view left: it is
// refused as a camera with no view is (the check cannot tell whether it
// moved), saying its views went for the board's tilt and how to capture.
// The premise, from the truth: cameras 4 and 5 see the board 70 deg or more
// from face-on in every capture.
TEST(NightlyCheck, ACameraThatSeesTheBoardOnlyEdgeOnIsRefusedAsOneWithNoView) {
  const SimulatedRig ring = RingRig();
  const Target target = DefaultTarget();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<BoardObservation> views;
  for (int k = 0; k < kCaptures; ++k) {
    const double pitch_deg = 4 * u(rng), turn_deg = -22 + 2 * u(rng);
    for (const int c : {4, 5})
      ASSERT_GE(RingTiltDeg(ring, c, turn_deg, pitch_deg), 70) << "capture " << k << " cam" << c;
    for (const BoardObservation& v : RingCapture(ring, target, k, turn_deg, pitch_deg, rng, kRenderedNoisePx))
      views.push_back(v);
  }
  try {
    RunNightlyCheck(StoredRig(ring, kRenderedNoisePx), target, views, CheckOptions(), "captures");
    ADD_FAILURE() << "judged with cameras 4 and 5 unchecked";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("camera(s) 4, 5 saw the board in no capture where another camera saw it too "
                                         "(16 of their views were set aside: the board seen 70 deg or more from "
                                         "face-on), so the check cannot tell whether they moved: take captures that "
                                         "show the board to every camera with another one, turned less than 70 deg "
                                         "from facing it"),
              std::string::npos)
        << e.what();
  }
}

// `ring` with module `m` (not 0, whose frame is the reference) moved
// `shift_mm` in module 0's frame, both its cameras together.
SimulatedRig RingWithModuleShifted(const SimulatedRig& ring, int m, const Eigen::Vector3d& shift_mm) {
  std::vector<Pose> module0_from_module;
  for (int k = 0; k < ring.rig.num_modules(); ++k)
    module0_from_module.push_back(k == m ? Pose(Eigen::Matrix3d::Identity(), shift_mm) * ring.rig.S(0, k)
                                         : ring.rig.S(0, k));
  return {Rig(ring.rig.cameras(), ring.rig.camera_names(), ring.rig.modules(), module0_from_module),
          ring.world_from_module0};
}

// A ring night as the ring study's simulator draws its captures
// (datasets/calibration_poses.cc, ring3.yaml's tilt_max_deg 40): the board
// at the object turned about the vertical and the horizontal by a draw
// uniform over the disc of 40 deg. Facing module 0 the side modules see it
// 60 deg from face-on, so turned ~10 deg towards one side the other sees it
// past 70 deg (set aside): the two side modules see it together in few
// captures.
std::vector<BoardObservation> StudyRingNight(const SimulatedRig& ring, const Target& target, unsigned seed) {
  return RingNight(ring, target, seed, [](int, const std::function<double()>& draw) {
    double turn, pitch;
    do {
      turn = draw(), pitch = draw();
    } while (turn * turn + pitch * pitch > 1);
    return std::pair{40 * turn, 40 * pitch};
  });
}

// A side module of the ring shifted 0.1 mm (issue 6's module bump, the ring
// study's module:1 and module:2) on 10 nights: its closure with module 0
// fails, module 0's with the other side module holds, and the side modules'
// pair is not judged on some nights (3 of 10 for each here: too few captures
// see the board under 70 deg from both). Named alone only where it was in
// two failing pairs, the
// shifted module read "module 0 and module 1 disagree" (or 2) on the others:
// on 3 of 10 nights each before. Named alone now on every night: module 0
// agrees with the third module, whose pair with the shifted one is not
// judged. Never another module alone; unshifted, the same nights read ok.
// The shift is 5-25 times a closure's threshold here (0.03 px corners:
// thresholds of 4-20 um), so no night hangs on the noise.
TEST(NightlyCheck, ARingsShiftedSideModuleIsNamedAloneWhereItsPairWithTheOtherSideIsNotJudged) {
  const SimulatedRig ring = RingRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(ring, kRenderedNoisePx);
  constexpr unsigned kNights = 10;
  for (int module : {1, 2}) {
    int flagged = 0, alone = 0, side_pair_judged = 0;
    for (unsigned seed = 1; seed <= kNights; ++seed) {
      std::mt19937 rng(1000 + seed);
      std::uniform_real_distribution<double> u(-1, 1);
      const Eigen::Vector3d shift_mm = 0.1 * Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      const CheckResult r =
          RunNightlyCheck(stored, target, StudyRingNight(RingWithModuleShifted(ring, module, shift_mm), target, seed),
                          CheckOptions(), "test");
      flagged += !r.ok();
      const bool named_alone = r.closure_modules == std::vector<int>{module} && !r.closure_which_unknown;
      alone += named_alone;
      for (const CheckFigure& f : r.figures) side_pair_judged += f.name == "pair_1_2_closure_mm";
      const std::vector<int> modules = r.FlaggedModules();
      EXPECT_TRUE(std::count(modules.begin(), modules.end(), module)) << "seed " << seed << ": " << r.Explanation();
      EXPECT_TRUE(named_alone || r.closure_which_unknown) << "seed " << seed << ": " << r.Explanation();
      if (!named_alone) std::printf("module %d seed %u: %s\n", module, seed, r.Explanation().c_str());
      if (module == 1) {
        const CheckResult unmoved =
            RunNightlyCheck(stored, target, StudyRingNight(ring, target, seed), CheckOptions(), "test");
        EXPECT_TRUE(unmoved.ok()) << "seed " << seed << ": " << unmoved.Explanation();
      }
    }
    std::printf("module %d shifted: flagged %d/%u, named alone %d/%u, side pair judged on %d\n", module, flagged,
                kNights, alone, kNights, side_pair_judged);
    EXPECT_EQ(flagged, static_cast<int>(kNights)) << "module " << module;
    EXPECT_EQ(alone, static_cast<int>(kNights)) << "module " << module;
    // Some nights leave the side pair unjudged, or the rule is not exercised.
    EXPECT_LT(side_pair_judged, static_cast<int>(kNights)) << "module " << module;
  }
}

// Views with cameras a and b exchanged in the captures `swapped` says.
std::vector<BoardObservation> Exchanged(std::vector<BoardObservation> views, int a, int b,
                                        const std::function<bool(int)>& swapped) {
  for (BoardObservation& v : views)
    if (swapped(v.capture) && (v.camera == a || v.camera == b)) v.camera = v.camera == a ? b : a;
  return views;
}

// Two cameras' images exchanged in every capture (cables or folders mixed
// up): within a module, the night read "camera 0 changed: neither a new pose
// nor a new lens alone explains", camera 1 not named, and across modules
// "captures of another rig". Refused as bad input, naming the swap.
TEST(NightlyCheck, TwoCamerasWhoseImagesAreExchangedAreNamedAsSwapped) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const std::vector<BoardObservation> views = Observe(truth, target, {}, 3);
  for (auto [a, b] : {std::pair{0, 1}, std::pair{0, 2}}) {
    try {
      RunNightlyCheck(StoredRig(truth), target, Exchanged(views, a, b, [](int) { return true; }), CheckOptions(),
                      "captures");
      ADD_FAILURE() << "cam" << a << " and cam" << b << " exchanged: judged";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("cam" + std::to_string(a) + " and cam" + std::to_string(b) +
                          " look swapped: each matches the other's calibration"),
                std::string::npos)
          << what;
    }
  }
  // Unexchanged, nothing is said of a swap.
  EXPECT_TRUE(RunNightlyCheck(StoredRig(truth), target, views, CheckOptions(), "captures").ok());
}

// A module whose board pose is rubbish: module 0's cameras exchanged in half
// the captures (too few for a swap: the other half fit as given), which puts
// its board poses there far off, with a covariance to match. The closure's
// spread cap was evaluated at each module's own pose, so there it capped
// nothing (the demo's night, swapped throughout: 1108.8 mm, and 5.84 deg
// passed against 15.97 deg). Evaluated where the board is (either module's
// pose, the smaller), it stays at the noise's scale: at 0.2 px corners and
// 0.05 px of calibration error, under 0.5 mm and 0.5 deg (as in
// AClosureSpreadNoNoiseExplainsDoesNotLoosenItsThreshold), and both fail.
TEST(NightlyCheck, AModuleWhosePoseIsRubbishDoesNotLoosenTheClosure) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = WithProjectionUncertainty(StoredRig(truth), 0.05);
  const std::vector<BoardObservation> views =
      Exchanged(Observe(truth, target, {}, 3), 0, 1, [](int capture) { return capture % 2 == 0; });
  const CheckResult r = RunNightlyCheck(stored, target, views, CheckOptions(), "test");
  for (const char* name : {"pair_0_1_closure_mm", "pair_0_1_closure_deg"}) {
    const auto f =
        std::find_if(r.figures.begin(), r.figures.end(), [&](const CheckFigure& x) { return x.name == name; });
    ASSERT_NE(f, r.figures.end()) << name;
    EXPECT_LT(f->threshold, 0.5) << name << ": the rubbish poses loosened the threshold";
    EXPECT_FALSE(f->pass) << name << " " << f->value << " within " << f->threshold;
  }
}

// A trigger or sync slip: one capture's module-0 views are those of another
// capture (they agree with each other, so the view test sets neither
// aside). The night read "module 0 and module 1 disagree" with no capture
// named; the capture is set aside whole (which module slipped two modules
// cannot tell), each of its views named, and the unmoved rig reads ok. A
// module shifted 0.1 mm is off in every capture, and still fails with
// nothing set aside.
TEST(NightlyCheck, OneCaptureWhoseModulesWereTakenAtDifferentMomentsIsSetAsideAndNamed) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(truth);
  auto slipped = [&](const std::vector<BoardObservation>& night) {
    std::vector<BoardObservation> views;
    for (const BoardObservation& v : night) {
      const bool module0 = ModuleOfCameraIsZero(stored, v.camera);
      if (v.capture == 2 && module0) continue;  // replaced by capture 5's below
      views.push_back(v);
      if (v.capture == 5 && module0) {
        views.push_back(v);
        views.back().capture = 2;
      }
    }
    return views;
  };
  const CheckResult r = RunNightlyCheck(stored, target, slipped(Observe(truth, target, {}, 8)), CheckOptions(), "test");
  std::set<int> cameras;
  for (const SetAsideView& aside : r.views_set_aside) {
    EXPECT_EQ(aside.capture, 2);
    EXPECT_EQ(aside.why, SetAsideWhy::kOtherMoment);
    EXPECT_EQ(aside.whole_capture, WholeCapture::kModulesDisagree);
    EXPECT_GT(aside.off_px, aside.bound_px);
    cameras.insert(aside.camera);
  }
  EXPECT_EQ(cameras, (std::set<int>{0, 1, 2, 3}));
  EXPECT_TRUE(r.ok()) << r.Explanation();
  Bump shifted;
  shifted.module = 1;
  shifted.translation_mm = 0.1;
  const CheckResult moved = RunNightlyCheck(stored, target, Observe(truth, target, shifted, 8), CheckOptions(), "test");
  EXPECT_TRUE(moved.views_set_aside.empty());
  EXPECT_FALSE(moved.ok());
}

// A slip in a capture of three views: module 0's pair from capture 5, module
// 1's second view lost (too few corners, as a view at the image's edge is).
// cam2 read as off its capture, the two other views agreeing with each
// other, and cam2 alone was set aside: a good view named, the slipped pair
// judged with the night. Two views of one module, triggered together, are
// one witness against the lone camera: which was taken at another moment
// the capture cannot tell, so it goes whole, said as either. A lone
// camera's slip, cam0's image from capture 5 beside cam1 and cam2, is
// decided by views of both modules: cam0 alone goes. Every reading is
// hundreds of px (another board pose) against bounds of ten times the 0.2 px
// noise, so neither outcome hangs on the noise.
TEST(NightlyCheck, ASlipInACaptureOfThreeViewsIsNotBlamedOnTheLoneModulesCamera) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(truth);
  const std::vector<BoardObservation> night = Observe(truth, target, {}, 8);
  // Capture 2 without cam3, its `slipped` cameras' views capture 5's.
  auto three_views = [&](const std::set<int>& slipped) {
    std::vector<BoardObservation> views;
    for (const BoardObservation& v : night) {
      if (v.capture == 2 && (v.camera == 3 || slipped.count(v.camera))) continue;
      views.push_back(v);
      if (v.capture == 5 && slipped.count(v.camera)) {
        views.push_back(v);
        views.back().capture = 2;
      }
    }
    int in_capture_2 = 0;
    for (const BoardObservation& v : views) in_capture_2 += v.capture == 2;
    EXPECT_EQ(in_capture_2, 3);
    return views;
  };
  const CheckResult pair = RunNightlyCheck(stored, target, three_views({0, 1}), CheckOptions(), "test");
  std::set<int> cameras;
  for (const SetAsideView& aside : pair.views_set_aside) {
    EXPECT_EQ(aside.capture, 2);
    EXPECT_EQ(aside.whole_capture, WholeCapture::kViewOrModule);
    EXPECT_EQ(aside.lone_camera, 2);
    EXPECT_EQ(aside.other_module, 0);
    cameras.insert(aside.camera);
  }
  EXPECT_EQ(cameras, (std::set<int>{0, 1, 2}));
  ASSERT_FALSE(pair.views_set_aside.empty());
  EXPECT_NE(WholeCaptureText(pair.views_set_aside[0]).find("cam2 is off module 0's views by "), std::string::npos)
      << WholeCaptureText(pair.views_set_aside[0]);
  EXPECT_TRUE(pair.ok()) << pair.Explanation();
  const CheckResult lone = RunNightlyCheck(stored, target, three_views({0}), CheckOptions(), "test");
  ASSERT_EQ(lone.views_set_aside.size(), 1u);
  EXPECT_EQ(lone.views_set_aside[0].capture, 2);
  EXPECT_EQ(lone.views_set_aside[0].camera, 0);
  EXPECT_EQ(lone.views_set_aside[0].whole_capture, WholeCapture::kNo);
  EXPECT_TRUE(lone.ok()) << lone.Explanation();
}

// The slip of a capture of three views where the capture had four, its
// fourth set aside first for its corners' jumps (cam3, every other corner
// 2 px along the row: a jump far beyond any bound). Refused for too few
// captures, the capture lost was said by cam3's jump alone: the whole
// capture's reason was added only where its entry was the capture's first.
TEST(NightlyCheck, ACaptureGoneWholeAfterAViewOfItsJumpedIsSaidWithBoth) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(truth);
  std::vector<BoardObservation> views;
  for (const BoardObservation& v : Observe(truth, target, {}, 8)) {
    const bool module0 = ModuleOfCameraIsZero(stored, v.camera);
    if (v.capture == 2 && module0) continue;  // capture 5's below
    views.push_back(v);
    if (v.capture == 2 && v.camera == 3)
      for (size_t k = 0; k < views.back().q_px.size(); k += 2) views.back().q_px[k].x() += 2.0;
    if (v.capture == 5 && module0) {
      views.push_back(v);
      views.back().capture = 2;
    }
  }
  ASSERT_EQ(std::count_if(views.begin(), views.end(), [](const BoardObservation& v) { return v.capture == 2; }), 4);
  const CheckResult r = RunNightlyCheck(stored, target, views, CheckOptions(), "test");
  ASSERT_EQ(r.views_set_aside.size(), 4u);
  EXPECT_EQ(r.views_set_aside[0].camera, 3);
  EXPECT_EQ(r.views_set_aside[0].why, SetAsideWhy::kCornersJump);
  for (size_t k = 1; k < r.views_set_aside.size(); ++k)
    EXPECT_EQ(r.views_set_aside[k].whole_capture, WholeCapture::kViewOrModule) << k;
  CheckOptions all_needed;
  all_needed.min_captures = 8;
  try {
    RunNightlyCheck(stored, target, views, all_needed, "captures");
    ADD_FAILURE() << "seven captures were judged";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("only 7 of 8 captures are left to check: capture 2: cam3's corners jump "), std::string::npos)
        << what;
    EXPECT_NE(what.find(", its other views: cam2 is off module 0's views by "), std::string::npos) << what;
    EXPECT_NE(what.find("(set aside); the check needs 8"), std::string::npos) << what;
  }
}

// Both cameras of module 1 moved, 0.15 mm each in opposite directions (its
// baseline stretched or squeezed): only the worse of the two was named
// ("camera 3 changed: neither ...", read against poses that camera 2's own
// move spoiled), camera 2 not. Each is named, and each read against the
// cameras not named (module 0's) is a motion of its 0.15 mm: through
// 0.03 px corners (the rendered corners' noise) a shift reads to a few
// hundredths of a mm, within 0.05 mm here.
TEST(NightlyCheck, BothCamerasOfAModuleThatMovedAreNamed) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  Bump stretched;
  stretched.shifted_camera = truth.rig.module(1).left_camera;
  stretched.opposite_camera = truth.rig.module(1).right_camera;
  stretched.translation_mm = 0.15;
  const CheckResult r = RunNightlyCheck(StoredRig(truth, kRenderedNoisePx), target,
                                        Observe(truth, target, stretched, 9, kRenderedNoisePx), CheckOptions(), "test");
  EXPECT_FALSE(r.ok());
  std::vector<int> cameras = r.FlaggedCameras();
  std::sort(cameras.begin(), cameras.end());
  EXPECT_EQ(cameras, (std::vector<int>{2, 3})) << r.Explanation();
  for (const CameraChange& c : r.camera_changes) {
    EXPECT_TRUE(c.kind == CameraChangeKind::kMoved || c.kind == CameraChangeKind::kMovedOrLens) << c.Describe();
    EXPECT_NEAR(c.shifted_mm, 0.15, 0.05) << c.Describe();
  }
}

// Module 1 shifted 0.5 mm while camera 0's principal point moved +1 px:
// module 0's cameras disagree with each other (the lens), so its closure
// was not judged, and each was read against module 1 alone: cameras 0 and
// 1 "moved" about 0.5 mm, camera 1 unchanged, the modules' offset unnamed.
// One shift of module 0 and its lenses explain both, the lenses alone do
// not: the pair is named, the shift given, and camera 0's lens alone. A
// module's two cameras moved apart (its baseline stretched) is no shift of
// the module: both still named as moved. At 0.03 px corners (the rendered
// corners' noise) a shift and a principal point read to a few thousandths:
// held to a tenth.
TEST(NightlyCheck, AModuleShiftedBesidesALensOfTheOtherIsNamedWithTheLens) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(truth, kRenderedNoisePx);
  Bump bump;
  bump.module = 1;
  bump.translation_mm = 0.5;
  bump.camera = 0;
  bump.lens.principal_point_px = {1, 0};
  for (unsigned seed : {11u, 12u}) {
    const CheckResult r =
        RunNightlyCheck(stored, target, Observe(truth, target, bump, seed, kRenderedNoisePx), CheckOptions(), "test");
    EXPECT_FALSE(r.ok());
    EXPECT_EQ(r.FlaggedCameras(), (std::vector<int>{0})) << r.Explanation();
    EXPECT_EQ(r.closure_modules, (std::vector<int>{0, 1})) << r.Explanation();
    ASSERT_EQ(r.module_shifts.size(), 1u) << r.Explanation();
    EXPECT_EQ(r.module_shifts[0].module, 0);
    EXPECT_NEAR(r.module_shifts[0].shift_mm.norm(), 0.5, 0.05) << r.Explanation();
    // Module 1 moved: with two modules the shift is module 0's against
    // module 1, which moved not told.
    EXPECT_EQ(r.module_shifts[0].relative_to, (std::vector<int>{1}));
    EXPECT_TRUE(r.module_shifts[0].which_unknown);
    ASSERT_EQ(r.camera_changes.size(), 1u) << r.Explanation();
    // A principal point's shift reads, to first order, as a turn: "lens"
    // or "either", never "moved" alone nor "neither".
    EXPECT_TRUE(r.camera_changes[0].kind == CameraChangeKind::kLens ||
                r.camera_changes[0].kind == CameraChangeKind::kMovedOrLens)
        << r.Explanation();
    EXPECT_NEAR(r.camera_changes[0].principal_point_px.x(), 1, 0.1) << r.Explanation();
    EXPECT_NE(r.Explanation().find("module 0 and module 1 disagree"), std::string::npos) << r.Explanation();
  }
}

// `truth` with every translation (each baseline, S) scaled by `scale`: the
// rig's scale changed, its lenses and turns as they were.
SimulatedRig Scaled(const SimulatedRig& truth, double scale) {
  std::vector<StereoModule> modules = truth.rig.modules();
  for (StereoModule& m : modules)
    m.right_from_left = Pose(m.right_from_left.rotation(), scale * m.right_from_left.translation_mm());
  std::vector<Pose> module0_from_module;
  for (int m = 0; m < truth.rig.num_modules(); ++m)
    module0_from_module.push_back(Pose(truth.rig.S(0, m).rotation(), scale * truth.rig.S(0, m).translation_mm()));
  return {Rig(truth.rig.cameras(), truth.rig.camera_names(), modules, module0_from_module), truth.world_from_module0};
}

// Every camera's focal length +0.1 % (thermal drift): no camera is left
// unchanged to read the others against, and the verdict named the worse
// camera of each module, "neither", as if the others had not changed (with
// a note after them). One change shared by every camera explains the
// night: said so, with its size, and no camera named alone. Every
// principal point +0.5 px alike named cameras 0 and 1 "moved" 0.2 mm; +1 px
// alike reads as the shared change too, on each of seeds 1-12 (measured:
// the fit's x within 0.0007 px of +1, its y within 0.014 px of 0). +0.5 px
// alike does not, reliably: to first order it is a turn of each module as
// a whole, its own cameras agreeing but by a hair, and it read as the
// shared change on 6 of seeds 1-12, "module 0 and module 1 disagree" on
// the others (the audit's count). The rig's scale, every baseline and S
// 0.2 % longer, read cameras "neither" (the board measured -0.2 %, under
// the board-size note's 0.5 %): said as the rig's scale against the
// board's. Each drift fails every camera's figure by far (0.1 % is ~0.2 px
// over the board against 0.03 px corners), so this does not hang on the
// noise. The focal change is held to a tenth of the drift, where ~400
// corners a camera at 0.03 px fix a focal factor to ~1e-5; the principal
// point, which those corners fix to ~0.003 px, to 0.01 px in x (3 times
// that) and 0.03 px in y (twice the 0.014 px seen over seeds 1-12, more
// than the corners alone explain). One camera's drift, or a module
// shifted, is not a shared change: named as before.
TEST(NightlyCheck, EveryLensDriftedAlikeIsSaidNotNamedAsTwoCameras) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig stored = StoredRig(truth, kRenderedNoisePx);
  Bump thermal;
  thermal.every_lens = true;
  thermal.lens.focal_percent = 0.1;
  const CheckResult r =
      RunNightlyCheck(stored, target, Observe(truth, target, thermal, 10, kRenderedNoisePx), CheckOptions(), "test");
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.shared_lens_explains) << r.Explanation();
  EXPECT_NEAR(r.shared_lens_change.focal_percent, 0.1, 0.01) << r.Explanation();
  EXPECT_TRUE(r.camera_changes.empty()) << r.Explanation();
  EXPECT_EQ(r.FlaggedCameras(), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_TRUE(r.FlaggedModules().empty()) << r.Explanation();
  EXPECT_EQ(r.Explanation().find("every camera's lens changed alike: focal length +0.1"), 0u) << r.Explanation();
  EXPECT_EQ(r.Explanation().find("neither"), std::string::npos) << r.Explanation();

  Bump principal;
  principal.every_lens = true;
  principal.lens.principal_point_px = {1.0, 0};
  const CheckResult pp =
      RunNightlyCheck(stored, target, Observe(truth, target, principal, 10, kRenderedNoisePx), CheckOptions(), "test");
  EXPECT_FALSE(pp.ok());
  EXPECT_TRUE(pp.shared_lens_explains) << pp.Explanation();
  EXPECT_NEAR(pp.shared_lens_change.principal_point_px.x(), 1.0, 0.01) << pp.Explanation();
  EXPECT_NEAR(pp.shared_lens_change.principal_point_px.y(), 0.0, 0.03) << pp.Explanation();
  EXPECT_TRUE(pp.camera_changes.empty()) << pp.Explanation();

  const CheckResult scaled = RunNightlyCheck(
      stored, target, Observe(Scaled(truth, 1.002), target, {}, 10, kRenderedNoisePx), CheckOptions(), "test");
  EXPECT_FALSE(scaled.ok());
  EXPECT_FALSE(scaled.shared_lens_explains) << scaled.Explanation();
  EXPECT_TRUE(scaled.shared_scale_explains) << scaled.Explanation();
  EXPECT_NEAR(scaled.shared_scale, 1 / 1.002, 0.0002) << scaled.Explanation();
  EXPECT_TRUE(scaled.camera_changes.empty()) << scaled.Explanation();
  EXPECT_EQ(scaled.FlaggedModules(), (std::vector<int>{0, 1})) << scaled.Explanation();
  EXPECT_EQ(scaled.Explanation().find("the rig's scale against the board's changed: every module measures the board "
                                      "0.2"),
            0u)
      << scaled.Explanation();

  // One camera's drift leaves the others to read it against.
  Bump one;
  one.camera = 2;
  one.lens.focal_percent = 0.1;
  const CheckResult named =
      RunNightlyCheck(stored, target, Observe(truth, target, one, 10, kRenderedNoisePx), CheckOptions(), "test");
  EXPECT_FALSE(named.every_camera_fails) << named.Explanation();
  EXPECT_FALSE(named.shared_lens_explains || named.shared_scale_explains) << named.Explanation();
  EXPECT_EQ(named.FlaggedCameras(), (std::vector<int>{2})) << named.Explanation();
  Bump shifted;
  shifted.module = 1;
  shifted.translation_mm = 0.1;
  const CheckResult moved =
      RunNightlyCheck(stored, target, Observe(truth, target, shifted, 10, kRenderedNoisePx), CheckOptions(), "test");
  EXPECT_FALSE(moved.shared_lens_explains || moved.shared_scale_explains) << moved.Explanation();
  EXPECT_EQ(moved.closure_modules, (std::vector<int>{0, 1})) << moved.Explanation();
}

// A board printed 0.3 % large, as the simulator prints one (each face's
// print scaled about its first inner corner, back_from_front as the file
// says), seen by the unmoved rig and judged against the file. The board as
// a solid put the back face 0.27 mm off the print and two unmoved cameras
// were named "neither"; with the faces' prints scaled alone every figure
// holds: the board's print, no camera named. 0.3 % is ~0.6 px over the
// board against 0.03 px corners, far beyond the noise; the fitted size is
// held to a tenth of the error (the modules' reading scatters ~0.02 %).
TEST(NightlyCheck, ABoardPrintedOffItsFileIsSaidAsItsPrintNotAsCameras) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target file = DefaultTarget();
  Target::Layout layout = file.layout();
  constexpr double kPrint = 1.003;
  layout.square_size_mm *= kPrint;
  layout.margin_mm *= kPrint;
  layout.tag_size_mm *= kPrint;
  for (TargetFace& face : layout.faces)
    for (TagPlacement& tag : face.tags) tag.center_x_mm *= kPrint, tag.center_y_mm *= kPrint;
  const Target printed(layout, "printed");
  const Rig stored = StoredRig(truth, kRenderedNoisePx);
  for (unsigned seed : {10u, 11u, 12u}) {
    const CheckResult r =
        RunNightlyCheck(stored, file, Observe(truth, printed, {}, seed, kRenderedNoisePx), CheckOptions(), "test");
    EXPECT_FALSE(r.ok()) << seed;
    EXPECT_TRUE(r.shared_scale_explains) << seed << ": " << r.Explanation();
    EXPECT_TRUE(r.shared_scale_print_only) << seed << ": " << r.Explanation();
    EXPECT_NEAR(r.shared_scale, kPrint, 0.0003) << seed << ": " << r.Explanation();
    EXPECT_TRUE(r.camera_changes.empty()) << seed << ": " << r.Explanation();
    // No module named: recalibrated against the file, every baseline and S
    // would take the print's error.
    EXPECT_TRUE(r.FlaggedModules().empty()) << seed << ": " << r.Explanation();
    EXPECT_TRUE(r.FlaggedCameras().empty()) << seed << ": " << r.Explanation();
    EXPECT_EQ(r.Explanation().find("the board's print is not its file's size"), 0u) << seed << ": " << r.Explanation();
    EXPECT_NE(r.Explanation().find("the rig's scale unchecked (measure the board"), std::string::npos)
        << seed << ": " << r.Explanation();
  }
}

// The rig's scale changed 0.3 % (every baseline and S) and the plate
// 15 um thicker than its file (5 mm x 0.3 %, within a plate's file's 0.01 mm
// sigma per axis, 1.5 of them): the board as a solid misses the night by
// its thickness alone, 15 um against closure thresholds of 3.5-12 um, and
// the same print on a plate scaled in its plane, thick as the file says,
// explains it. Read "the board's print is not its file's size", the night
// would have told a user not to recalibrate a rig whose scale changed: the
// in-plane print is the rig's scale's reading, "cannot tell which".
TEST(NightlyCheck, ARigScaleChangeTheSolidMissesByAHairIsNotSaidAsTheBoardsPrint) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target file = DefaultTarget();
  constexpr double kRigScale = 1.003;
  Target::Layout layout = file.layout();
  layout.back_from_front = IdealBackFromFront(layout.corners_x, layout.square_size_mm, 5.0 * kRigScale);
  const Target thicker(layout, "thicker");
  const Rig stored = StoredRig(truth, kRenderedNoisePx);
  const CheckResult r = RunNightlyCheck(
      stored, file, Observe(Scaled(truth, kRigScale), thicker, {}, 10, kRenderedNoisePx), CheckOptions(), "test");
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.shared_scale_explains) << r.Explanation();
  EXPECT_FALSE(r.shared_scale_print_only) << r.Explanation();
  EXPECT_EQ(r.Explanation().find("the rig's scale against the board's changed"), 0u) << r.Explanation();
  EXPECT_NE(r.Explanation().find("it cannot tell which"), std::string::npos) << r.Explanation();
  EXPECT_EQ(r.FlaggedModules(), (std::vector<int>{0, 1})) << r.Explanation();
}

// The consistency figures' statistics for a view predicted through a weak
// pose (board_pose.h): module 0's cam1 sees the board's first three rows (33
// corners), cam0 all of it, read through cam1's pose (as seed 1016 of the
// rendered nights: 99 corners through a 31-corner pose). The pose errs by
// two independent sources (tonight's noise, the calibration's error), each
// a noise on cam1's corners: drawn here as one noise of their summed
// variance. 20 000 draws of the sum of squares of cam0's prediction errors:
// its mean and variance are the statistics' (within 4 standard errors; the
// variance's own from the draws' fourth moment: 1.06 px^4 against 1.05),
// where the two sources' variances added as sums of their own, as the check
// did, read 0.61 px^4.
TEST(NightlyCheck, AWeakPosesPredictionErrorHasTheVarianceOfItsSourcesAddedInThePose) {
  const SimulatedRig truth = MakeDefaultRig();
  const Target target = DefaultTarget();
  const Rig& rig = truth.rig;
  const Eigen::Vector3d center((target.corners_x() - 1) * 0.5 * target.square_size_mm(),
                               (target.corners_y() - 1) * 0.5 * target.square_size_mm(), 0);
  const Pose ref_from_front = truth.world_from_module0.Inverse() *
                              Pose::FromRotationVector(Eigen::Vector3d(0.2, -0.15, 0.1), Eigen::Vector3d(5, -5, 0)) *
                              Pose(Eigen::Matrix3d::Identity(), -center);
  auto ideal = [&](int c, int rows) {
    BoardObservation v{0, c, Face::kFront, {}, {}};
    const Pose cam_from_front = rig.CamFromReference(c) * ref_from_front;
    for (int id = 0; id < rows * target.corners_x(); ++id) {
      v.corner_ids.push_back(id);
      v.q_px.push_back(rig.camera(c).Project(cam_from_front * target.CornerInFace(id)));
    }
    return v;
  };
  const BoardObservation pose_view = ideal(1, 3), view = ideal(0, target.corners_y());
  const double tonight_px = 0.03, calibration_px = 0.02, view_px = 0.03;
  const int n = static_cast<int>(view.corner_ids.size());
  const std::vector<double> tonight(rig.num_cameras(), tonight_px), calibration(rig.num_cameras(), calibration_px);
  const PredictionStatistics expected = ViewPredictionStatistics(
      n, view_px, PredictionErrorStatistics(rig, target, {&pose_view}, {tonight, calibration}, view, ref_from_front));
  // As the check summed them before: each source's sum of squares alone.
  const PredictionStatistics t = PredictionErrorStatistics(rig, target, {&pose_view}, {tonight}, view, ref_from_front);
  const PredictionStatistics c =
      PredictionErrorStatistics(rig, target, {&pose_view}, {calibration}, view, ref_from_front);
  const double summed_var = 2 * n * 2 * std::pow(view_px, 4) + t.var_ss_px4 + c.var_ss_px4 +
                            4 * view_px * view_px * (t.mean_ss_px2 + c.mean_ss_px2);

  std::mt19937 rng(7);
  std::normal_distribution<double> pose_noise(0, std::hypot(tonight_px, calibration_px)), noise(0, view_px);
  const int draws = 20000;
  std::vector<double> ss_drawn;
  for (int d = 0; d < draws; ++d) {
    BoardObservation p = pose_view, v = view;
    for (Eigen::Vector2d& q : p.q_px) q += Eigen::Vector2d(pose_noise(rng), pose_noise(rng));
    for (Eigen::Vector2d& q : v.q_px) q += Eigen::Vector2d(noise(rng), noise(rng));
    const BoardPoseEstimate fit = EstimateBoardPose(rig, target, {&p}, &ref_from_front);
    ASSERT_TRUE(fit.ok);
    double ss = 0;
    for (const Eigen::Vector2d& e : ReprojectionErrors(rig, target, v, fit.ref_from_front)) ss += e.squaredNorm();
    ss_drawn.push_back(ss);
  }
  double mean = 0, sum2 = 0, sum4 = 0;
  for (double ss : ss_drawn) mean += ss / draws;
  for (double ss : ss_drawn) sum2 += std::pow(ss - mean, 2), sum4 += std::pow(ss - mean, 4);
  const double var = sum2 / (draws - 1), var_se = std::sqrt((sum4 / draws - var * var) / draws);
  EXPECT_NEAR(mean, expected.mean_ss_px2, 4 * std::sqrt(var / draws));
  EXPECT_NEAR(var, expected.var_ss_px4, 4 * var_se);
  EXPECT_LT(summed_var, var - 4 * var_se);
}

// Two views of one capture left open (knocked in the last capture, or two
// images of another moment): the verdict gives each its own figure. It
// printed the first view's for both ("capture 007 cam1, cam2 is off ... by
// 1.300 px").
TEST(NightlyCheck, TwoOpenViewsOfOneCaptureEachGiveTheirOwnFigure) {
  CheckResult r;
  SetAsideView a;
  a.capture = 7, a.camera = 1, a.why = SetAsideWhy::kOtherMoment, a.off_px = 1.3, a.bound_px = 0.29;
  a.left_open = true, a.capture_name = "007";
  SetAsideView b = a;
  b.camera = 2, b.off_px = 4.27, b.bound_px = 0.31;
  r.views_set_aside = {a, b};
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.Verdict(), "recapture");
  const std::string text = r.Explanation();
  EXPECT_NE(text.find("capture 007: cam1 by 1.300 px (bound 0.290 px), cam2 by 4.270 px (bound 0.310 px) off its "
                      "capture's other views and no later capture shows cam1, cam2"),
            std::string::npos)
      << text;
}

}  // namespace
}  // namespace stereorig
