// `stereorig calibrate` end to end on rendered images: the default rig's
// geometry with pinhole cameras (what targets/synthetic_view.h renders),
// captures of the targets library's default double-sided board, detection,
// the three stages, the rig file and the report. Judged against the truth by
// module agreement through S (as calib/calibrate_test.cc does on corners).
// The refusals exit 2 with one line naming the problem.
#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <set>

#include "calib/calib_test_util.h"
#include "calib/capture_folder.h"
#include "calib/convergence.h"
#include "calib/core/rig_file.h"
#include "datasets/default_rig.h"
#include "targets/synthetic_view.h"
#include "targets/target_file.h"
#include "tests/cli_runner.h"

namespace stereorig {
namespace {

namespace fs = std::filesystem;

struct RenderedSet {
  std::string dir;
  Rig truth;
  Pose ref_from_volume;
};

// The default rig with distortion-free cameras (the renderer is a pinhole).
Rig PinholeDefaultRig(Pose* world_from_module0) {
  const SimulatedRig d = MakeDefaultRig();
  *world_from_module0 = d.world_from_module0;
  std::vector<Camera> cams;
  for (const Camera& c : d.rig.cameras()) {
    cams.emplace_back("LENSMODEL_PINHOLE", std::vector<double>(c.intrinsics().begin(), c.intrinsics().begin() + 4),
                      c.imager_width_px(), c.imager_height_px());
  }
  return Rig(cams, d.rig.camera_names(), d.rig.modules(), std::vector<Pose>{Pose::Identity(), d.rig.S(0, 1)});
}

RenderedSet Render(const std::string& name, int captures, unsigned seed) {
  RenderedSet set;
  // Unique per process: other checkouts may run this test at the same time.
  set.dir = ::testing::TempDir() + "/" + name + "_" + std::to_string(getpid());
  fs::remove_all(set.dir);
  fs::create_directories(set.dir + "/captures");
  Pose world_from_module0;
  set.truth = PinholeDefaultRig(&world_from_module0);
  set.ref_from_volume = world_from_module0.Inverse();
  const Target target = DefaultTarget();
  WriteTargetFile(target, set.dir + "/target.yaml");
  std::ofstream(set.dir + "/layout.yaml") << "modules:\n  - {name: module0, left: 0, right: 1, face: front}\n"
                                             "  - {name: module1, left: 2, right: 3, face: back}\n";
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const double s = target.square_size_mm();
  const Eigen::Vector3d centre(0.5 * (target.corners_x() - 1) * s, 0.5 * (target.corners_y() - 1) * s, 0);
  SyntheticViewOptions view;
  view.supersample = 2;
  view.noise_sigma_dn = 2.0;
  for (int c = 0; c < captures; ++c) {
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.35 * u(rng), Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(0.55 * u(rng), Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(0.55 * u(rng), Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
    const Pose ref_from_front = set.ref_from_volume * Pose(R, Eigen::Vector3d(20 * u(rng), 15 * u(rng), 25 * u(rng))) *
                                Pose(Eigen::Matrix3d::Identity(), -centre);
    char folder[32];
    std::snprintf(folder, sizeof folder, "/captures/%03d", c);
    fs::create_directories(set.dir + folder);
    for (int cam = 0; cam < set.truth.num_cameras(); ++cam) {
      const Pose cam_from_ref = set.truth.CamFromReference(cam);
      const Eigen::Vector3d cam_centre = cam_from_ref.Inverse().translation_mm();
      const bool front = (cam_centre - ref_from_front.translation_mm()).dot(ref_from_front.rotation().col(2)) < 0;
      const Face face = front ? Face::kFront : Face::kBack;
      const Pose cam_from_face =
          cam_from_ref * ref_from_front * (front ? Pose::Identity() : target.back_from_front().Inverse());
      const Camera& k = set.truth.camera(cam);
      PinholeCamera pin;
      pin.fx_px = k.fx(), pin.fy_px = k.fy(), pin.cx_px = k.cx(), pin.cy_px = k.cy();
      pin.width_px = k.imager_width_px(), pin.height_px = k.imager_height_px();
      view.seed = seed * 1000 + c * 10 + cam;
      cv::imwrite(set.dir + folder + "/cam" + std::to_string(cam) + ".png",
                  RenderFace(target, face, pin, cam_from_face, view));
    }
  }
  return set;
}

// Rendering and detection cost ~0.5-1 s per image on this machine, so the
// sets are small: 8 captures to calibrate, 2 for each refusal.
const RenderedSet& Rendered() {
  static const RenderedSet set = Render("calib_cli", 8, 5);
  return set;
}

// A fresh folder `name` in the rendered set, holding the set's target file
// with its text `from` (which must be there) edited to `to`: a hand-edited
// target file. Returns the folder.
std::string EditedTargetFolder(const std::string& name, const std::string& from, const std::string& to) {
  const RenderedSet& set = Rendered();
  const std::string dir = set.dir + "/" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ifstream in(set.dir + "/target.yaml");
  std::string text(std::istreambuf_iterator<char>(in), {});
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from << " not in " << text;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  std::ofstream(dir + "/target.yaml") << text;
  return dir;
}

TEST(CalibrateCli, RenderedCapturesToRigFileAndReport) {
  const RenderedSet& set = Rendered();
  const std::string args = "calibrate --captures " + set.dir + "/captures --target " + set.dir +
                           "/target.yaml --layout " + set.dir + "/layout.yaml --out " + set.dir +
                           "/rig.yaml --report " + set.dir + "/report.json --lensmodel LENSMODEL_OPENCV5";
  fs::remove_all(set.dir + "/new");
  const testing::Result r = testing::RunCli(args + " --export-cameramodels " + set.dir + "/new/models");
  ASSERT_EQ(r.code, 0) << r.err;
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(fs::exists(set.dir + "/new/models/cam" + std::to_string(k) + ".cameramodel"));
  // The success line names every output, the models by their folder (it
  // named only the rig file and the report).
  EXPECT_NE(r.out.find("wrote " + set.dir + "/rig.yaml, " + set.dir + "/report.json and 4 camera models " +
                       "(camK.cameramodel) in " + set.dir + "/new/models\n"),
            std::string::npos)
      << r.out;
  std::printf("%s", r.out.c_str());
  EXPECT_NE(r.err.find("detect 000"), std::string::npos);  // progress
  // libmrcal's outlier-loop lines are kept off stderr: "mrcal.c(5351): Threw out some outliers (have a total of 1737
  // now); going again", its total the unseen corners too, beside the summary's outlier count. (Anything else the
  // libraries print, a libdogleg CHOLMOD warning say, still comes through.)
  EXPECT_EQ(r.err.find("mrcal.c("), std::string::npos) << r.err;
  EXPECT_NE(r.out.find(" outliers, coverage "), std::string::npos) << r.out;
  const Rig rig = ReadRigFile(set.dir + "/rig.yaml");
  ASSERT_EQ(rig.num_modules(), 2);
  EXPECT_TRUE(fs::exists(set.dir + "/report.json"));
  // Stage 3's per-camera limits: the rendered corners' noise (~0.02 px) is
  // under the floor, a tenth of --max-rms-px (0.1 px), so the floor sets
  // them, and the summary and the report say so (calib/convergence.h).
  EXPECT_NE(r.out.find(" px and the floor 0.100 px, 0.1 x --max-rms-px)\n"), std::string::npos) << r.out;
  {
    std::ifstream report_file(set.dir + "/report.json");
    const nlohmann::json cameras =
        nlohmann::json::parse(report_file).at("stage3_system").at("refined").at("camera_residuals");
    ASSERT_EQ(cameras.size(), 4u);
    for (const nlohmann::json& c : cameras) {
      const double sigma_px = c.at("stage2_sigma_px").get<double>();
      EXPECT_GT(sigma_px, 0.0);
      EXPECT_LT(sigma_px, 0.1) << "rendered corners";
      EXPECT_NEAR(c.at("median_limit_px").get<double>(), kRayleighMedian * std::hypot(sigma_px, 0.1), 1e-9);
      EXPECT_NEAR(c.at("p90_limit_px").get<double>(), kRayleighP90 * std::hypot(sigma_px, 0.1), 1e-9);
    }
  }
  // The board it was calibrated with, for the nightly check (its file by
  // its absolute path; the sizes are the rendered set's, 11x9 of 9 mm).
  ASSERT_TRUE(rig.provenance().target.has_value());
  EXPECT_EQ(rig.provenance().target->file, fs::absolute(set.dir + "/target.yaml").lexically_normal().string());
  EXPECT_EQ(rig.provenance().target->corners_x, 11);
  EXPECT_EQ(rig.provenance().target->square_size_mm, 9.0);
  const auto points = VolumePoints(set.ref_from_volume, Eigen::Vector3d(75, 75, 50), 500, 3);
  const double agreement = testing::ModuleAgreementRms(set.truth, rig, rig.S(0, 1), 0, 1, points);
  std::printf("rendered images: module agreement through S %.4f mm\n", agreement);
  // Rendered corners carry a few hundredths of a pixel of detection error (no
  // lens distortion here), far below the 0.2 px of the corner-level tests.
  EXPECT_LT(agreement, 0.05);
}

// Captures in folders with names of their own (pose_a, pose_b, ...): the
// summary names each camera's worst view by its folder, as the detection
// lines do ("detect pose_d: ..."); it used to print the capture's 0-based
// position among the folders ("worst view: capture 3"), which the user had
// to count out. The report keeps the index and adds the name beside it.
TEST(CalibrateCli, SummaryNamesTheWorstViewsByTheirFolders) {
  const RenderedSet& set = Rendered();
  const std::string named = set.dir + "/named";
  fs::remove_all(named);
  std::vector<fs::path> numbered;
  for (const auto& e : fs::directory_iterator(set.dir + "/captures")) numbered.push_back(e.path());
  std::sort(numbered.begin(), numbered.end());
  ASSERT_EQ(numbered.size(), 8u);
  std::vector<std::string> names;  // by position: the capture index a non-numeric folder gets
  for (size_t k = 0; k < numbered.size(); ++k) {
    names.push_back(std::string("pose_") + char('a' + k));
    fs::create_directories(named + "/" + names.back());
    for (const auto& image : fs::directory_iterator(numbered[k]))
      fs::copy_file(image.path(), named + "/" + names.back() + "/" + image.path().filename().string());
  }
  const std::string report = set.dir + "/named_report.json";
  const testing::Result r = testing::RunCli("calibrate --captures " + named + " --target " + set.dir +
                                            "/target.yaml --layout " + set.dir + "/layout.yaml --out " + set.dir +
                                            "/named_rig.yaml --report " + report + " --lensmodel LENSMODEL_OPENCV5");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("detect pose_d:"), std::string::npos) << r.err;
  const std::string said = "worst view: capture ";
  int lines = 0;
  for (size_t at = r.out.find(said); at != std::string::npos; at = r.out.find(said, at + 1)) {
    ++lines;
    EXPECT_EQ(r.out.compare(at + said.size(), 5, "pose_"), 0) << r.out.substr(at, 50);
  }
  EXPECT_EQ(lines, 4) << r.out;  // one per camera
  std::ifstream f(report);
  const nlohmann::json j = nlohmann::json::parse(f);
  int views = 0;
  for (const auto& camera : j.at("stage1_intrinsics"))
    for (const auto& v : camera.at("worst_views")) {
      ++views;
      const int capture = v.at("capture").get<int>();
      ASSERT_GE(capture, 0);
      ASSERT_LT(capture, 8);
      ASSERT_TRUE(v.contains("capture_name")) << v.dump();
      EXPECT_EQ(v.at("capture_name").get<std::string>(), names[size_t(capture)]);
    }
  EXPECT_GT(views, 0);
}

// A models' folder that cannot be made (a name longer than the file
// system's 255 characters): exit 2 naming it, and nothing left, neither a
// folder above it nor the rig file and report (both used to be written
// before the folder was made, and the folder above it stayed, empty). It is
// refused when claimed, before the calibration (it used to be found only
// when the folder was made after it).
TEST(CalibrateCli, AModelsFolderThatCannotBeMadeLeavesNothing) {
  const RenderedSet& set = Rendered();
  const std::string folder = set.dir + "/long/" + std::string(300, 'x');
  fs::remove_all(set.dir + "/long");
  const testing::Result r =
      testing::RunCli("calibrate --captures " + set.dir + "/captures --target " + set.dir + "/target.yaml --layout " +
                      set.dir + "/layout.yaml --out " + set.dir + "/long_rig.yaml --report " + set.dir +
                      "/long_report.json --lensmodel LENSMODEL_OPENCV5 --export-cameramodels " + folder);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(folder + ": cannot create this folder for the camera models"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("accepted views"), std::string::npos) << "the calibration ran: " << r.err;
  EXPECT_FALSE(fs::exists(set.dir + "/long")) << "the folder made on the way was left behind";
  EXPECT_FALSE(fs::exists(set.dir + "/long_rig.yaml"));
  EXPECT_FALSE(fs::exists(set.dir + "/long_report.json"));
  // A report at a folder the export would create (--report A with
  // --export-cameramodels A/models): refused before the calibration, not
  // found when the models' folder cannot be made after it.
  const std::string report = set.dir + "/a_report_not_a_folder";
  fs::remove_all(report);
  const testing::Result clash =
      testing::RunCli("calibrate --captures " + set.dir + "/captures --target " + set.dir + "/target.yaml --layout " +
                      set.dir + "/layout.yaml --out " + set.dir + "/clash_rig.yaml --report " + report +
                      " --export-cameramodels " + report + "/models");
  EXPECT_EQ(clash.code, 2) << clash.err;
  EXPECT_NE(clash.err.find("is claimed by the report (--report) as a file"), std::string::npos) << clash.err;
  EXPECT_EQ(clash.err.find("detect 000"), std::string::npos) << "refused before any work";
  EXPECT_FALSE(fs::exists(report));
  EXPECT_FALSE(fs::exists(set.dir + "/clash_rig.yaml"));
}

// A stage whose rms is over --max-rms-px did not converge (calib/
// convergence.h): the summary is printed and the report written, to find
// out why; the rig file and the camera models are not, and an earlier run's
// rig file stays. Provoked here with a limit under the rendered corners'
// noise (stage 1 at a few hundredths of a px; each camera then solved from
// every seed candidate, all converging to it): every camera is named, and
// the report says why it stands alone. A real stage 1 that did not
// converge: IntrinsicsWindow.EverySeedIsTriedBeforeACameraIsNamedAsNotConverged
// (calib_e2e_test).
TEST(CalibrateCli, AStageOverTheRmsLimitWritesNoRigFile) {
  const RenderedSet& set = Rendered();
  const std::string dir = set.dir + "/rms_limit";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string rig = dir + "/rig.yaml", report = dir + "/report.json";
  std::ofstream(rig) << "an earlier run's rig file\n";
  const std::string args = "calibrate --captures " + set.dir + "/captures --target " + set.dir +
                           "/target.yaml --layout " + set.dir + "/layout.yaml --out " + rig + " --report " + report +
                           " --lensmodel LENSMODEL_OPENCV5 --export-cameramodels " + dir + "/models";
  const testing::Result r = testing::RunCli(args + " --max-rms-px 0.001");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(rig + ": not written: stage 1 did not converge: camera 0 (cam0) at rms "), std::string::npos)
      << r.err;
  for (const char* camera : {"camera 1 (cam1)", "camera 2 (cam2)", "camera 3 (cam3)"})
    EXPECT_NE(r.err.find(camera), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("over --max-rms-px 0.001 "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the report is in " + report), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("stage 1: intrinsics per camera"), std::string::npos) << "the summary first: " << r.out;
  std::ifstream earlier(rig);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(earlier), {}), "an earlier run's rig file\n");
  EXPECT_NE(r.out.find("stages 2 and 3 not run: stage 1 did not converge"), std::string::npos) << r.out;
  std::ifstream report_file(report);
  const nlohmann::json j = nlohmann::json::parse(report_file);
  EXPECT_EQ(j.at("convergence").at("max_rms_px").get<double>(), 0.001);
  EXPECT_EQ(j.at("convergence").at("not_converged").get<std::string>().rfind("stage 1 did not converge: camera 0", 0),
            0u)
      << j.at("convergence").dump();
  EXPECT_EQ(j.at("stage1_intrinsics").size(), 4u);
  EXPECT_EQ(j.at("stage2_stereo").size(), 0u);  // not run
  EXPECT_FALSE(fs::exists(dir + "/models")) << "camera models of a calibration that did not converge";
  // A limit that is not a positive number: refused before any work.
  const testing::Result zero = testing::RunCli(args + " --max-rms-px 0");
  EXPECT_EQ(zero.code, 2) << zero.err;
  EXPECT_NE(zero.err.find("--max-rms-px"), std::string::npos) << zero.err;
  EXPECT_EQ(zero.err.find("detect 000"), std::string::npos) << "refused before any work: " << zero.err;
}

// A target file whose back face is 100 mm behind the front (the plate is
// 5 mm): stage 3 does not converge and leaves a direction undetermined, so
// ceres::Covariance fails. Ceres said so through glog, raw lines on stderr
// ("WARNING: Logging before InitGoogleLogging() ..." and "E...
// covariance_impl.cc:772] Error: Covariance matrix is near rank deficient
// ...") beside our own refusal; now stderr holds no Ceres line, and the
// report says why no sigma is given.
TEST(CalibrateCli, AnUndeterminedStageThreeSaysSoWithoutCeresLogLines) {
  const RenderedSet& set = Rendered();
  const std::string dir = EditedTargetFolder("thick_plate", "[0, 0, -1, 5]", "[0, 0, -1, 100]");
  const std::string rig = dir + "/rig.yaml", report = dir + "/report.json";
  const testing::Result r =
      testing::RunCli("calibrate --captures " + set.dir + "/captures --target " + dir + "/target.yaml --layout " +
                      set.dir + "/layout.yaml --out " + rig + " --report " + report);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("stereorig calibrate: " + rig + ": not written: stage 3 did not converge"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(rig));
  for (const char* ceres : {"InitGoogleLogging", "covariance_impl", "rank deficient"})
    EXPECT_EQ(r.err.find(ceres), std::string::npos) << ceres << ": " << r.err;
  std::ifstream report_file(report);
  const nlohmann::json j = nlohmann::json::parse(report_file);
  EXPECT_EQ(j.at("stage3_system")
                .at("covariance")
                .get<std::string>()
                .rfind("not computed: the adjustment leaves a direction of its parameters undetermined", 0),
            0u)
      << j.at("stage3_system").at("covariance");
}

// One capture whose module 1 images are another capture's (as the
// commissioning walkthrough made it: cp 007/cam{2,3}.png 003/): each module
// converges alone, stage 3 cannot put the board in one place in capture 003
// and its rms is far over the limit, while its median corner residual,
// what alone was judged, stayed at the noise. Named as stage 3 not
// converging, with the capture, before any plate check: the target file was
// blamed ("back_from_front: stage 3 moved its tx by +0.2019 mm ... fix the
// file"), the report's not_converged empty. Module 1's two cameras still
// agree with each other (one capture's pair, moved together), so stages 1
// and 2 pass.
TEST(CalibrateCli, ACaptureWhoseModulesWereNotTakenTogetherIsNamed) {
  const RenderedSet& set = Rendered();
  const std::string dir = set.dir + "/out_of_sync";
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::copy(set.dir + "/captures", dir + "/captures", fs::copy_options::recursive);
  for (const char* cam : {"/cam2.png", "/cam3.png"})
    fs::copy_file(set.dir + "/captures/005" + cam, dir + "/captures/003" + cam, fs::copy_options::overwrite_existing);
  const std::string rig = dir + "/rig.yaml", report = dir + "/report.json";
  const testing::Result r =
      testing::RunCli("calibrate --captures " + dir + "/captures --target " + set.dir + "/target.yaml --layout " +
                      set.dir + "/layout.yaml --out " + rig + " --report " + report + " --lensmodel LENSMODEL_OPENCV5");
  EXPECT_EQ(r.code, 2) << r.err;
  const std::string last = r.err.substr(r.err.rfind("stereorig calibrate:"));
  EXPECT_EQ(last.rfind("stereorig calibrate: " + rig + ": not written: stage 3 did not converge: rms ", 0), 0u) << last;
  const size_t worst = last.find("; its worst capture");
  ASSERT_NE(worst, std::string::npos) << last;
  EXPECT_EQ(last.substr(last.find(' ', worst + 16) + 1, 11), "003 at rms ") << last;
  EXPECT_NE(last.find("not taken at the same moment"), std::string::npos) << last;
  EXPECT_EQ(last.find("target file's back_from_front is not this plate's"), std::string::npos) << last;
  EXPECT_EQ(testing::Lines(last), 1) << r.err;
  EXPECT_FALSE(fs::exists(rig));
  EXPECT_NE(r.out.find("  worst capture: 003, rms "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not judged against the target file's back_from_front: stage 3 did not converge"),
            std::string::npos)
      << r.out;
  std::ifstream report_file(report);
  const nlohmann::json j = nlohmann::json::parse(report_file);
  const nlohmann::json& s = j.at("stage3_system");
  EXPECT_EQ(j.at("convergence").at("not_converged").get<std::string>().rfind("stage 3 did not converge: rms ", 0), 0u);
  EXPECT_EQ(s.at("wrong_plate").get<std::string>(), "");
  // The capture is what raises the rms: its board is where capture 005
  // put it, tens of px from where module 0 saw it; the others move only as
  // its pull bends S (measured: 003 at 42.5 px, the next 1.44 px, 29 times
  // less, against the rendered corners' few hundredths of a px unbent). The
  // median corner stays under the limit, as it did when it alone was judged.
  const nlohmann::json& captures = s.at("refined").at("capture_rms");
  ASSERT_EQ(captures.size(), 8u);
  EXPECT_EQ(captures[0].at("capture_name").get<std::string>(), "003");
  EXPECT_GT(captures[0].at("rms_px").get<double>(), 10 * captures[1].at("rms_px").get<double>());
  EXPECT_GT(s.at("refined").at("reprojection_rms_px").get<double>(), 1.0);
  EXPECT_LT(s.at("refined").at("median_corner_residual_px").get<double>(), 1.0);
}

// Stage 3's Ceres iteration limit is --max-iterations (it was 100, fixed):
// a solve that reaches it is refused (exit 2, the summary and the report
// written, no rig file), and the refusal names the flag and the limit.
// Its first solve, Horn-only (S and the stereo pairs held, the board
// poses solved), was not checked at all: stopped short, it is warned of on
// stderr and in the report (it only seeds the full adjustment, which is
// judged on its own; its rms is then where it stopped). One iteration
// stops both here: the rendered set's Horn seeds are a few hundredths of a
// px from the optimum, which Ceres's tolerances (1e-12) do not call
// converged after one step.
TEST(CalibrateCli, StageThreesIterationLimitIsAnOptionAndItsSolvesAreChecked) {
  const RenderedSet& set = Rendered();
  const std::string dir = set.dir + "/iterations";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string rig = dir + "/rig.yaml", report = dir + "/report.json";
  const std::string args = "calibrate --captures " + set.dir + "/captures --target " + set.dir +
                           "/target.yaml --layout " + set.dir + "/layout.yaml --out " + rig + " --report " + report +
                           " --lensmodel LENSMODEL_OPENCV5";
  const testing::Result r = testing::RunCli(args + " --max-iterations 1");
  EXPECT_EQ(r.code, 2) << r.err;
  const std::string last = r.err.substr(r.err.rfind("stereorig calibrate:"));
  EXPECT_EQ(last.rfind("stereorig calibrate: " + rig +
                           ": not written: stage 3 did not converge: Ceres ended at "
                           "NO_CONVERGENCE after 1 iteration (",
                       0),
            0u)
      << last;
  EXPECT_NE(last.find("it reached its iteration limit, --max-iterations 1: a solve still converging needs a higher "
                      "one"),
            std::string::npos)
      << last;
  EXPECT_FALSE(fs::exists(rig));
  EXPECT_NE(
      r.err.find(
          "calibrate: warning: stage 3's Horn-only solve (S and the stereo pairs held at Horn's and "
          "stage 2's, the board poses solved) did not converge: Ceres ended at NO_CONVERGENCE after 1 iteration ("),
      std::string::npos)
      << r.err;
  EXPECT_NE(r.out.find("  (the Horn-only rms is where its solve stopped: Ceres ended at NO_CONVERGENCE"),
            std::string::npos)
      << r.out;
  std::ifstream report_file(report);
  const nlohmann::json j = nlohmann::json::parse(report_file);
  const nlohmann::json& s = j.at("stage3_system");
  EXPECT_EQ(s.at("max_iterations").get<int>(), 1);
  EXPECT_EQ(s.at("horn_only").at("solver_problem").get<std::string>().rfind("Ceres ended at NO_CONVERGENCE", 0), 0u);
  EXPECT_EQ(s.at("solver_problem").get<std::string>().rfind("Ceres ended at NO_CONVERGENCE", 0), 0u);
  ASSERT_EQ(j.at("warnings").size(), 1u) << j.at("warnings").dump();
  EXPECT_EQ(j.at("warnings")[0].get<std::string>().rfind("stage 3's Horn-only solve", 0), 0u);

  // Not a whole number >= 1 (that int holds): refused before any work,
  // naming the flag.
  for (const char* bad : {"0", "-3", "1.5", "ten", "1e3", "99999999999"}) {
    const testing::Result b = testing::RunCli(args + " --max-iterations " + bad);
    EXPECT_EQ(b.code, 2) << bad;
    EXPECT_EQ(b.err.rfind("stereorig calibrate: --max-iterations: must be ", 0), 0u) << b.err;
    EXPECT_EQ(b.err.find("detect 000"), std::string::npos) << "refused before any work: " << b.err;
  }
  // Leading zeros are decimal, as the check reads them: CLI11's own
  // conversion, after it, ran 010 as 8 and refused 09 ("Could not convert").
  for (const auto& [text, count] : {std::pair<std::string, int>{"010", 10}, {"09", 9}}) {
    fs::remove(report);
    const testing::Result z = testing::RunCli(args + " --max-iterations " + text);
    ASSERT_TRUE(fs::exists(report)) << text << ": " << z.err;
    std::ifstream f(report);
    EXPECT_EQ(nlohmann::json::parse(f).at("stage3_system").at("max_iterations").get<int>(), count) << text;
  }
  const testing::Result help = testing::RunCli("calibrate --help");
  EXPECT_NE(help.out.find("--max-iterations INT=100"), std::string::npos) << help.out;
}

// --max-rms-px also sets the floor of stage 3's per-camera limits (a tenth
// of it, calib/convergence.h): its help says what that floor lets through,
// which raising the limit widens.
TEST(CalibrateCli, MaxRmsPxHelpSaysWhatStageThreesFloorLetsThrough) {
  const testing::Result help = testing::RunCli("calibrate --help");
  EXPECT_NE(help.out.find("or a tenth of this where that noise is less: a floor that grows with it (at 10, a module "
                          "moved 1 mm between captures passes) and on low-noise corners passes a bias in S of a few "
                          "of its sigmas\n"),
            std::string::npos)
      << help.out;
}

TEST(CalibrateCli, RefusesImagesOfTheWrongSize) {
  const RenderedSet set = Render("calib_cli_size", 2, 6);
  cv::Mat noise(480, 640, CV_8UC1);  // noise: its image data far longer than the 200 bytes kept below
  cv::randu(noise, 0, 256);
  cv::imwrite(set.dir + "/captures/001/cam1.png", noise);
  const std::string calibrate = "calibrate --captures " + set.dir + "/captures --target " + set.dir +
                                "/target.yaml --layout " + set.dir + "/layout.yaml --out " + set.dir +
                                "/rig.yaml --report " + set.dir + "/report.json";
  const testing::Result r = testing::RunCli(calibrate);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(testing::Lines(r.err.substr(r.err.rfind("stereorig calibrate:"))), 1) << r.err;
  // One image of each size: neither is the odd one out, both are named.
  EXPECT_NE(r.err.find("cam1's images differ in size, and no size is most of them: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("640x480: " + set.dir + "/captures/001/cam1.png"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(set.dir + "/rig.yaml"));

  // The size is read from the header, before the pixels are decoded: the
  // same wrong-size image cut short after its first 200 bytes (its header
  // whole, its image data not) is refused for its size, not for the
  // damage a decode would have met first.
  const std::string cut = set.dir + "/captures/001/cam1.png";
  std::string bytes;
  {
    std::ifstream in(cut, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  ASSERT_GT(bytes.size(), 200u);
  std::ofstream(cut, std::ios::binary | std::ios::trunc) << bytes.substr(0, 200);
  const testing::Result cut_run = testing::RunCli(calibrate);
  EXPECT_EQ(cut_run.code, 2);
  EXPECT_NE(cut_run.err.find("640x480: " + set.dir + "/captures/001/cam1.png"), std::string::npos) << cut_run.err;
  EXPECT_FALSE(fs::exists(set.dir + "/rig.yaml"));
}

// A simulated dataset without target captures (`simulate
// --calibration-captures 0`: spec.yaml and truth/, no calibration/) is
// named as such; its truth/ and scenes/ were taken for capture folders
// ("truth/cam0.png: missing (each capture needs camK.png ...)").
TEST(CalibrateCli, ADatasetWithoutCapturesIsNamedSo) {
  const std::string dir = ::testing::TempDir() + "/calib_cli_no_captures_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir + "/ds/truth");
  fs::create_directories(dir + "/ds/scenes/sphere/active");
  std::ofstream(dir + "/ds/spec.yaml") << "a spec\n";
  WriteTargetFile(DefaultTarget(), dir + "/ds/target.yaml");
  std::ofstream(dir + "/ds/layout.yaml") << "modules:\n  - {name: module0, left: 0, right: 1}\n";
  const testing::Result r =
      testing::RunCli("calibrate --captures " + dir + "/ds --target " + dir + "/ds/target.yaml --layout " + dir +
                      "/ds/layout.yaml --out " + dir + "/rig.yaml --report " + dir + "/report.json");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("stereorig calibrate: " + dir +
                       "/ds: is a simulated dataset (spec.yaml, truth/) with no target captures: a dataset's are in "
                       "its calibration/ folder, which this one lacks"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir + "/rig.yaml"));
  fs::remove_all(dir);
}

// A target file of another grid (a plain 9 x 6 board's) against captures of
// the default 11 x 9 board: next to no image shows a board of the file's
// grid, and the refusal asks whether the board was seen and whether the file
// is its; it said "too few views" and nothing more.
TEST(CalibrateCli, ATargetFileOfAnotherGridIsQuestionedWhenNoBoardIsFound) {
  const RenderedSet set = Render("calib_cli_plain", 2, 8);
  WriteTargetFile(PlainTarget(9, 6, 9.0), set.dir + "/plain_9x6.yaml");
  const testing::Result r = testing::RunCli("calibrate --captures " + set.dir + "/captures --target " + set.dir +
                                            "/plain_9x6.yaml --layout " + set.dir + "/layout.yaml --out " + set.dir +
                                            "/rig.yaml --report " + set.dir + "/report.json");
  EXPECT_EQ(r.code, 2);
  const std::string last = r.err.substr(r.err.rfind("stereorig calibrate:"));
  EXPECT_EQ(testing::Lines(last), 1) << r.err;
  EXPECT_NE(last.find("images show no board as " + set.dir +
                      "/plain_9x6.yaml describes it (corners_x 9, corners_y 6, inner corners along a row, along a "
                      "column): is the board in view and lit, and is that file this board's target file?"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(set.dir + "/rig.yaml"));
}

TEST(CalibrateCli, RefusesAFaceSeenByTheWrongModule) {
  const RenderedSet set = Render("calib_cli_face", 2, 7);
  std::ofstream(set.dir + "/layout.yaml") << "modules:\n  - {name: module0, left: 0, right: 1, face: back}\n"
                                             "  - {name: module1, left: 2, right: 3, face: front}\n";
  const testing::Result r =
      testing::RunCli("calibrate --captures " + set.dir + "/captures --target " + set.dir + "/target.yaml --layout " +
                      set.dir + "/layout.yaml --out " + set.dir + "/rig.yaml --report " + set.dir + "/report.json");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("wrong module"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(set.dir + "/rig.yaml"));
}

// The rig file and the report are checked before the captures are read: one
// path for both left the report in place of the rig file with exit 0, and a
// report into a missing folder failed after the whole calibration with the
// rig file already written. Each is refused at once (no capture needed: the
// folder given does not even exist), and nothing is written.
TEST(CalibrateCli, OutputsThatCollideOrHaveNoFolderAreRefusedBeforeAnyWork) {
  const std::string dir = ::testing::TempDir() + "/calib_cli_paths";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir + "/layout.yaml") << "modules:\n  - {name: module0, left: 0, right: 1}\n";
  const std::string inputs =
      "calibrate --captures " + dir + "/no_captures --target " + dir + "/target.yaml --layout " + dir + "/layout.yaml";
  testing::Result r = testing::RunCli(inputs + " --out " + dir + "/rig.yaml --report " + dir + "/rig.yaml");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("rig.yaml: would be written twice (the rig file (--out) and the report (--report))"),
            std::string::npos)
      << r.err;
  r = testing::RunCli(inputs + " --out " + dir + "/rig.yaml --report " + dir + "/missing/report.json");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("report.json: its folder does not exist"), std::string::npos) << r.err;
  r = testing::RunCli(inputs + " --out " + dir + "/layout.yaml --report " + dir + "/report.json");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("layout.yaml: is the layout file (--layout)"), std::string::npos) << r.err;
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  // The camera models' folder (created if needed): not a file, not under
  // a file, not the rig file's or the report's path (create_directories
  // failed there only after both were written).
  std::ofstream(dir + "/models") << "a file, not a folder\n";
  const std::pair<std::string, std::string> folders[] = {
      {dir + "/models", "models: is a file, not a folder"},
      {dir + "/models/sub", "/models is a file, not a folder"},
      {dir + "/rig.yaml", "rig.yaml: is claimed by the rig file (--out) as a file"}};
  for (const auto& [folder, says] : folders) {
    r = testing::RunCli(inputs + " --out " + dir + "/rig.yaml --report " + dir + "/report.json --export-cameramodels " +
                        folder);
    EXPECT_EQ(r.code, 2) << folder;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
  }
  // Each model file too: a rig file named models/cam1.cameramodel would be
  // replaced by camera 1's model after the calibration.
  fs::create_directories(dir + "/m2");
  r = testing::RunCli(inputs + " --out " + dir + "/m2/cam1.cameramodel --report " + dir +
                      "/report.json --export-cameramodels " + dir + "/m2");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("cam1.cameramodel: would be written twice (the rig file (--out) and camera 1's model"),
            std::string::npos)
      << r.err;
  // (Each message names an output, which only the checks before the
  // calibration can: the captures and target given do not exist, so the
  // calibration would have failed naming those.)
}

// Options are named by their flags, not the library's fields
// ("options.lensmodel", "options.seed_focal_px"), with the valid values;
// an output under a file says that it is a file, not that its folder is
// missing. Refused before any work (the captures given do not exist).
TEST(CalibrateCli, OptionsAreNamedByTheirFlags) {
  const std::string dir = ::testing::TempDir() + "/calib_cli_flags";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir + "/layout.yaml") << "modules:\n  - {name: module0, left: 0, right: 1}\n";
  std::ofstream(dir + "/rig.yaml") << "a file, not a folder\n";
  const std::string inputs = "calibrate --captures " + dir + "/no_captures --target " + dir + "/target.yaml --layout " +
                             dir + "/layout.yaml --report " + dir + "/report.json";
  testing::Result r = testing::RunCli(inputs + " --out " + dir + "/out.yaml --lensmodel OPENCV8");
  EXPECT_EQ(r.code, 2);
  const std::string models =
      "LENSMODEL_OPENCV4, LENSMODEL_OPENCV5, LENSMODEL_OPENCV8, LENSMODEL_OPENCV12 or "
      "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=.._Ny=.._fov_x_deg=..";
  EXPECT_NE(r.err.find("--lensmodel: unknown lens model 'OPENCV8' (LENSMODEL_OPENCV8?); use " + models),
            std::string::npos)
      << r.err;
  // The refusal, the help and what is accepted agree: every model listed
  // passes the options check (the run then stops at the missing target),
  // and a pinhole, which cannot hold a lens's distortion, is refused (it
  // was accepted, unlisted, and passed --max-rms-px at 15x the corners'
  // noise on the default rig's lenses).
  for (const char* model : {"LENSMODEL_OPENCV4", "LENSMODEL_OPENCV5", "LENSMODEL_OPENCV8", "LENSMODEL_OPENCV12",
                            "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=8_Ny=6_fov_x_deg=45"}) {
    r = testing::RunCli(inputs + " --out " + dir + "/out.yaml --lensmodel " + model);
    EXPECT_EQ(r.code, 2) << model;
    EXPECT_EQ(r.err.find("--lensmodel"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("target.yaml: no such file"), std::string::npos) << r.err;
  }
  r = testing::RunCli(inputs + " --out " + dir + "/out.yaml --lensmodel LENSMODEL_PINHOLE");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("stereorig calibrate: --lensmodel: 'LENSMODEL_PINHOLE' is not calibrated here", 0), 0u)
      << r.err;
  EXPECT_NE(r.err.find("use " + models), std::string::npos) << r.err;
  const testing::Result help = testing::RunCli("calibrate --help");
  for (const char* model : {"LENSMODEL_OPENCV4", "LENSMODEL_OPENCV5", "LENSMODEL_OPENCV8", "LENSMODEL_OPENCV12",
                            "LENSMODEL_SPLINED_STEREOGRAPHIC", "not LENSMODEL_PINHOLE"})
    EXPECT_NE(help.out.find(model), std::string::npos) << model << "\n" << help.out;
  r = testing::RunCli(inputs + " --out " + dir + "/out.yaml --focal -5");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--focal"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("options."), std::string::npos) << r.err;
  r = testing::RunCli(inputs + " --out " + dir + "/rig.yaml/x");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("rig.yaml/x: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/rig.yaml is a file, not a folder"), std::string::npos) << r.err;
}

// A target file hand-edited to corners_x 12 for the rendered 11 x 9 board
// (its tags where they were): the tags place the board, each view keeps the
// corners it finds, and the calibration succeeds with the 12th column never
// seen and the rig recording a board of 12 x 9. A warning names the file
// and the column; the rendered set's own file gives none.
TEST(CalibrateCli, ACornerColumnNoViewShowedIsWarnedOf) {
  const RenderedSet& set = Rendered();
  const std::string dir = EditedTargetFolder("t12", "corners_x: 11", "corners_x: 12");
  const std::string args = "calibrate --captures " + set.dir + "/captures --layout " + set.dir + "/layout.yaml --out " +
                           dir + "/rig.yaml --report " + dir + "/report.json --lensmodel LENSMODEL_OPENCV5 --target ";
  const testing::Result r = testing::RunCli(args + dir + "/target.yaml");
  EXPECT_NE(r.err.find("calibrate: warning: " + dir +
                       "/target.yaml says corners_x 12, corners_y 9 (inner corners along a row, along a column), but "
                       "its column 12 of corners (1-based) never showed in any of the "),
            std::string::npos)
      << r.err;
  const testing::Result right = testing::RunCli(args + set.dir + "/target.yaml");
  EXPECT_EQ(right.code, 0) << right.err;
  EXPECT_EQ(right.err.find("never showed"), std::string::npos) << right.err;
}

// A splined model's configuration is judged with the options: mrcal parsed
// it and judged it only at its first projection, after the whole detection
// pass (Nx=4_Ny=3 aborted there, SIGABRT, exit 134), or never (fov_x_deg=400
// wrote a rig, fov_x_deg=0 ran the whole solve). Refused before any work:
// the captures given do not exist, and the refusal is not theirs.
TEST(CalibrateCli, ASplinedModelMrcalCannotBuildIsRefused) {
  const std::string dir = ::testing::TempDir() + "/calib_cli_spline";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir + "/layout.yaml") << "modules:\n  - {name: module0, left: 0, right: 1}\n";
  const std::string inputs = "calibrate --captures " + dir + "/no_captures --target " + dir + "/target.yaml --layout " +
                             dir + "/layout.yaml --out " + dir + "/out.yaml --report " + dir + "/report.json";
  const std::string spline = "LENSMODEL_SPLINED_STEREOGRAPHIC_";
  const std::string fov = ", the horizontal field of view the stereographic projection can span, deg";
  const std::pair<std::string, std::string> refused[] = {
      {"order=3_Nx=4_Ny=3_fov_x_deg=50", "Nx=4 Ny=3: an order 3 spline needs Nx and Ny >= 4 (mrcal's minimum)"},
      {"order=3_Nx=3_Ny=8_fov_x_deg=50", "Nx=3 Ny=8: an order 3 spline needs Nx and Ny >= 4 (mrcal's minimum)"},
      {"order=2_Nx=2_Ny=6_fov_x_deg=50", "Nx=2 Ny=6: an order 2 spline needs Nx and Ny >= 3 (mrcal's minimum)"},
      {"order=4_Nx=8_Ny=6_fov_x_deg=50", "order=4: mrcal's splines are of order 2 or 3"},
      {"order=1_Nx=8_Ny=6_fov_x_deg=50", "order=1: mrcal's splines are of order 2 or 3"},
      {"order=3_Nx=8_Ny=6_fov_x_deg=0", "fov_x_deg=0: must be in (0, 360)" + fov},
      {"order=3_Nx=8_Ny=6_fov_x_deg=360", "fov_x_deg=360: must be in (0, 360)" + fov},
      {"order=3_Nx=8_Ny=6_fov_x_deg=400", "fov_x_deg=400: must be in (0, 360)" + fov}};
  for (const auto& [config, says] : refused) {
    const testing::Result r = testing::RunCli(inputs + " --lensmodel " + spline + config);
    EXPECT_EQ(r.code, 2) << config;
    EXPECT_EQ(r.err, "stereorig calibrate: --lensmodel: '" + spline + config + "': " + says + "\n") << r.err;
  }
  // Each limit's edge is accepted (the run then stops at the missing target).
  for (const char* config : {"order=3_Nx=4_Ny=4_fov_x_deg=1", "order=2_Nx=3_Ny=3_fov_x_deg=359"}) {
    const testing::Result r = testing::RunCli(inputs + " --lensmodel " + spline + config);
    EXPECT_EQ(r.code, 2) << config;
    EXPECT_NE(r.err.find("target.yaml: no such file"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir + "/out.yaml"));
  EXPECT_FALSE(fs::exists(dir + "/report.json"));
}

// The capture images are inputs too (calib/capture_folder.h,
// CaptureFolderImages): --out, --report or --export-cameramodels named like
// one of them, in a captures folder or a dataset's calibration/, would
// replace it. Refused before any work, one line naming the path, the images
// byte-identical and nothing written. (The target file given does not
// exist: only the check before the calibration can name the output.)
TEST(CalibrateCli, AnOutputOverACaptureImageIsRefused) {
  const std::string dir = ::testing::TempDir() + "/calib_cli_images";
  fs::remove_all(dir);
  fs::create_directories(dir + "/caps/000");
  fs::create_directories(dir + "/ds/calibration/001");
  std::ofstream(dir + "/layout.yaml") << "modules:\n  - {name: module0, left: 0, right: 1}\n";
  const std::vector<std::string> images = {dir + "/caps/000/cam0.png", dir + "/caps/000/cam1.png",
                                           dir + "/ds/calibration/001/cam1.png"};
  for (const std::string& image : images) std::ofstream(image) << "an image\n";
  auto calibrate = [&](const std::string& captures, const std::string& outputs) {
    return testing::RunCli("calibrate --captures " + dir + "/" + captures + " --target " + dir +
                           "/target.yaml --layout " + dir + "/layout.yaml " + outputs);
  };
  const std::string rig = " --out " + dir + "/rig.yaml", report = " --report " + dir + "/report.json";
  const struct {
    std::string captures, outputs, says;
  } cases[] = {
      {"caps", " --out " + images[0] + report, images[0] + ": is a capture image (--captures)"},
      {"caps", rig + " --report " + images[1], images[1] + ": is a capture image (--captures)"},
      {"ds", rig + " --report " + images[2], images[2] + ": is a capture image (--captures)"},
      {"caps", rig + report + " --export-cameramodels " + images[0], images[0] + ": is a capture image (--captures)"}};
  for (const auto& c : cases) {
    const testing::Result r = calibrate(c.captures, c.outputs);
    EXPECT_EQ(r.code, 2) << c.outputs;
    EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
  }
  for (const std::string& image : images) {
    std::ifstream f(image);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(f), {}), "an image\n") << image;
  }
  EXPECT_FALSE(fs::exists(dir + "/rig.yaml"));
  EXPECT_FALSE(fs::exists(dir + "/report.json"));
}

// --- Robustness walkthrough 44 (fuzz-bounds): the layout against the captures ---

// A layout naming two modules "module0" calibrated (exit 0) a rig of two
// "module0". Refused when the layout is read, before any work: the captures
// given do not exist, and the refusal is not theirs.
TEST(CalibrateCli, ALayoutWithTwoModulesOfOneNameIsRefused) {
  const std::string dir = ::testing::TempDir() + "/calib_cli_dup_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir + "/layout.yaml") << "modules:\n  - {name: module0, left: 0, right: 1}\n"
                                         "  - {name: module0, left: 2, right: 3}\n";
  const testing::Result r =
      testing::RunCli("calibrate --captures " + dir + "/no_captures --target " + dir + "/target.yaml --layout " + dir +
                      "/layout.yaml --out " + dir + "/rig.yaml --report " + dir + "/report.json");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "stereorig calibrate: " + dir +
                       "/layout.yaml: modules[1].name: module0 is used twice (modules[0] too): each module needs a "
                       "name of its own\n");
  EXPECT_FALSE(fs::exists(dir + "/rig.yaml"));
  EXPECT_FALSE(fs::exists(dir + "/report.json"));
  fs::remove_all(dir);
}

// Captures holding cameras no module of the layout names: calibrate left
// them out and said nothing (a one-module rig from four cameras' captures).
// A one-module calibration may be meant, so it goes on, with a warning on
// stderr and in the report naming the cameras left out.
// The captures are given through a link whose name holds an escape
// sequence (ESC [31m): the warning on stderr shows it escaped, as error
// lines do (it reached the terminal raw), the report keeps it as it is.
TEST(CalibrateCli, CamerasTheLayoutLeavesOutAreWarnedOf) {
  namespace fs = std::filesystem;
  const RenderedSet& set = Rendered();
  std::ofstream(set.dir + "/one_module.yaml") << "modules:\n  - {name: module0, left: 0, right: 1, face: front}\n";
  const std::string captures = set.dir + "/cap\x1b[31m";
  fs::remove(captures);
  fs::create_directory_symlink(set.dir + "/captures", captures);
  const testing::Result r =
      testing::RunCli("calibrate --captures '" + captures + "' --target " + set.dir + "/target.yaml --layout " +
                      set.dir + "/one_module.yaml --out " + set.dir + "/one.yaml --report " + set.dir +
                      "/one.json --lensmodel LENSMODEL_OPENCV5");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string held =
      " holds cam2.png (in 8 captures), cam3.png (in 8 captures), but the layout "
      "names cameras 0 to 1 only: the rig leaves them out (name them in a module of the "
      "layout to calibrate them)";
  const std::string warning = captures + held;
  EXPECT_NE(r.err.find("calibrate: warning: " + set.dir + "/cap\\x1B[31m" + held + "\n"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << "a raw ESC reached stderr";
  EXPECT_EQ(ReadRigFile(set.dir + "/one.yaml").num_cameras(), 2);
  std::ifstream report(set.dir + "/one.json");
  const nlohmann::json json = nlohmann::json::parse(report);
  EXPECT_EQ(json["warnings"], nlohmann::json::array({warning})) << json["warnings"].dump();
  // The layout of every camera leaves none out.
  EXPECT_EQ(CamerasLeftOutNote(set.dir + "/captures", 4), "");
}

// Copies of one capture (a trigger delivering one frame again, or the board
// left still) count as one board pose: eight copies calibrated, exit 0,
// with a baseline 10.8 mm off and sigmas shrunk by sqrt(8). Five copies
// (the default's minimum of views) are refused, naming the camera and the
// captures; a copy among enough poses calibrates, with a warning naming it
// by its folder.
TEST(CalibrateCli, CopiesOfOneCaptureAreOneBoardPose) {
  const RenderedSet& set = Rendered();
  std::ofstream(set.dir + "/one_module.yaml") << "modules:\n  - {name: module0, left: 0, right: 1, face: front}\n";
  const std::string copies = set.dir + "/copies";
  fs::remove_all(copies);
  for (int c = 1; c <= 5; ++c)
    for (const std::string image : {"cam0.png", "cam1.png"}) {
      fs::create_directories(copies + "/00" + std::to_string(c));
      fs::copy_file(set.dir + "/captures/000/" + image, copies + "/00" + std::to_string(c) + "/" + image);
    }
  const std::string args = " --target " + set.dir + "/target.yaml --layout " + set.dir + "/one_module.yaml --out " +
                           set.dir + "/copies.yaml --report " + set.dir + "/copies.json";
  const testing::Result r = testing::RunCli("calibrate --captures " + copies + args);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(copies + ": camera 0 (cam0): too few distinct board poses: its 5 usable views show 1, need at "
                                "least 5; repeated: captures 001, 002, 003, 004 and 005 (corners apart by their noise "
                                "alone"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(set.dir + "/copies.yaml"));
  EXPECT_FALSE(fs::exists(set.dir + "/copies.json"));
  // A named folder among them is named by its name, not by its index (6,
  // the one after the largest number: a folder that does not exist).
  fs::rename(copies + "/005", copies + "/retake");
  const testing::Result named = testing::RunCli("calibrate --captures " + copies + args);
  EXPECT_EQ(named.code, 2);
  EXPECT_NE(named.err.find("repeated: captures 001, 002, 003, 004 and retake (corners"), std::string::npos)
      << named.err;

  // The set's 8 captures and capture 000 again as 008.
  const std::string again = set.dir + "/again";
  fs::remove_all(again);
  fs::create_directories(again);
  for (int c = 0; c < 8; ++c)
    for (const std::string image : {"cam0.png", "cam1.png"}) {
      fs::create_directories(again + "/00" + std::to_string(c));
      fs::copy_file(set.dir + "/captures/00" + std::to_string(c) + "/" + image,
                    again + "/00" + std::to_string(c) + "/" + image);
    }
  fs::copy(again + "/000", again + "/008");
  const testing::Result a = testing::RunCli("calibrate --captures " + again + args);
  ASSERT_EQ(a.code, 0) << a.err;
  for (const std::string camera : {"camera 0 (cam0)", "camera 1 (cam1)"})
    EXPECT_NE(a.err.find("calibrate: warning: " + camera + " sees one board pose again in captures 000, 008"),
              std::string::npos)
        << a.err;
  std::ifstream report(set.dir + "/copies.json");
  const nlohmann::json json = nlohmann::json::parse(report);
  EXPECT_EQ(json["warnings"].size(), 2u) << json["warnings"].dump();
}

// A module of an empty name was accepted (exit 0, a rig whose module has
// no name); refused when the layout is read, before any image.
TEST(CalibrateCli, ALayoutModuleWithAnEmptyNameIsRefused) {
  const std::string dir = ::testing::TempDir() + "/calib_cli_empty_name_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir + "/layout.yaml") << "modules:\n  - {name: \"\", left: 0, right: 1}\n";
  const testing::Result r =
      testing::RunCli("calibrate --captures " + dir + "/no_captures --target " + dir + "/target.yaml --layout " + dir +
                      "/layout.yaml --out " + dir + "/rig.yaml --report " + dir + "/report.json");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "stereorig calibrate: " + dir +
                       "/layout.yaml: modules[0].name: is empty: each module needs a name of its own\n");
  EXPECT_FALSE(fs::exists(dir + "/rig.yaml"));
  EXPECT_FALSE(fs::exists(dir + "/report.json"));
  fs::remove_all(dir);
}

// The rendered set's captures 000..`count - 1`, cameras 0 and 1 only (module
// 0 of the layout one_module.yaml), copied into a fresh folder `dir`.
void CopyModuleZeroCaptures(const RenderedSet& set, const std::string& dir, int count) {
  fs::remove_all(dir);
  for (int c = 0; c < count; ++c) {
    const std::string capture = "/00" + std::to_string(c);
    fs::create_directories(dir + capture);
    for (const std::string image : {"/cam0.png", "/cam1.png"})
      fs::copy_file(set.dir + "/captures" + capture + image, dir + capture + image);
  }
  std::ofstream(set.dir + "/one_module.yaml") << "modules:\n  - {name: module0, left: 0, right: 1, face: front}\n";
}

// An image of the wrong size in the first capture: the first image read set
// the size, and the error named a right one (001/cam1.png). The odd one
// out is named, against the size most of the camera's images have.
TEST(CalibrateCli, AWrongSizedImageInTheFirstCaptureIsTheOneNamed) {
  const RenderedSet& set = Rendered();
  const std::string dir = set.dir + "/odd_first";
  CopyModuleZeroCaptures(set, dir, 3);
  cv::Mat noise(480, 640, CV_8UC1);
  cv::randu(noise, 0, 256);
  cv::imwrite(dir + "/000/cam1.png", noise);
  const testing::Result r =
      testing::RunCli("calibrate --captures " + dir + " --target " + set.dir + "/target.yaml --layout " + set.dir +
                      "/one_module.yaml --out " + dir + "/rig.yaml --report " + dir + "/report.json");
  EXPECT_EQ(r.code, 2);
  const Camera& cam1 = set.truth.camera(1);
  EXPECT_EQ(r.err, "stereorig calibrate: " + dir +
                       "/000/cam1.png: image of the wrong size: 640x480, but 2 of cam1's 3 "
                       "images are " +
                       std::to_string(cam1.imager_width_px()) + "x" + std::to_string(cam1.imager_height_px()) + "\n");
  EXPECT_FALSE(fs::exists(dir + "/rig.yaml"));
}

// Sub-folders of the captures that are no captures: the camera models an
// earlier run wrote beside them (--export-cameramodels DIR/models), and a
// viewer's hidden .thumbs. Each was taken for a capture ("models/cam0.png:
// missing"); they are skipped and named on stdout. A folder holding some
// cameras' images but not all is still a capture, refused for the missing.
TEST(CalibrateCli, FoldersHoldingNoCaptureAreSkippedAndNamed) {
  const RenderedSet& set = Rendered();
  const std::string dir = set.dir + "/beside";
  CopyModuleZeroCaptures(set, dir, 8);
  fs::create_directories(dir + "/.thumbs");
  fs::copy_file(dir + "/000/cam0.png", dir + "/.thumbs/cam0.png");
  const std::string args = " --target " + set.dir + "/target.yaml --layout " + set.dir + "/one_module.yaml --out " +
                           dir + "/rig.yaml --report " + dir + "/report.json";
  testing::Result r =
      testing::RunCli("calibrate --captures " + dir + args + " --export-cameramodels " + dir + "/models");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("skipped " + dir + "/.thumbs: not a capture (a hidden folder, or one holding no camK.png)\n"),
            std::string::npos)
      << r.out;
  ASSERT_TRUE(fs::exists(dir + "/models/cam0.cameramodel"));
  // Run again, the models now among the captures.
  r = testing::RunCli("calibrate --captures " + dir + args);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("skipped " + dir + "/models: not a capture"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("calibrate: 8 captures, "), std::string::npos) << r.err;
  // Some cameras' images but not all: a capture that lacks one.
  fs::remove(dir + "/003/cam1.png");
  r = testing::RunCli("calibrate --captures " + dir + args);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(dir + "/003/cam1.png: missing"), std::string::npos) << r.err;
}

// Folders holding images, none named camK.png (Cam0.png, cam00.png,
// left.png, or images a folder deeper), were skipped as "no capture": a
// night lost captures without a word. They are refused, naming the folder
// and its files; a hidden folder is still skipped, and named in a refusal
// ("too few views" is likely its doing) and in the report's warnings.
TEST(CalibrateCli, AMisnamedCaptureIsRefusedAndASkippedOneNamedInRefusalAndReport) {
  const RenderedSet& set = Rendered();
  const std::string dir = set.dir + "/misnamed";
  const std::string args = " --target " + set.dir + "/target.yaml --layout " + set.dir + "/one_module.yaml --out " +
                           dir + "/rig.yaml --report " + dir + "/report.json";
  for (const std::vector<std::string>& names : std::vector<std::vector<std::string>>{
           {"Cam0.png", "Cam1.png"}, {"cam0.PNG", "cam1.PNG"}, {"cam00.png", "cam01.png"}, {"left.png", "right.png"}}) {
    CopyModuleZeroCaptures(set, dir, 8);
    fs::rename(dir + "/003/cam0.png", dir + "/003/" + names[0]);
    fs::rename(dir + "/003/cam1.png", dir + "/003/" + names[1]);
    const testing::Result r = testing::RunCli("calibrate --captures " + dir + args);
    EXPECT_EQ(r.code, 2) << names[0];
    EXPECT_NE(r.err.find(dir + "/003: holds " + names[0] + ", " + names[1] + " but no camK.png"), std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir + "/rig.yaml"));
  }
  // Eight captures, one hidden: calibrated, the report naming it.
  CopyModuleZeroCaptures(set, dir, 8);
  fs::rename(dir + "/005", dir + "/.005");
  testing::Result r = testing::RunCli("calibrate --captures " + dir + args);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream f(dir + "/report.json");
  const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  ASSERT_TRUE(j.is_object());
  bool named = false;
  for (const auto& w : j.at("warnings")) named |= w.get<std::string>().find("skipped: " + dir + "/.005") == 0;
  EXPECT_TRUE(named) << j.at("warnings").dump();
  // Five, one hidden: too few views, and the refusal names the hidden one.
  CopyModuleZeroCaptures(set, dir, 5);
  fs::rename(dir + "/004", dir + "/.004");
  r = testing::RunCli("calibrate --captures " + dir + args);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("too few views"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("; skipped: " + dir + "/.004 (not captures"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

// Models of another rig in the --export-cameramodels folder (cam2 and cam3
// of an earlier two-module calibration) stayed beside this one-module
// calibration's cam0 and cam1 without a word. Warned of, naming them.
TEST(CalibrateCli, ModelsOfAnotherRigInTheModelsFolderAreWarnedOf) {
  const RenderedSet& set = Rendered();
  const std::string dir = set.dir + "/other_models";
  CopyModuleZeroCaptures(set, dir + "/captures", 8);
  fs::create_directories(dir + "/models");
  for (const char* name : {"cam2.cameramodel", "cam3.cameramodel"})
    std::ofstream(dir + "/models/" + name) << "another rig's\n";
  std::ofstream(dir + "/models/.tmp-999-0-cam0.cameramodel") << "an interrupted write's\n";  // hidden: not a model
  const testing::Result r =
      testing::RunCli("calibrate --captures " + dir + "/captures --target " + set.dir + "/target.yaml --layout " +
                      set.dir + "/one_module.yaml --out " + dir + "/rig.yaml --report " + dir +
                      "/report.json --export-cameramodels " + dir + "/models");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("calibrate: warning: " + dir +
                       "/models also holds cam2.cameramodel, cam3.cameramodel, not written by this run: another "
                       "rig's models?"),
            std::string::npos)
      << r.err;
  EXPECT_TRUE(fs::exists(dir + "/models/cam0.cameramodel"));
  // Kept in the report, as every warning calibrate prints is (docs/formats.md).
  std::ifstream f(dir + "/report.json");
  const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  ASSERT_TRUE(j.is_object());
  int kept = 0;
  for (const auto& w : j.at("warnings"))
    kept += w.get<std::string>() == dir +
                                        "/models also holds cam2.cameramodel, cam3.cameramodel, not written by this "
                                        "run: another rig's models? (remove them, or export into a folder of its own)";
  EXPECT_EQ(kept, 1) << j.at("warnings").dump();
  // A run refused after its solve (every stage over a 0.001 px limit) writes
  // no model there: no warning of the others.
  const testing::Result refused =
      testing::RunCli("calibrate --captures " + dir + "/captures --target " + set.dir + "/target.yaml --layout " +
                      set.dir + "/one_module.yaml --out " + dir + "/rig2.yaml --report " + dir +
                      "/report2.json --max-rms-px 0.001 --export-cameramodels " + dir + "/models");
  EXPECT_EQ(refused.code, 2) << refused.err;
  EXPECT_NE(refused.err.find("not written: "), std::string::npos) << refused.err;  // refused after the solve
  EXPECT_EQ(refused.err.find("also holds"), std::string::npos) << refused.err;
  fs::remove_all(dir);
}

// A module whose right camera's images are all of another size (cam1 read
// out in a smaller window): calibrated, the rig file written, exit 0, and
// every reconstruction refused it after ("its two cameras' imagers differ
// in size (not supported)"). Refused naming the module and both sizes,
// nothing written, and before any detection (the PNG headers give the
// sizes): after it, a real rig's user waited minutes for the refusal.
TEST(CalibrateCli, AModuleOfTwoImagerSizesIsRefused) {
  const RenderedSet& set = Rendered();
  const std::string dir = set.dir + "/two_sizes";
  CopyModuleZeroCaptures(set, dir, 8);
  const Camera& cam1 = set.truth.camera(1);
  const int width_px = cam1.imager_width_px() - 40, height_px = cam1.imager_height_px() - 30;
  for (int c = 0; c < 8; ++c) {  // the window's corner at the sensor's: cx, cy unchanged
    const std::string image = dir + "/00" + std::to_string(c) + "/cam1.png";
    cv::imwrite(image, cv::imread(image, cv::IMREAD_GRAYSCALE)(cv::Rect(0, 0, width_px, height_px)).clone());
  }
  const testing::Result r =
      testing::RunCli("calibrate --captures " + dir + " --target " + set.dir + "/target.yaml --layout " + set.dir +
                      "/one_module.yaml --out " + dir + "/rig.yaml --report " + dir + "/report.json");
  EXPECT_EQ(r.code, 2) << r.err;
  const Camera& cam0 = set.truth.camera(0);
  EXPECT_NE(r.err.find("stereorig calibrate: " + dir + ": module0's cameras differ in imager size: cam0's images are " +
                       std::to_string(cam0.imager_width_px()) + "x" + std::to_string(cam0.imager_height_px()) +
                       ", cam1's " + std::to_string(width_px) + "x" + std::to_string(height_px) + "; "),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("detect 00"), std::string::npos) << r.err;  // before any detection, so any solve
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/rig.yaml"));
  EXPECT_FALSE(fs::exists(dir + "/report.json"));
  fs::remove_all(dir);
}

// A capture folder's name is its index when it is a number. A time stamp
// (20261207153000) no int holds aborted the run (std::stoi's out_of_range,
// exit 134); two folders of one index (003 and 0003) were merged into one
// capture, refused as "capture 3, camera 0: observed twice", no folder
// named. Each is refused before any detection, naming the folders.
TEST(CalibrateCli, ACaptureFolderNumberPastAnIntOrTakenTwiceIsRefused) {
  const RenderedSet& set = Rendered();
  const std::string dir = set.dir + "/indices";
  const std::string args = " --target " + set.dir + "/target.yaml --layout " + set.dir + "/one_module.yaml --out " +
                           dir + "/rig.yaml --report " + dir + "/report.json";
  CopyModuleZeroCaptures(set, dir, 8);
  fs::rename(dir + "/007", dir + "/20261207153000");
  testing::Result r = testing::RunCli("calibrate --captures " + dir + args);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(r.err, "stereorig calibrate: " + dir +
                       "/20261207153000: a capture folder's number must be under 10^9 (it is the capture's index): "
                       "rename it (000, 001, ...)\n");
  EXPECT_FALSE(fs::exists(dir + "/rig.yaml"));
  EXPECT_FALSE(fs::exists(dir + "/report.json"));
  fs::rename(dir + "/20261207153000", dir + "/0003");
  r = testing::RunCli("calibrate --captures " + dir + args);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(r.err, "stereorig calibrate: " + dir + "/003: is capture 3, as " + dir +
                       "/0003 is (a folder's number is its capture's index, 003 and 0003 alike): rename one (000, "
                       "001, ...)\n");
  EXPECT_FALSE(fs::exists(dir + "/rig.yaml"));
  EXPECT_FALSE(fs::exists(dir + "/report.json"));
  fs::remove_all(dir);
}

// A named folder among numbered ones is a capture of its own: numbered from
// 001 with a `retake` beside them, the retake's place among the sorted
// folders (7) was its index and 007's too, refused as two folders of one
// index (before: "observed twice"). It takes the index after the largest
// number (8), and the eight captures calibrate.
TEST(CalibrateCli, ANamedFolderAmongNumberedOnesIsACaptureOfItsOwn) {
  const RenderedSet& set = Rendered();
  const std::string dir = set.dir + "/named_among";
  CopyModuleZeroCaptures(set, dir, 8);
  fs::rename(dir + "/000", dir + "/retake");  // 001..007 and retake
  const testing::Result r =
      testing::RunCli("calibrate --captures " + dir + " --target " + set.dir + "/target.yaml --layout " + set.dir +
                      "/one_module.yaml --out " + dir + "/rig.yaml --report " + dir + "/report.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("detect retake:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("calibrate: 8 captures, "), std::string::npos) << r.err;
  std::ifstream f(dir + "/report.json");
  const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  ASSERT_TRUE(j.is_object());
  // Every (capture, capture_name) pair the report holds (the views stage 1
  // and stage 2 list): retake is capture 8 wherever it is named, 007 is 7.
  std::map<std::string, std::set<int>> indices_of;
  std::function<void(const nlohmann::json&)> walk = [&](const nlohmann::json& v) {
    if (v.is_object() && v.contains("capture") && v.contains("capture_name"))
      indices_of[v.at("capture_name").get<std::string>()].insert(v.at("capture").get<int>());
    if (v.is_structured())
      for (const auto& child : v) walk(child);
  };
  walk(j);
  EXPECT_EQ(indices_of["retake"], std::set<int>{8});
  EXPECT_EQ(indices_of["007"], std::set<int>{7});
  fs::remove_all(dir);
}

}  // namespace
}  // namespace stereorig
