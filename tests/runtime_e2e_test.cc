// The runtime end to end on the simulator's default rig and scenes (cup and
// sphere, every sensor effect on: shot and read noise, laser speckle
// contrast 0.2, PSF blur, 2x2 rays per pixel), reconstructed with the TRUE rig
// (a calibration would take minutes; `stereorig score` measures the
// calibrated case, docs/reconstruct.md). Judged as issue 5 judges:
//   - accuracy against the simulator's dense truth surface after one rigid
//     alignment (score.h), and for the sphere also against the analytic
//     sphere of object.yaml, a computation that shares nothing with ours;
//   - fill against the renderer's truth: object pixels both cameras of a
//     module see and a grid lights (fill_score.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>
#include <vector>

#include "calib/core/input_error.h"
#include "calib/core/rig_file.h"
#include "datasets/simulate.h"
#include "reconstruct/runtime.h"
#include "reconstruct/scene_score.h"

namespace stereorig {
namespace {

namespace fs = std::filesystem;

// Simulates `scenes` (active and passive captures, no calibration captures)
// of the rig in `spec` (default: the default rig) into TempDir()/name at
// `seed` and speckle contrast `speckle`; returns the folder. The scene list
// is part of the realization.
std::string SimulateScenes(const std::vector<std::string>& scenes, int seed, double speckle, const std::string& name,
                           SimSpec spec = DefaultSimSpec()) {
  spec.scenes.names = scenes;
  spec.render.speckle_contrast = speckle;
  SimulateOptions o;
  o.out_dir = ::testing::TempDir() + "/" + name;
  o.seed = seed;
  o.calibration_captures = 0;
  Simulate(spec, o);
  return o.out_dir;
}

// Reconstructs `scene`'s active capture of `dataset` with its truth rig and
// default options, scores it (as RuntimeOnSimulatedScenes::Run) and prints
// each module's figures after `label`.
SceneScore ReconstructAndScore(const std::string& dataset, const std::string& scene, const std::string& label,
                               const RuntimeOptions& options = RuntimeOptions{}) {
  const Rig rig = ReadRigFile(dataset + "/truth/rig.yaml");
  const Runtime runtime(rig, options);
  const Reconstruction rec = runtime.Process(LoadCapture(dataset + "/scenes/" + scene + "/active", rig), false);
  const SceneScore s = ScoreScene(runtime, rec, ReadSceneTruth(dataset, scene));
  for (size_t m = 0; m < s.fill.size(); ++m) {
    const ErrorFigures& e = s.accuracy.per_module[m];
    std::printf("%s module %zu: fill %.3f, %d points, |e| %.4f mm, std %.4f mm\n", label.c_str(), m, s.fill[m].fill(),
                e.points, e.mean_abs_mm, e.std_mm);
  }
  std::printf("%s merged: |e| %.4f mm; aligned by %.4f deg, %.4f mm\n", label.c_str(), s.accuracy.all.mean_abs_mm,
              s.accuracy.truth_from_cloud.AngleDeg(), s.accuracy.truth_from_cloud.translation_mm().norm());
  return s;
}

// One scene alone, simulated at `seed` (the default rig and speckle) and
// scored with its truth rig twice: with `control` (the defaults with one
// step off, `what` naming that) and with the defaults.
struct ControlAndDefault {
  SceneScore off, on;
};
ControlAndDefault ScoreControlAndDefault(const std::string& scene, int seed, const RuntimeOptions& control,
                                         const std::string& what) {
  const std::string dataset = SimulateScenes({scene}, seed, DefaultSimSpec().render.speckle_contrast,
                                             "runtime_e2e_" + scene + std::to_string(seed));
  const std::string label = "seed " + std::to_string(seed) + " " + scene;
  return {ReconstructAndScore(dataset, scene, label + ", " + what, control),
          ReconstructAndScore(dataset, scene, label)};
}

// Both modules of the default run meet issue 5's per-module targets (mean
// |e| and std < 0.1 mm) and keep at least min_fill_gain more fill than the
// control (negative: lose at most that much). Both runs have two modules
// (the caller asserts it).
void ExpectTargetsAndFillAgainstControl(const ControlAndDefault& r, double min_fill_gain) {
  for (size_t m = 0; m < 2; ++m) {
    EXPECT_LT(r.on.accuracy.per_module[m].mean_abs_mm, 0.1) << "module " << m;
    EXPECT_LT(r.on.accuracy.per_module[m].std_mm, 0.1) << "module " << m;
    EXPECT_GT(r.on.fill[m].fill(), r.off.fill[m].fill() + min_fill_gain) << "module " << m;
  }
}

class RuntimeOnSimulatedScenes : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dataset_ = new std::string(
        SimulateScenes({"cup", "sphere"}, 1, DefaultSimSpec().render.speckle_contrast, "runtime_e2e_dataset"));
  }
  static void TearDownTestSuite() {
    delete dataset_;
    dataset_ = nullptr;
  }

  struct Outcome {
    Reconstruction rec;
    SceneScore score;
  };
  static Outcome Run(const std::string& scene) {
    const Rig rig = ReadRigFile(*dataset_ + "/truth/rig.yaml");
    const Runtime runtime(rig, RuntimeOptions{});
    Outcome out;
    out.rec = runtime.Process(LoadCapture(*dataset_ + "/scenes/" + scene + "/active", rig), false);
    out.score = ScoreScene(runtime, out.rec, ReadSceneTruth(*dataset_, scene));
    for (size_t m = 0; m < out.score.fill.size(); ++m) {
      const ErrorFigures& e = out.score.accuracy.per_module[m];
      std::printf("%s module %zu: fill %.3f of %d target px; %d points, |e| %.4f mm, std %.4f mm\n", scene.c_str(), m,
                  out.score.fill[m].fill(), out.score.fill[m].target_px, e.points, e.mean_abs_mm, e.std_mm);
    }
    std::printf("%s merged: |e| %.4f mm, std %.4f mm; aligned by %.4f deg, %.4f mm\n", scene.c_str(),
                out.score.accuracy.all.mean_abs_mm, out.score.accuracy.all.std_mm,
                out.score.accuracy.truth_from_cloud.AngleDeg(),
                out.score.accuracy.truth_from_cloud.translation_mm().norm());
    return out;
  }
  static std::string* dataset_;
};
std::string* RuntimeOnSimulatedScenes::dataset_ = nullptr;

// Issue 5's per-module figures, where this session meets them, on both
// modules. One module at 200 mm: mean |e| <= 0.1 mm, std <= 0.1 mm; measured
// 0.05 / 0.07 mm: laser speckle (contrast 0.2, independent per camera)
// decorrelates the views to a ZNCC of ~0.9, ~0.25 px of disparity noise =
// 0.1 mm of depth. The fill is asserted at what it measures, NOT yet at the
// issue's 90 % (`stereorig score` lists the losses). Nearly every point is on
// a target pixel: points where the right camera does not see the surface
// would be guesses.
void ExpectModuleFigures(const SceneScore& s, double min_fill) {
  ASSERT_EQ(s.fill.size(), 2u);
  for (size_t m = 0; m < 2; ++m) {
    EXPECT_LT(s.accuracy.per_module[m].mean_abs_mm, 0.1) << "module " << m;
    EXPECT_LT(s.accuracy.per_module[m].std_mm, 0.1) << "module " << m;
    EXPECT_GT(s.fill[m].fill(), min_fill) << "module " << m;
    EXPECT_LT(s.fill[m].other_px, 0.03 * s.fill[m].filled_px) << "module " << m;
  }
  EXPECT_LT(s.accuracy.all.mean_abs_mm, 0.15);  // two modules merged
}

// Measured fill: 0.92 and 0.90 per module.
TEST_F(RuntimeOnSimulatedScenes, CupMeetsTheAccuracyTargets) {
  const Outcome o = Run("cup");
  ExpectModuleFigures(o.score, 0.85);
  EXPECT_GT(o.score.fill_all.fill(), 0.88);
}

// Measured fill: 0.84 on both modules.
TEST_F(RuntimeOnSimulatedScenes, SphereAgreesWithTheAnalyticSphere) {
  const Outcome o = Run("sphere");
  ExpectModuleFigures(o.score, 0.80);
  // The analytic sphere (object.yaml: centre, diameter), in the truth rig's
  // frame: the cloud needs no alignment here. Radial residuals of every
  // point; a wrong grid line index shows as a blob ~3.5 mm off.
  std::ifstream f(*dataset_ + "/truth/scenes/sphere/object.yaml");
  std::stringstream text;
  text << f.rdbuf();
  std::smatch c, d;
  const std::string s = text.str();
  ASSERT_TRUE(std::regex_search(s, c, std::regex(R"(center_mm: \[([^,]+), ([^,]+), ([^\]]+)\])")));
  ASSERT_TRUE(std::regex_search(s, d, std::regex(R"(diameter_mm: ([0-9.eE+-]+))")));
  const Eigen::Vector3d centre(std::stod(c[1]), std::stod(c[2]), std::stod(c[3]));
  const double radius = 0.5 * std::stod(d[1]);
  int n = 0, far = 0;
  double sum_abs = 0, worst = 0;
  for (size_t i = 0; i < o.rec.cloud.size(); ++i) {
    const double e = (o.rec.cloud.xyz_mm[i].cast<double>() - centre).norm() - radius;
    sum_abs += std::abs(e);
    far += std::abs(e) > 0.8;
    worst = std::max(worst, std::abs(e));
    ++n;
  }
  ASSERT_GT(n, 0);
  std::printf("sphere: %d points, mean |radial residual| %.4f mm, %d beyond 0.8 mm, worst %.3f mm\n", n, sum_abs / n,
              far, worst);
  EXPECT_LT(sum_abs / n, 0.1);
  // Session 1's demo failed P_F (range of radial residuals <= 1.5 mm) on a
  // blob of ~375 points one grid period off; now none may be that far.
  EXPECT_LT(far, n / 1000);
  EXPECT_LT(worst, 1.5);
}

// A capture's cloud does not depend on the threads that made it: the
// runtime's loops run on a work-stealing pool (parallel_for.h), whose chunks
// start wherever threads come free, and Process() may be called from several
// threads at once. The sphere's cloud, bit for bit: with the default pool (2
// modules x 2 threads), every step on the calling thread (modules in turn,
// one thread each), 8 threads per module, and two Process() calls at once on
// one runtime.
TEST_F(RuntimeOnSimulatedScenes, TheCloudIsTheSameWhateverTheThreads) {
  const Rig rig = ReadRigFile(*dataset_ + "/truth/rig.yaml");
  const std::vector<cv::Mat> capture = LoadCapture(*dataset_ + "/scenes/sphere/active", rig);
  auto same = [](const PointCloud& a, const PointCloud& b) {
    return a.xyz_mm == b.xyz_mm && a.normal == b.normal && a.intensity == b.intensity && a.module == b.module &&
           a.confidence == b.confidence;
  };
  const Runtime pooled(rig, RuntimeOptions{});
  const PointCloud reference = pooled.Process(capture, false).cloud;
  ASSERT_GT(reference.size(), 10000u);

  RuntimeOptions one_thread;
  one_thread.parallel_modules = false;
  one_thread.match.num_threads = 1;
  EXPECT_TRUE(same(Runtime(rig, one_thread).Process(capture, false).cloud, reference)) << "one thread";

  RuntimeOptions eight_threads;
  eight_threads.match.num_threads = 8;
  EXPECT_TRUE(same(Runtime(rig, eight_threads).Process(capture, false).cloud, reference)) << "8 threads per module";

  PointCloud first, second;
  std::thread other([&] { first = pooled.Process(capture, false).cloud; });
  second = pooled.Process(capture, false).cloud;
  other.join();
  EXPECT_TRUE(same(first, reference)) << "two calls at once: the other thread's";
  EXPECT_TRUE(same(second, reference)) << "two calls at once: this thread's";
}

// Twice the default speckle (contrast 0.4) on the flatness plate, the scene
// where it hurt most: issue 5 asks the figures at speckle off, default and
// high. The local surface fit measures the stronger noise (median misfit
// ~0.28 px against its 0.2 px reference), fits a wider window and reaches
// the edges of the valid region (local_surface_fit.h, session 13). On this
// realization (truth rig, seed 1, the plate alone; the simulator and the
// runtime are deterministic): mean |e| 0.072 / 0.068 mm, std 0.098 / 0.089
// mm (session 20; 0.105 / 0.091 when this test was written, before session
// 13's fit up to the edges); session 12's fit 0.100 / 0.092 and 0.145 /
// 0.128. (Other realizations give std 0.085-0.119 mm at this speckle: the
// figure moves by ~10 % between them, so issue 5's 0.1 mm is met on some
// and missed on others.) Asserted:
// the issue's mean |e| target, and std below 0.115 mm, which session 12's
// fit fails on both modules.
TEST(RuntimeAtStrongSpeckle, PlateMeetsTheMeanTargetAndStaysNearTheStdOne) {
  const std::string dataset = SimulateScenes({"plate"}, 1, 0.4, "runtime_e2e_speckle04");
  const SceneScore s = ReconstructAndScore(dataset, "plate", "speckle 0.4 plate");
  ASSERT_EQ(s.fill.size(), 2u);
  for (size_t m = 0; m < 2; ++m) {
    const ErrorFigures& e = s.accuracy.per_module[m];
    EXPECT_LT(e.mean_abs_mm, 0.1) << "module " << m;
    EXPECT_LT(e.std_mm, 0.115) << "module " << m;
  }
  EXPECT_LT(s.accuracy.all.mean_abs_mm, 0.15);  // two modules merged
}

// The default speckle on a realization no option was tuned on (seed 6,
// the ball bar and the plate alone, truth rig; the scene list is part of
// the realization). Session 20 found the four datasets every session
// scored hiding failures that fresh realizations show (reconstruct-log.md,
// "The speed options scored on fresh realizations"); this one guards issue
// 5's targets, per module and merged, as the issue states them. Measured:
// ball bar 0.053 / 0.059 mm mean |e|, std 0.069 / 0.094 mm (module 1's
// nearest the target: ~30 points a few pixels off at the lower ball's left
// silhouette), plate std 0.069 / 0.073; fill 0.806 / 0.796 and 0.967 /
// 0.975, asserted less ~3 points (the simulator and the runtime are
// deterministic: the margin is for a deliberate change of the pipeline,
// which should then say why).
TEST(RuntimeOnAFreshRealization, BallBarAndPlateMeetTheAccuracyTargets) {
  const std::string dataset =
      SimulateScenes({"ballbar", "plate"}, 6, DefaultSimSpec().render.speckle_contrast, "runtime_e2e_seed6");
  for (const auto& [scene, min_fill] : {std::pair{"ballbar", 0.77}, {"plate", 0.94}}) {
    const SceneScore s = ReconstructAndScore(dataset, scene, std::string("seed 6 ") + scene);
    ASSERT_EQ(s.fill.size(), 2u);
    for (size_t m = 0; m < 2; ++m) {
      const ErrorFigures& e = s.accuracy.per_module[m];
      EXPECT_LT(e.mean_abs_mm, 0.1) << scene << " module " << m;
      EXPECT_LT(e.std_mm, 0.1) << scene << " module " << m;
      EXPECT_GT(s.fill[m].fill(), min_fill) << scene << " module " << m;
    }
    EXPECT_LT(s.accuracy.all.mean_abs_mm, 0.15) << scene;  // two modules merged
  }
}

// The right view's edge (right_view_edge.h) on a realization where it
// matters: the default plate alone at seed 35, truth rig. Module 0's right
// sensor ends beside the plate, and without the test strips of points a grid
// period off stay beside its edge. Measured (`stereorig score`, the same
// realization, match.right_view_edge_test false / true; before session 28's
// last speckle pass along the slopes): module 0 std 0.153
// -> 0.077 mm, mean |e| 0.064 -> 0.059 mm; module 1 0.071 mm both ways; fill
// 96.8 / 97.3 % both ways. (Seed 10 read 0.179 -> 0.073 mm before the seam
// join's spread went to 3 px, which now moves its strips as well.) Asserted:
// without the test module 0 misses issue 5's std target (the control); with
// it both modules meet the targets and keep their fill to 0.2 points (the
// pixels dropped are ones the fill does not count: their true match lies
// off the right view).
TEST(RuntimeOnAFreshRealization, ThePlateBesideTheRightViewsEdgeKeepsNoStripAPeriodOff) {
  RuntimeOptions without_test;
  without_test.match.right_view_edge_test = false;
  const ControlAndDefault r = ScoreControlAndDefault("plate", 35, without_test, "without the test");
  ASSERT_EQ(r.off.fill.size(), 2u);
  ASSERT_EQ(r.on.fill.size(), 2u);
  EXPECT_GT(r.off.accuracy.per_module[0].std_mm, 0.1);
  ExpectTargetsAndFillAgainstControl(r, -0.002);
}

// The grid-line test (grid_line_support.h) on a realization where it
// matters: the default ball bar alone at seed 16, truth rig. Above the grid's
// envelope the balls are lit by ambient light only; growing carried the
// limbs' disparity into that band along their outlines, points 1-1.5 mm off.
// Measured (before session 28's last speckle pass along the slopes;
// `stereorig score`, the same realization, match.grid_line_test
// false / true): module 0 std 0.105 -> 0.083 mm, module 1 0.119 -> 0.083 mm;
// fill 80.3 / 82.2 % both ways (the points dropped lie outside the grid-lit
// target). Over the ball bar alone at seeds 1-30, modules above 0.1 mm std
// went from 14 to 4 of 60 and no module's fill moved
// (docs/reconstruct-log.md, session 25). Asserted: without the test a module
// misses issue 5's std target (the control); with it both meet the targets
// and keep their fill to 0.2 points.
TEST(RuntimeOnAFreshRealization, TheBallBarKeepsNoPointOnItsOutlineBesideTheGrid) {
  RuntimeOptions without_test;
  without_test.match.grid_line.enabled = false;
  const ControlAndDefault r = ScoreControlAndDefault("ballbar", 16, without_test, "without the test");
  ASSERT_EQ(r.off.fill.size(), 2u);
  ASSERT_EQ(r.on.fill.size(), 2u);
  EXPECT_GT(std::max(r.off.accuracy.per_module[0].std_mm, r.off.accuracy.per_module[1].std_mm), 0.1);
  ExpectTargetsAndFillAgainstControl(r, -0.002);
}

// The last speckle pass along the slopes (match.final_speckle_along_slopes)
// on a realization where it matters: the default tuber alone at seed 3,
// truth rig. Growing reaches the tuber's steep right flank (|dd/dx| > 1
// near the silhouette), and the plain filter, whose neighbours must lie
// within 1 px, cut it into strips and removed them: points that pass every
// test at the truth disparity. Measured (`stereorig score`, the same
// realization, the option false / true): fill 89.9 / 91.0 % -> 90.2 /
// 91.3 %, mean |e| and std unchanged to 0.0001 mm; on the score gate's 90
// module rows +0.21 fill points on average, none lower, std within
// +0.0004 mm (docs/reconstruct-log.md, session 28). Asserted: each module
// gains fill (at least 0.1 point, measured 0.3) within the gate's accuracy
// bound (+0.002 mm) and issue 5's targets. Not asserted: the 90 % module 0
// now reaches, by 0.2 points (too close for a later change's noise).
TEST(RuntimeOnAFreshRealization, TheTubersSteepFlankSurvivesTheLastSpecklePass) {
  RuntimeOptions plain;
  plain.match.final_speckle_along_slopes = false;
  const ControlAndDefault r = ScoreControlAndDefault("tuber", 3, plain, "plain last pass");
  ASSERT_EQ(r.off.fill.size(), 2u);
  ASSERT_EQ(r.on.fill.size(), 2u);
  ExpectTargetsAndFillAgainstControl(r, 0.001);
  for (size_t m = 0; m < 2; ++m) {  // within the score gate's accuracy bound
    const ErrorFigures &on = r.on.accuracy.per_module[m], &off = r.off.accuracy.per_module[m];
    EXPECT_LT(on.mean_abs_mm, off.mean_abs_mm + 0.002) << "module " << m;
    EXPECT_LT(on.std_mm, off.std_mm + 0.002) << "module " << m;
  }
}

// A rig of three modules, 120 degrees apart around the object (the default
// rig's module 0, and its module 1's cameras and projector moved to +-120
// degrees), every module's grid lighting the object for all: the runtime is
// built for M modules, and the merge through S is only exercised beyond the
// facing pair here. Scored as above (truth rig, seed 11, the cup): each
// module must meet issue 5's per-module targets after ONE rigid alignment of
// the merged cloud, so a module put into the reference frame by the wrong S
// (or none) shows as millimetres of error on that module. Measured: mean |e|
// 0.033 / 0.034 / 0.031 mm, std 0.043 / 0.044 / 0.039 mm, fill 0.922 / 0.895
// / 0.901 (`stereorig score` on the same realization); fill asserted ~3
// points under that, as above.
// The default spec with a third module: module 1's cameras and projector
// copied, modules 1 and 2 at +-120 degrees around the object.
SimSpec ThreeModuleRingSpec() {
  SimSpec spec = DefaultSimSpec();
  STEREORIG_CHECK(spec.modules.size() == 2);  // module 1 is copied below
  spec.modules.push_back(spec.modules[1]);
  for (int m = 1; m < 3; ++m) {
    const double a = 2 * M_PI * m / 3;
    spec.modules[m].name = "module" + std::to_string(m);
    spec.modules[m].center_mm = Eigen::Vector3d(200 * std::sin(a), 0, -200 * std::cos(a));
  }
  return spec;
}

TEST(RuntimeOnAThreeModuleRig, EveryModuleMeetsTheAccuracyTargetsInOneFrame) {
  const std::string dataset =
      SimulateScenes({"cup"}, 11, DefaultSimSpec().render.speckle_contrast, "runtime_e2e_ring3", ThreeModuleRingSpec());
  const SceneScore s = ReconstructAndScore(dataset, "cup", "three modules, cup");
  ASSERT_EQ(s.fill.size(), 3u);  // the truth rig has three modules, each scored
  for (size_t m = 0; m < 3; ++m) {
    const ErrorFigures& e = s.accuracy.per_module[m];
    EXPECT_LT(e.mean_abs_mm, 0.1) << "module " << m;
    EXPECT_LT(e.std_mm, 0.1) << "module " << m;
    EXPECT_GT(s.fill[m].fill(), 0.86) << "module " << m;
  }
  EXPECT_LT(s.accuracy.all.mean_abs_mm, 0.15);  // three modules merged
}

// The plate on the ring faces modules 1 and 2 at ~60 degrees (its yaw is
// random within +-10 degrees); in this realization (seed 4, the plate
// alone) module 1's left camera grazes it: dd/dx ~ -1.6 px/px, the right
// view 2.6x as wide as the left. With default options module 1 keeps no
// point (the speckle filter's 1 px reach cuts that slope into one-pixel
// strips, each removed; following the slopes in the last pass alone, the
// default since session 28, does not save them: session 22 measured 0 %
// with only that pass); with match.speckle_along_slopes it is one
// surface. Measured with it (~7 s): fill 0.620, mean |e| 0.027 mm, std
// 0.126 mm. Issue 5's std target (0.1 mm) is not met and not asserted: the
// CLI's realization of this spec and seed (`stereorig simulate`, `score
// --diagnose`: fill 0.647, std 0.216 mm) has 1.45 % of its points > 1 px
// off (a band along the plate's right edge 0.4-0.7 px low, scattered
// mismatches), the rest 0.16 px from the truth on average. Asserted: the
// mean |e| target (0.1 mm: the default speckle's ~0.25 px of disparity
// noise is ~0.1 mm at 200 mm, ExpectModuleFigures), and the fill ~5 points
// under what it measures, as above; module 1's std only as a guard against
// a growing tail of mismatches, at twice what it measures (0.25 mm: not a
// target). Modules 0 and 2, which the option changes too (measured std
// 0.074 and 0.088 mm), are held to issue 5's per-module targets.
TEST(RuntimeOnAThreeModuleRig, APlateTheLeftCameraGrazesIsMeasuredAlongItsSlope) {
  const std::string dataset = SimulateScenes({"plate"}, 4, DefaultSimSpec().render.speckle_contrast,
                                             "runtime_e2e_ring3_plate", ThreeModuleRingSpec());
  RuntimeOptions options;
  options.match.speckle_along_slopes = true;
  const SceneScore s = ReconstructAndScore(dataset, "plate", "three modules, plate", options);
  ASSERT_EQ(s.fill.size(), 3u);
  EXPECT_GT(s.fill[1].fill(), 0.57);
  EXPECT_LT(s.accuracy.per_module[1].mean_abs_mm, 0.1);
  EXPECT_LT(s.accuracy.per_module[1].std_mm, 0.25);
  for (const size_t m : {size_t(0), size_t(2)}) {
    EXPECT_LT(s.accuracy.per_module[m].mean_abs_mm, 0.1) << "module " << m;
    EXPECT_LT(s.accuracy.per_module[m].std_mm, 0.1) << "module " << m;
  }
}

// Where a ring module's RIGHT camera grazes the plate (1 - dd/dx < 0.3:
// here module 2, seed 11, the plate alone), that module keeps a small patch
// matched ~95 px off: a surface ~50 mm behind the plate, which nothing in
// its own data refutes ("The oblique plate (session 22)" in
// reconstruct-log.md). Module 1 measures the plate from the other side of
// module 2's view, and its points lie in front of that patch along module
// 2's left camera's rays: the free-space test (free_space.h) removes it,
// and, as ~97 % of the patch is seen through, the patch goes whole (its
// ~3 % beyond module 1's cover too: session 22's test alone left 29 of
// 2 564). Asserted against the same capture without the test: module 2's
// points more than 0.5 mm off (~1.1 px of disparity at 200 mm; the
// module's correct points scatter by ~0.1 mm, so 0.5 mm is 5 sigma) fall
// to at most 1 %, and modules 0 and 1 lose at most 0.1 % of their points (their
// surfaces are the plate itself; what the test may take from them is a
// point whose 5x5 neighbourhood holds another module's nearer points, at
// the plate's edges).
TEST(RuntimeOnAThreeModuleRig, TheFreeSpaceTestRemovesAPatchTheRightCameraGrazes) {
  const std::string dataset = SimulateScenes({"plate"}, 11, DefaultSimSpec().render.speckle_contrast,
                                             "runtime_e2e_ring3_plate11", ThreeModuleRingSpec());
  RuntimeOptions options;
  options.free_space_test = false;
  const SceneScore without = ReconstructAndScore(dataset, "plate", "without the free-space test", options);
  options.free_space_test = true;
  const SceneScore with = ReconstructAndScore(dataset, "plate", "with the free-space test", options);
  ASSERT_EQ(with.fill.size(), 3u);
  auto off = [](const ErrorFigures& e) { return std::lround(e.points * (1 - e.within_0_5_mm)); };
  const long off_without = off(without.accuracy.per_module[2]), off_with = off(with.accuracy.per_module[2]);
  std::printf("module 2: %ld points > 0.5 mm off without the test, %ld with it\n", off_without, off_with);
  EXPECT_GT(off_without, 500) << "the realization no longer has the grazed patch";
  EXPECT_LE(off_with, off_without / 100);
  for (const size_t m : {size_t(0), size_t(1)}) {
    EXPECT_GE(with.accuracy.per_module[m].points, 0.999 * without.accuracy.per_module[m].points) << "module " << m;
    EXPECT_LT(with.accuracy.per_module[m].std_mm, 0.15) << "module " << m;
  }
}

}  // namespace
}  // namespace stereorig
