#include "datasets/simulate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <unordered_map>

#include "calib/core/input_error.h"
#include "calib/core/input_error_testing.h"
#include "calib/core/rig_file.h"
#include "calib/core/yaml_reader.h"
#include "datasets/sim_test_util.h"
#include "targets/target_file.h"

namespace stereorig {
namespace {

namespace fs = std::filesystem;

std::string Slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string RunSim(const SimSpec& spec, const std::string& name, uint64_t seed, int threads, RigBump bump = {}) {
  SimulateOptions o;
  o.out_dir = ::testing::TempDir() + "/simtest_" + name;
  o.seed = seed;
  o.threads = threads;
  o.bump = bump;
  Simulate(spec, o);
  return o.out_dir;
}

TEST(Simulate, SameSeedSameBytesWhateverTheThreads) {
  SimSpec spec = SmallRingSpec(2, 4, 2);
  spec.scenes.names = {"tuber"};  // the slowest shape: sphere tracing
  const fs::path a = RunSim(spec, "det_a", 5, 1), b = RunSim(spec, "det_b", 5, 2), c = RunSim(spec, "det_c", 6, 2);
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator(a)) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), a);
    ASSERT_TRUE(fs::exists(b / rel)) << rel;
    EXPECT_EQ(Slurp(e.path()), Slurp(b / rel)) << rel;
    ++files;
  }
  EXPECT_GT(files, 25);
  // Another seed: other poses, other noise.
  EXPECT_NE(Slurp(a / "calibration/000/cam0.png"), Slurp(c / "calibration/000/cam0.png"));
  EXPECT_NE(Slurp(a / "scenes/tuber/passive/cam0.png"), Slurp(c / "scenes/tuber/passive/cam0.png"));
}

// Any number of modules renders: the layout, the truth rig and every image.
TEST(Simulate, OneTwoAndThreeModuleRigsRender) {
  for (int m = 1; m <= 3; ++m) {
    SimSpec spec = SmallRingSpec(m, 4, 2);
    spec.scenes.names = {"sphere"};
    const fs::path dir = RunSim(spec, "ring" + std::to_string(m), 1, 2);
    const Rig rig = ReadRigFile((dir / "truth/rig.yaml").string());
    EXPECT_EQ(rig.num_modules(), m);
    YamlMap layout = YamlMap::LoadFile((dir / "layout.yaml").string());
    EXPECT_EQ(layout.GetMaps("modules").size(), static_cast<size_t>(m));
    for (int cam = 0; cam < 2 * m; ++cam) {
      const std::string name = "cam" + std::to_string(cam) + ".png";
      for (const char* k : {"000", "001"}) {
        const cv::Mat im = cv::imread((dir / "calibration" / k / name).string(), cv::IMREAD_UNCHANGED);
        ASSERT_EQ(im.type(), CV_8U) << dir / "calibration" / k / name;
        EXPECT_EQ(im.cols, spec.modules[cam / 2].left.width_px);
      }
      const cv::Mat active = cv::imread((dir / "scenes/sphere/active" / name).string(), cv::IMREAD_UNCHANGED);
      const cv::Mat passive = cv::imread((dir / "scenes/sphere/passive" / name).string(), cv::IMREAD_UNCHANGED);
      const cv::Mat id = cv::imread((dir / "truth/scenes/sphere" / ("id_" + name)).string(), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(active.empty());
      ASSERT_FALSE(id.empty());
      // Every camera sees the sphere, and its own module's laser on it.
      const cv::Mat on = id > 0;
      EXPECT_GT(cv::countNonZero(on), 200);
      EXPECT_GT(cv::mean(active, on)[0], cv::mean(passive, on)[0] + 5);
    }
  }
}

TEST(Simulate, RefusesToReplaceAFolderThatIsNotADatasetAndLeavesNoTemporaries) {
  const fs::path dir = ::testing::TempDir() + "/simtest_precious";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "thesis.txt") << "do not lose";
  SimulateOptions o;
  o.out_dir = dir.string();
  EXPECT_THROW(Simulate(SmallRingSpec(1, 4, 1), o), InputError);
  EXPECT_EQ(Slurp(dir / "thesis.txt"), "do not lose");
  for (const auto& e : fs::directory_iterator(dir.parent_path())) {
    EXPECT_EQ(e.path().filename().string().find(".simtest_precious.tmp"), std::string::npos);
  }
}

// An existing folder is replaced whole, so only an earlier dataset holding
// nothing else is: an earlier dataset (every file and folder the simulator
// wrote, scenes and artifacts included) is replaced; one with a file the
// simulator does not write, or a folder with a spec.yaml but no
// truth/simulation.yaml (a user's project), is refused naming it, and
// nothing in it is lost. Before, a spec.yaml was enough and the notes went
// with the folder.
TEST(Simulate, ReplacesAnEarlierDatasetOnlyIfItHoldsNothingElse) {
  SimSpec spec = SmallRingSpec(1, 4, 1);
  spec.scenes.names = {"sphere", "plate"};  // artifacts/ too
  const fs::path dir = RunSim(spec, "replace", 1, 2);
  SimulateOptions o;
  o.out_dir = dir.string();
  EXPECT_EQ(testing::InputErrorMessage([&] { Simulate(spec, o); }), "");  // every file the simulator's own
  const std::string refusal =
      ", which the simulator does not write; refusing to replace the dataset and delete it "
      "(move it out, or choose another --out)";
  std::ofstream(dir / "truth" / "scenes" / "sphere" / "notes.txt") << "keep";
  EXPECT_EQ(testing::InputErrorMessage([&] { Simulate(spec, o); }),
            dir.string() + ": holds truth/scenes/sphere/notes.txt" + refusal);
  fs::remove(dir / "truth" / "scenes" / "sphere" / "notes.txt");
  fs::create_directories(dir / "scores");
  std::ofstream(dir / "scores" / "cup.json") << "{}";
  std::ofstream(dir / "scenes" / "sphere" / "active" / "cam0.jpg") << "";
  EXPECT_EQ(testing::InputErrorMessage([&] { Simulate(spec, o); }),
            dir.string() + ": holds scenes/sphere/active/cam0.jpg" + refusal);  // the first by name
  EXPECT_EQ(Slurp(dir / "scores" / "cup.json"), "{}");
  // A project folder: its own spec, no truth/.
  const fs::path project = ::testing::TempDir() + "/simtest_project";
  fs::remove_all(project);
  fs::create_directories(project);
  std::ofstream(project / "spec.yaml") << SimSpecToYaml(spec);
  o.out_dir = project.string();
  EXPECT_EQ(testing::InputErrorMessage([&] { Simulate(spec, o); }),
            project.string() +
                ": exists and is not a stereorig dataset (no truth/simulation.yaml of format stereorig-sim-info); "
                "refusing to replace it");
  EXPECT_EQ(Slurp(project / "spec.yaml"), SimSpecToYaml(spec));
}

// The files a run reads may not be in --out, which is replaced whole: the
// spec's target file (and, from the command, its --spec file) is refused by
// name, before any folder is made.
TEST(Simulate, RefusesAnOutHoldingItsInputs) {
  const fs::path dir = ::testing::TempDir() + "/simtest_inputs";
  fs::remove_all(dir);
  fs::create_directories(dir / "empty");
  WriteTargetFile(DefaultTarget(), (dir / "empty" / "board.yaml").string());
  SimSpec spec = SmallRingSpec(1, 4, 0);
  spec.scenes.names.clear();
  spec.calibration.target = (dir / "empty" / "board.yaml").string();
  SimulateOptions o;
  o.out_dir = (dir / "empty").string();
  EXPECT_EQ(testing::InputErrorMessage([&] { Simulate(spec, o); }),
            o.out_dir + ": holds the spec's target file (calibration.target) " + spec.calibration.target +
                ": replacing the folder with the dataset would delete it");
  o.out_dir = spec.calibration.target;
  EXPECT_EQ(testing::InputErrorMessage([&] { Simulate(spec, o); }),
            o.out_dir + ": is the spec's target file (calibration.target), not a folder for the dataset (--out)");
  spec.calibration.target = "default";
  o.out_dir = (dir / "new").string();
  o.inputs = {{(dir / "new" / "spec.yaml").string(), "the spec file (--spec)"}};
  fs::create_directories(dir / "new");
  std::ofstream(dir / "new" / "spec.yaml") << SimSpecToYaml(spec);
  EXPECT_NE(testing::InputErrorMessage([&] { Simulate(spec, o); }).find("new: holds the spec file (--spec)"),
            std::string::npos);
  EXPECT_EQ(Slurp(dir / "new" / "spec.yaml"), SimSpecToYaml(spec));
  EXPECT_TRUE(fs::exists(dir / "empty" / "board.yaml"));
}

// The warnings a run of `spec` gives on its progress sink.
std::vector<std::string> Warnings(const SimSpec& spec, const std::string& name) {
  SimulateOptions o;
  o.out_dir = ::testing::TempDir() + "/simtest_" + name;
  fs::remove_all(o.out_dir);
  std::vector<std::string> warnings;
  o.progress = [&](const std::string& line) {
    if (line.starts_with("warning: ")) warnings.push_back(line);
  };
  Simulate(spec, o);
  return warnings;
}

// A geometry that cannot work renders, but says so: a module looking away
// from the volume has cameras the board never reaches, and a projector past
// the volume lights nothing. Both rendered without a word. The sound rig
// gives no warning.
TEST(Simulate, CamerasTheBoardMissesAndProjectorsLightingNothingAreWarnedOf) {
  SimSpec spec = SmallRingSpec(2, 4, 2);
  spec.calibration.min_corners_per_camera = 12;
  spec.scenes.names = {"sphere"};
  EXPECT_EQ(Warnings(spec, "warn_none"), std::vector<std::string>{});
  SimSpec away = spec;
  away.scenes.names.clear();
  away.modules[0].look_at_mm = away.modules[0].center_mm + Eigen::Vector3d(0, 0, -800);
  const std::string misses =
      " target corners in any of the 2 calibration captures, fewer than "
      "calibration.min_corners_per_camera (12): check the module's center_mm and look_at_mm";
  EXPECT_EQ(Warnings(away, "warn_away"),
            (std::vector<std::string>{"warning: cam0 (module0's left camera) sees at most 0" + misses,
                                      "warning: cam1 (module0's right camera) sees at most 0" + misses}));
  SimSpec far = spec;
  far.calibration.captures = 0;
  far.modules[1].projector.offset_mm = Eigen::Vector3d(0, 0, 500);  // 300 mm past the centre, facing away from it
  EXPECT_EQ(Warnings(far, "warn_far"),
            (std::vector<std::string>{"warning: modules[1] (module1)'s projector lights no pixel of any camera in any "
                                      "scene: check its offset_mm and the module's look_at_mm"}));
}

// truth/rig.yaml of a small two-module rig (no scenes, seed 3), bumped.
Rig BumpedTruth(const std::string& name, const RigBump& bump) {
  SimSpec spec = SmallRingSpec(2, 4, 1);
  spec.scenes.names.clear();
  return ReadRigFile(RunSim(spec, name, 3, 2, bump) + "/truth/rig.yaml");
}

// The morning after a bump: the truth moves by exactly what was asked.
TEST(Simulate, BumpsMoveTheTruthByTheRequestedAmount) {
  const Rig before = BumpedTruth("bump0", {});
  RigBump cam;
  cam.camera = 1;
  cam.rotation_deg = 0.05;
  const Rig after_cam = BumpedTruth("bump1", cam);
  const Pose d = before.module(0).right_from_left * after_cam.module(0).right_from_left.Inverse();
  EXPECT_NEAR(d.AngleDeg(), 0.05, 1e-9);
  EXPECT_LT((before.S(0, 1).Inverse() * after_cam.S(0, 1)).AngleDeg(), 1e-12);  // other modules untouched
  RigBump mod;
  mod.module = 1;
  mod.translation_mm = 0.1;
  const Rig after_mod = BumpedTruth("bump2", mod);
  const Pose m = before.S(0, 1).Inverse() * after_mod.S(0, 1);
  EXPECT_NEAR(m.DistanceMm(), 0.1, 1e-9);
  EXPECT_LT(m.AngleDeg(), 1e-9);
  EXPECT_LT((before.module(1).right_from_left.Inverse() * after_mod.module(1).right_from_left).DistanceMm(), 1e-9);
}

// The options' check refuses, naming the flag, a bump that Any() would drop
// (an index below -1, "none") and a NaN amount (which reached the rig's own
// check, naming neither).
TEST(Simulate, OptionsRefuseABumpIndexBelowNoneAndANanAmount) {
  auto message = [](const RigBump& bump) {
    SimulateOptions o;
    o.out_dir = "unused";
    o.bump = bump;
    return testing::InputErrorMessage([&] { o.Check(); });
  };
  RigBump b;
  b.camera = -2;
  b.rotation_deg = 1;
  EXPECT_EQ(message(b), "--bump-camera: no camera -2");
  b = {};
  b.module = -3;
  b.translation_mm = 1;
  EXPECT_EQ(message(b), "--bump-module: no module -3");
  b = {};
  b.module = 1;
  b.rotation_deg = std::nan("");
  EXPECT_EQ(message(b), "--bump-rotation-deg: must be within +-10");
  b.rotation_deg = 0;
  b.translation_mm = -std::nan("");
  EXPECT_EQ(message(b), "--bump-translation-mm: must be within +-10");
}

// A drifted lens: truth/rig.yaml holds exactly the drifted intrinsics of that
// camera, every other intrinsic and every pose as they were.
TEST(Simulate, ALensDriftChangesOnlyThatCamerasIntrinsics) {
  const Rig before = BumpedTruth("lens0", {});
  RigBump lens;
  lens.camera = 2;
  lens.lens.focal_percent = 0.1;
  lens.lens.principal_point_px = {0.5, -1.25};
  const Rig after = BumpedTruth("lens1", lens);
  for (int c = 0; c < before.num_cameras(); ++c) {
    std::vector<double> expected = before.camera(c).intrinsics();
    if (c == 2) {
      expected[0] *= 1.001;
      expected[1] *= 1.001;
      expected[2] += 0.5;
      expected[3] -= 1.25;
    }
    for (size_t i = 0; i < expected.size(); ++i)
      EXPECT_NEAR(after.camera(c).intrinsics()[i], expected[i], 1e-9) << "camera " << c << " intrinsic " << i;
    EXPECT_LT((before.CamFromReference(c).Inverse() * after.CamFromReference(c)).DistanceMm(), 1e-9);
    EXPECT_LT((before.CamFromReference(c).Inverse() * after.CamFromReference(c)).AngleDeg(), 1e-9);
  }
}

}  // namespace
}  // namespace stereorig

namespace stereorig {
namespace {

// Any mrcal lens model: a pinhole and a splined stereographic camera render
// through their own unprojection.
TEST(Simulate, OtherLensModelsRender) {
  SimSpec spec = SmallRingSpec(1, 4, 1);
  spec.scenes.names = {"sphere"};
  CameraSpec& l = spec.modules[0].left;
  l.lensmodel = "LENSMODEL_PINHOLE";
  l.intrinsics.resize(4);
  CameraSpec& r = spec.modules[0].right;
  r.lensmodel = "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=8_Ny=6_fov_x_deg=50";
  r.intrinsics.resize(4);
  r.intrinsics.resize(4 + 2 * 8 * 6, 0.0);  // no deviation from a pure stereographic lens
  const fs::path dir = RunSim(spec, "lenses", 2, 2);
  for (const char* cam : {"cam0", "cam1"}) {
    const cv::Mat id =
        cv::imread((dir / "truth/scenes/sphere" / (std::string("id_") + cam + ".png")).string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(id.empty());
    EXPECT_GT(cv::countNonZero(id), 200) << cam;  // the sphere is in view of both lenses
  }
  EXPECT_EQ(ReadRigFile((dir / "truth/rig.yaml").string()).camera(1).lensmodel_name(), r.lensmodel);
}

}  // namespace
}  // namespace stereorig

namespace stereorig {
namespace {

std::vector<Eigen::Vector3f> ReadPly(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::string line;
  size_t n = 0;
  while (std::getline(f, line) && line != "end_header") {
    if (line.rfind("element vertex ", 0) == 0) n = std::stoul(line.substr(15));
  }
  std::vector<Eigen::Vector3f> pts(n);
  f.read(reinterpret_cast<char*>(pts.data()), static_cast<std::streamsize>(n * sizeof(Eigen::Vector3f)));
  EXPECT_TRUE(f.good()) << p;
  return pts;
}

// Two independent truths agree: every depth-map pixel (ray intersection),
// lifted to 3D, lies within 0.15 mm of a dense surface sample (parametric
// sampling). A 0.2 mm grid leaves no surface point farther than 0.2/sqrt(2).
TEST(Simulate, DepthMapsLieOnTheDenseSurface) {
  SimSpec spec = SmallRingSpec(2, 4, 0);
  spec.scenes.names = {"cup", "tuber", "ballbar"};
  const fs::path dir = RunSim(spec, "surface", 4, 2);
  const Rig rig = ReadRigFile((dir / "truth/rig.yaml").string());
  for (const std::string scene : {"cup", "tuber", "ballbar"}) {
    const std::vector<Eigen::Vector3f> pts = ReadPly(dir / "truth/scenes" / scene / "surface.ply");
    ASSERT_GT(pts.size(), 10000u);
    // A hash grid of 0.5 mm cells.
    const float cell = 0.5f;
    auto key = [&](const Eigen::Vector3f& p, int dx, int dy, int dz) {
      const int64_t x = static_cast<int64_t>(std::floor(p.x() / cell)) + dx;
      const int64_t y = static_cast<int64_t>(std::floor(p.y() / cell)) + dy;
      const int64_t z = static_cast<int64_t>(std::floor(p.z() / cell)) + dz;
      return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791);
    };
    std::unordered_map<int64_t, std::vector<int>> grid;
    for (size_t i = 0; i < pts.size(); ++i) grid[key(pts[i], 0, 0, 0)].push_back(static_cast<int>(i));
    double worst = 0;
    int checked = 0;
    for (int cam = 0; cam < rig.num_cameras(); ++cam) {
      const cv::Mat depth =
          cv::imread((dir / "truth/scenes" / scene / ("depth_cam" + std::to_string(cam) + ".tiff")).string(),
                     cv::IMREAD_UNCHANGED);
      ASSERT_EQ(depth.type(), CV_32F);
      const Pose ref_from_cam = rig.CamFromReference(cam).Inverse();
      for (int r = 0; r < depth.rows; r += 2) {
        for (int c = 0; c < depth.cols; c += 2) {
          const float z = depth.at<float>(r, c);
          if (!(z > 0)) continue;
          Eigen::Vector3d v;
          ASSERT_TRUE(rig.camera(cam).Unproject(Eigen::Vector2d(c, r), &v));
          const Eigen::Vector3f p = (ref_from_cam * (v * (z / v.z()))).cast<float>();
          double best = 1e9;
          for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
              for (int dz = -1; dz <= 1; ++dz) {
                auto it = grid.find(key(p, dx, dy, dz));
                if (it == grid.end()) continue;
                for (int i : it->second) best = std::min(best, static_cast<double>((pts[i] - p).norm()));
              }
          worst = std::max(worst, best);
          ++checked;
        }
      }
    }
    EXPECT_GT(checked, 1000) << scene;
    EXPECT_LT(worst, 0.15) << scene;
    std::printf("%s: %zu surface samples; %d depth pixels, farthest from a sample %.3f mm\n", scene.c_str(), pts.size(),
                checked, worst);
  }
}

}  // namespace
}  // namespace stereorig
