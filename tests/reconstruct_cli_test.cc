// `stereorig match` end to end: a rendered pair with known disparity goes in
// as PNG files, the PFM that comes out is read back with OpenCV's own PFM
// codec (independent of ours) and compared with the truth.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "calib/core/atomic_file.h"
#include "reconstruct/synthetic_pair.h"
#include "tests/cli_runner.h"

namespace stereorig {
namespace {

const std::string kBin = std::string(STEREORIG_BINARY_DIR) + "/stereorig";

int RunCli(const std::string& args) {
  const int status = std::system((kBin + " " + args + " >/dev/null 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(MatchCli, WritesAPfmThatMatchesTheTruth) {
  const std::string dir = ::testing::TempDir() + "/match_cli";
  std::filesystem::create_directories(dir);
  const SyntheticPair pair = RenderSyntheticPair(SyntheticPairSpec{});
  ASSERT_TRUE(cv::imwrite(dir + "/L.png", pair.left));
  ASSERT_TRUE(cv::imwrite(dir + "/R.png", pair.right));
  const std::string out = dir + "/disp.pfm";
  std::filesystem::remove(out);
  ASSERT_EQ(RunCli("match --left " + dir + "/L.png --right " + dir +
                   "/R.png --min-disparity 24 --num-disparities 64 "
                   "--out " +
                   out),
            0);
  const cv::Mat disp = cv::imread(out, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(disp.type(), CV_32FC1);
  ASSERT_EQ(disp.size(), pair.left.size());
  int valid = 0, total = 0, invalid_is_inf = 0, invalid = 0;
  double sum2 = 0;
  for (int y = 12; y < disp.rows - 12; ++y)
    for (int x = 70; x < disp.cols - 12; ++x) {
      ++total;
      const float d = disp.at<float>(y, x);
      if (!std::isfinite(d)) {
        ++invalid;
        invalid_is_inf += std::isinf(d) && d > 0;
        continue;
      }
      ++valid;
      sum2 += std::pow(d - pair.true_disparity_px.at<double>(y, x), 2);
    }
  EXPECT_EQ(invalid_is_inf, invalid);
  EXPECT_GT(valid, 0.97 * total);
  // Same bound as matcher_test's slanted plane (noise 2 DN + window model).
  EXPECT_LT(std::sqrt(sum2 / valid), 0.035);
  // Column 0 cannot match (its partner is off the right image): +inf.
  EXPECT_TRUE(std::isinf(disp.at<float>(100, 0)));
}

// A pair with nothing to match (flat grey) gives no valid disparity: match
// said only "0 valid disparities", exit 0; now a hint that the range may
// miss the scene. (The range-end warning: ReconstructCli.
// MatchWarnsOfARangeThatMissesTheObject, on a rendered capture's
// rectified pair: on this small synthetic pair, a perfectly periodic grid,
// the band pass keeps period-off copies to the far end of any range.)
TEST(MatchCli, NoValidDisparityHintsThatTheRangeMayMissTheScene) {
  const std::string dir = ::testing::TempDir() + "/match_cli_flat";
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(cv::imwrite(dir + "/flat.png", cv::Mat(240, 320, CV_8UC1, cv::Scalar(100))));
  const testing::Result none =
      testing::RunCli("match --left " + dir + "/flat.png --right " + dir +
                      "/flat.png --min-disparity 24 --num-disparities 64 --out " + dir + "/d.pfm");
  ASSERT_EQ(none.code, 0) << none.err;
  EXPECT_NE(none.out.find(" 0 valid disparities"), std::string::npos) << none.out;
  EXPECT_NE(none.err.find("stereorig match: hint: no valid disparity: the range [24, 88) px (--min-disparity, "
                          "--num-disparities) may miss the scene"),
            std::string::npos)
      << none.err;
}

// score: a dataset folder without a rig is bad input (exit 2), not a crash.
// (An unusable --diagnose folder, and bad input beside a usable one:
// ReconstructCli.ScoreBadInputLeavesNoDiagnoseFolder.)
TEST(ScoreCli, MissingDatasetExitsTwo) {
  // Named as what it is: before, every case read "DATASET/truth/rig.yaml: no such file".
  const std::string file = ::testing::TempDir() + "/score_cli_not_a_dataset.yaml";
  { std::ofstream(file) << "a: 1\n"; }
  const std::pair<std::string, std::string> datasets[] = {
      {::testing::TempDir() + "/no_such_dataset", "no such dataset folder (--dataset)"},
      {file, "is a file, not a dataset folder"},
      {::testing::TempDir(), "is not a simulator dataset: it has no truth/ folder"}};
  for (const auto& [dataset, says] : datasets)
    for (const char* command : {"score --dataset ", "bench --runs 1 --dataset "}) {
      const testing::Result r = testing::RunCli(command + dataset);
      EXPECT_EQ(r.code, 2) << command << dataset;
      EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
      EXPECT_NE(r.err.find(dataset + ": " + says), std::string::npos) << r.err;
    }
  // A --report that cannot be written is named before anything else is read
  // (not after minutes of scoring).
  const std::string report = ::testing::TempDir() + "/no_such_folder/s.json";
  const testing::Result r =
      testing::RunCli("score --dataset " + ::testing::TempDir() + "/no_such_dataset --report " + report);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(report + ": its folder does not exist"), std::string::npos) << r.err;
  // A report inside the --diagnose folder, which score creates: accepted (the
  // run then stops at the missing dataset, not at the report).
  const std::string diagnose = ::testing::TempDir() + "/score_cli_diagnose";
  std::filesystem::remove_all(diagnose);
  const testing::Result d = testing::RunCli("score --dataset " + ::testing::TempDir() + "/no_such_dataset --diagnose " +
                                            diagnose + " --report " + diagnose + "/s.json");
  EXPECT_EQ(d.code, 2);
  EXPECT_EQ(d.err.find("s.json"), std::string::npos) << d.err;
  EXPECT_NE(d.err.find("no_such_dataset"), std::string::npos) << d.err;
  EXPECT_FALSE(std::filesystem::exists(diagnose)) << "bad input left the --diagnose folder behind";
}

TEST(MatchCli, BadInputExitsTwoAndWritesNothing) {
  const std::string dir = ::testing::TempDir() + "/match_cli_bad";
  std::filesystem::create_directories(dir);
  const std::string out = dir + "/disp.pfm";
  std::filesystem::remove(out);
  cv::imwrite(dir + "/small.png", cv::Mat(10, 10, CV_8UC1, cv::Scalar(3)));
  cv::imwrite(dir + "/big.png", cv::Mat(12, 10, CV_8UC1, cv::Scalar(3)));
  EXPECT_EQ(RunCli("match --left " + dir + "/missing.png --right " + dir +
                   "/small.png --min-disparity 0 "
                   "--num-disparities 16 --out " +
                   out),
            2);
  EXPECT_EQ(RunCli("match --left " + dir + "/small.png --right " + dir +
                   "/big.png --min-disparity 0 "
                   "--num-disparities 16 --out " +
                   out),
            2);
  EXPECT_EQ(RunCli("match --left " + dir + "/small.png --right " + dir +
                   "/small.png --min-disparity 0 "
                   "--num-disparities 1 --out " +
                   out),
            2);
  EXPECT_FALSE(std::filesystem::exists(out));
  // A bad value is named by the flag the user typed.
  for (const auto& [flag, value] : {std::pair{"--num-disparities", "1"}, {"--threads", "0"}}) {
    const std::string args = std::string(flag) == "--threads" ? std::string(" --num-disparities 16 --threads ") + value
                                                              : std::string(" --num-disparities ") + value;
    const testing::Result bad = testing::RunCli("match --left " + dir + "/small.png --right " + dir +
                                                "/small.png --min-disparity 0" + args + " --out " + out);
    EXPECT_EQ(bad.code, 2);
    EXPECT_NE(bad.err.find(std::string(flag) + ": must be in"), std::string::npos) << bad.err;
  }
  // An output folder that is not there is refused before the matching runs
  // (the writer's own error came only after it), before the images are
  // even read: with a left image missing too, the folder is what is named.
  for (const std::string left : {"small.png", "missing.png"}) {
    const testing::Result no_folder =
        testing::RunCli("match --left " + dir + "/" + left + " --right " + dir +
                        "/small.png --min-disparity 0 --num-disparities 16 --out " + dir + "/no_such_folder/disp.pfm");
    EXPECT_EQ(no_folder.code, 2);
    EXPECT_NE(no_folder.err.find("no_such_folder/disp.pfm: its folder does not exist"), std::string::npos)
        << no_folder.err;
  }
  // The map written over an input image (it used to replace it with PFM data).
  const auto png_size = std::filesystem::file_size(dir + "/small.png");
  const testing::Result over_left =
      testing::RunCli("match --left " + dir + "/small.png --right " + dir +
                      "/big.png --min-disparity 0 --num-disparities 16 --out " + dir + "/small.png");
  EXPECT_EQ(over_left.code, 2);
  EXPECT_NE(over_left.err.find("small.png: is the left image (--left)"), std::string::npos) << over_left.err;
  EXPECT_EQ(std::filesystem::file_size(dir + "/small.png"), png_size);
}

}  // namespace
}  // namespace stereorig

#include <fcntl.h>
#include <linux/fs.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <regex>
#include <tuple>

#include "calib/core/png_testing.h"
#include "calib/core/rig_file.h"
#include "datasets/default_rig.h"
#include "datasets/sim_spec.h"
#include "datasets/simulate.h"
#include "reconstruct/metrology/ply_points.h"
#include "reconstruct/pfm.h"
#include "reconstruct/synthetic_scene.h"
#include "tests/cli_runner.h"
#include "tests/sim_scene.h"

namespace stereorig {
namespace {

std::string ReadFileBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// `stereorig args` exits 2 with one line on stderr that says `says`.
void ExpectRefusedInOneLine(const std::string& args, const std::string& says) {
  const testing::Result r = testing::RunCli(args);
  EXPECT_EQ(r.code, 2) << args;
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
}

class ReconstructCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = ::testing::TempDir() + "/reconstruct_cli";
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_ + "/capture");
    const SimulatedRig sim = MakeDefaultRig();
    WriteRigFile(sim.rig, dir_ + "/rig.yaml");
    SphereSceneSpec spec;
    spec.centre_mm = sim.world_from_module0.Inverse() * Eigen::Vector3d::Zero();
    centre_ = spec.centre_mm;
    const std::vector<cv::Mat> images = RenderSphereCapture(sim.rig, spec);
    for (size_t k = 0; k < images.size(); ++k)
      cv::imwrite(dir_ + "/capture/cam" + std::to_string(k) + ".png", images[k]);
  }
  // A copy of the good capture to break.
  std::string BrokenCapture(const std::string& name) {
    const std::string d = dir_ + "/" + name;
    std::filesystem::remove_all(d);
    std::filesystem::copy(dir_ + "/capture", d);
    return d;
  }
  // A dataset folder as far as score reads it before scoring: the truth rig
  // and one scene capture image (the rig file's).
  std::string ScoreDataset(const std::string& name) {
    const std::string d = dir_ + "/" + name;
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d + "/truth");
    std::filesystem::create_directories(d + "/scenes/cup/active");
    std::filesystem::copy_file(dir_ + "/rig.yaml", d + "/truth/rig.yaml");
    std::filesystem::copy_file(dir_ + "/capture/cam0.png", d + "/scenes/cup/active/cam0.png");
    return d;
  }
  std::string Args(const std::string& capture, const std::string& extra = "") {
    return "reconstruct --rig " + dir_ + "/rig.yaml --capture " + capture + " --out " + dir_ + "/out.ply --report " +
           dir_ + "/out.json " + extra;
  }
  void ExpectNoOutput() {
    EXPECT_FALSE(std::filesystem::exists(dir_ + "/out.ply"));
    EXPECT_FALSE(std::filesystem::exists(dir_ + "/out.json"));
    EXPECT_FALSE(std::filesystem::exists(dir_ + "/out.stl"));
  }
  void SetUp() override {
    for (const char* f : {"/out.ply", "/out.json", "/out.stl"}) std::filesystem::remove(dir_ + f);
  }
  static std::string dir_;
  static Eigen::Vector3d centre_;
};
std::string ReconstructCli::dir_;
Eigen::Vector3d ReconstructCli::centre_;

TEST_F(ReconstructCli, WritesACloudAnyPlyReaderReadsOnTheSphere) {
  ASSERT_EQ(RunCli(Args(dir_ + "/capture", "--mesh " + dir_ + "/out.stl")), 0);
  // The metrology library's PLY reader is independent of our writer.
  const std::vector<Eigen::Vector3d> pts = ReadPlyPoints(dir_ + "/out.ply");
  ASSERT_GT(pts.size(), 40000u);
  int near = 0;
  for (const auto& p : pts) near += std::abs((p - centre_).norm() - 25.0) < 0.3;
  EXPECT_GT(near, 0.99 * pts.size());
  // The report names what each module searched: the occupied band, inside
  // the volume's range and narrower (the sphere fills a fraction of it).
  std::ifstream report_file(dir_ + "/out.json");
  const nlohmann::json report = nlohmann::json::parse(report_file);
  ASSERT_EQ(report["modules"].size(), 2u);
  for (const nlohmann::json& m : report["modules"]) {
    const int range_lo = m["disparity_range_px"][0], range_hi = m["disparity_range_px"][1];
    const int band_lo = m["searched_disparity_px"][0], band_hi = m["searched_disparity_px"][1];
    EXPECT_LE(range_lo, band_lo) << m.dump();
    EXPECT_LT(band_lo, band_hi) << m.dump();
    EXPECT_LE(band_hi, range_hi) << m.dump();
    EXPECT_LT(band_hi - band_lo, (range_hi - range_lo) / 2) << m.dump();
    // Every lit pixel has one final status: they add up to lit_pixels, the
    // kept ones to lit_pixels_filled, and on this clean sphere most are kept.
    int lit_sum = 0;
    for (const auto& [status, count] : m["lit_pixels_by_status"].items()) lit_sum += count.get<int>();
    EXPECT_EQ(lit_sum, m["lit_pixels"].get<int>()) << m.dump();
    ASSERT_TRUE(m["lit_pixels_by_status"].contains("point")) << m.dump();
    EXPECT_EQ(m["lit_pixels_by_status"]["point"].get<int>(), m["lit_pixels_filled"].get<int>()) << m.dump();
    EXPECT_GT(m["lit_pixels_by_status"]["point"].get<int>(), m["lit_pixels"].get<int>() / 2) << m.dump();
  }
  // Binary STL: 80-byte header, count, 50 bytes per triangle.
  const auto stl_size = std::filesystem::file_size(dir_ + "/out.stl");
  EXPECT_GT(stl_size, 84u + 50u * 10000);
  EXPECT_EQ((stl_size - 84) % 50, 0u);
}

TEST_F(ReconstructCli, PrintsPerModuleTheBandSearchedAndWhereFillWent) {
  const testing::Result r = testing::RunCli(Args(dir_ + "/capture"));
  ASSERT_EQ(r.code, 0) << r.err;
  for (const std::string module : {"module 0: ", "module 1: "}) {
    const size_t at = r.out.find(module);
    ASSERT_NE(at, std::string::npos) << r.out;
    const size_t next = r.out.find('\n', r.out.find('\n', at) + 1);  // the module's two lines
    const std::string lines = r.out.substr(at, next - at);
    EXPECT_NE(lines.find("\n  searched d ["), std::string::npos) << lines;
    EXPECT_NE(lines.find("lit px without a point: "), std::string::npos) << lines;
  }
}

// The fill a capture prints is the runtime's own, over the pixels it finds
// lit; `score`'s is over the truth's object pixels, and the two differ with
// no word why (the demo cup's module 0: 76.5 % against 94.1 %). The run's
// first module line says so, once. Under passive options there is no grid:
// the pixels are "lit px", not "grid-lit px" (the demo's passive cup read
// "fill 3.6% of 15056 grid-lit px" with the lasers off).
TEST_F(ReconstructCli, TheFillIsCalledTheRuntimesOwnOnceAndItsPixelsAsTheOptionsLightThem) {
  const std::string says_whose = " (the runtime's own estimate; `stereorig score` measures fill against the truth)";
  const testing::Result active = testing::RunCli(Args(dir_ + "/capture"));
  ASSERT_EQ(active.code, 0) << active.err;
  const std::string first_line = active.out.substr(0, active.out.find('\n'));
  EXPECT_EQ(first_line.rfind("module 0: ", 0), 0u) << first_line;
  EXPECT_NE(first_line.find(" grid-lit px" + says_whose + ", match "), std::string::npos) << first_line;
  EXPECT_EQ(active.out.find(says_whose), active.out.rfind(says_whose)) << "said more than once: " << active.out;
  const std::string passive_options = dir_ + "/passive_options.yaml";
  std::ofstream(passive_options) << "crop_to_lit_region: false\nmatch:\n  min_distinctness: 0\n  grid_line_test: "
                                    "false\n  line_index: false\n";
  const testing::Result passive = testing::RunCli(Args(dir_ + "/capture", "--options " + passive_options));
  ASSERT_EQ(passive.code, 0) << passive.err;
  EXPECT_EQ(passive.out.find("grid-lit"), std::string::npos) << passive.out;
  EXPECT_TRUE(std::regex_search(passive.out, std::regex("\nmodule 1: [0-9]+ points, fill [0-9.]+% of [0-9]+ lit px, "
                                                        "match ")))
      << passive.out;
}

// A module that ends with no point says why, also with no grid-lit pixel
// where the measurement volume projects: the hint used to need lit pixels
// there, so a volume beside the object (its ROI, cropped to nothing lit,
// holds 0 lit px) gave "0 points ... of 0 grid-lit px", exit 0 and no word.
// The left camera's whole image tells that case (lit elsewhere: set the
// volume) from a dark capture (lit nowhere: check the capture).
TEST_F(ReconstructCli, AModuleWithNoLitPixelInTheVolumeSaysWhy) {
  WriteFileAtomically(dir_ + "/beside.yaml", "volume_center_mm: [200, 0, 200]\n");
  // The capture's images flat at 10 grey levels (dark), and at 128 (the
  // lasers off under ambient light): the rectified view's step from 128 to
  // its zero fill has contrast of its own, which read as ~5 700 "grid-lit"
  // px along the view's edge and a summary that blamed the refinement
  // ("refine_failed 65%"), not the projector (lit_mask.h, LitWindowOnData).
  std::vector<std::string> flat;
  for (const auto& [name, grey] : {std::pair{"dark", 10}, {"flat128", 128}}) {
    flat.push_back(BrokenCapture(name));
    for (int k = 0; k < 4; ++k) {
      const std::string image = flat.back() + "/cam" + std::to_string(k) + ".png";
      ASSERT_TRUE(cv::imwrite(image, cv::Mat(cv::imread(image).size(), CV_8UC1, cv::Scalar(grey))));
    }
  }
  const std::regex no_lit_pixels(
      "\n  no point: no lit pixels: is the projector on, or is this a passive capture\\? No pixel of the left "
      "camera's image is grid-lit \\(9x9 std above lit_contrast_dn\\): a dark or flat image");
  const std::pair<std::string, std::regex> cases[] = {
      {Args(dir_ + "/capture", "--options " + dir_ + "/beside.yaml"),
       std::regex("\n  no point: [1-9][0-9]* px of the left camera's image are grid-lit, none where the measurement "
                  "volume projects: the volume is beside the object; set working_distance_mm \\(or "
                  "volume_center_mm, volume_size_mm\\) to where it is")},
      {Args(flat[0]), no_lit_pixels},
      {Args(flat[1]), no_lit_pixels}};
  for (const auto& [args, says] : cases) {
    const testing::Result r = testing::RunCli(args);
    ASSERT_EQ(r.code, 0) << args << ": " << r.err;
    for (const std::string module : {"module 0: 0 points", "module 1: 0 points"}) {
      const size_t at = r.out.find(module), next = r.out.find("\nmodule", at + 1);
      ASSERT_NE(at, std::string::npos) << r.out;
      const std::string summary = r.out.substr(at, next == std::string::npos ? std::string::npos : next - at);
      EXPECT_TRUE(std::regex_search(summary, says)) << args << ":\n" << summary;
    }
    // The report holds the count the line reads: > 0 beside the object, 0 dark or flat.
    std::ifstream f(dir_ + "/out.json");
    for (const nlohmann::json& m : nlohmann::json::parse(f)["modules"]) {
      ASSERT_TRUE(m.contains("left_camera_lit_pixels")) << m.dump();
      EXPECT_EQ(m["left_camera_lit_pixels"].get<int>() > 0, args.find("beside") != std::string::npos) << m.dump();
    }
  }
}

// A volume that holds only the sphere's front cap (20 mm deep, from 25 to 5
// mm in front of its centre): the surface goes on past the volume's far
// end, and the matches reach it, which the summary and the report say
// (ModuleReport::RangeEndReached); under the default volume, which holds
// the whole sphere, neither module says so.
TEST_F(ReconstructCli, MatchesReachingAnEndOfTheVolumesRangeAreWarnedOf) {
  const Eigen::Vector3d cap_centre_mm = centre_ - 15.0 * centre_.normalized();
  WriteFileAtomically(dir_ + "/cap.yaml", "volume_center_mm: [" + std::to_string(cap_centre_mm.x()) + ", " +
                                              std::to_string(cap_centre_mm.y()) + ", " +
                                              std::to_string(cap_centre_mm.z()) +
                                              "]\nvolume_size_mm: [150, 150, 20]\n");
  const std::string warning = "warning: its matches reach the far end of the measurement volume's disparity range";
  const testing::Result whole = testing::RunCli(Args(dir_ + "/capture"));
  ASSERT_EQ(whole.code, 0) << whole.err;
  EXPECT_EQ(whole.out.find("warning: its matches reach"), std::string::npos) << whole.out;
  const testing::Result cap = testing::RunCli(Args(dir_ + "/capture", "--options " + dir_ + "/cap.yaml"));
  ASSERT_EQ(cap.code, 0) << cap.err;
  EXPECT_NE(cap.out.find(warning), std::string::npos) << cap.out;
  std::ifstream f(dir_ + "/out.json");
  const nlohmann::json report = nlohmann::json::parse(f);
  int far_with_points = 0;
  for (const auto& m : report["modules"]) far_with_points += m["range_end_reached"] == "far" && m["points"] > 0;
  EXPECT_GE(far_with_points, 1) << report["modules"].dump();
  // In a batch (what a line runs), one line per such module.
  const testing::Result batch =
      testing::RunCli("reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ + "/capture --out-dir " + dir_ +
                      "/batch_cap --options " + dir_ + "/cap.yaml");
  ASSERT_EQ(batch.code, 0) << batch.err;
  EXPECT_TRUE(std::regex_search(batch.out, std::regex("\n  warning: module [01]'s matches reach the far end of the "
                                                      "measurement volume's disparity range")))
      << batch.out;
}

// `match` takes a rectified pair and a disparity range, and no command gave
// either: --rectified-out writes each module's pair as the runtime
// rectifies it and prints the match command that searches it with the
// runtime's range and ROI. That command, run as printed, matches the sphere
// with no range warning; the cloud is the one written without the option.
TEST_F(ReconstructCli, RectifiedOutWritesEachModulesPairAndTheMatchCommandForIt) {
  ASSERT_EQ(RunCli(Args(dir_ + "/capture")), 0);
  const std::string plain_cloud = ReadFileBytes(dir_ + "/out.ply");
  // A space in the folder: the printed command quotes the paths (it split
  // them in two, and the command failed as pasted).
  const std::string rect = dir_ + "/rect/new pairs";
  std::filesystem::remove_all(dir_ + "/rect");
  const testing::Result r = testing::RunCli(Args(dir_ + "/capture", "--rectified-out '" + rect + "'"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(ReadFileBytes(dir_ + "/out.ply"), plain_cloud);
  for (int m = 0; m < 2; ++m) {
    const std::string left = rect + "/module" + std::to_string(m) + "_left.png";
    const cv::Mat image = cv::imread(left, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(image.type(), CV_8UC1) << left;
    EXPECT_GT(cv::countNonZero(image), image.total() / 10) << left;
    const std::string says = "module " + std::to_string(m) + ": rectified pair " + left + ", ";
    const size_t at = r.out.find(says);
    ASSERT_NE(at, std::string::npos) << r.out;
    const size_t command = r.out.find("stereorig match ", at);
    ASSERT_NE(command, std::string::npos) << r.out;
    // The volume's range and ROI, not what the runtime searched in this
    // capture after its lit-region crop and band pass: not "the runtime's".
    const std::string intro = "; the volume's search: ";
    EXPECT_EQ(r.out.substr(command - intro.size(), intro.size()), intro) << r.out;
    const std::string args = r.out.substr(command + 10, r.out.find('\n', command) - command - 10);
    EXPECT_NE(args.find(" --min-disparity "), std::string::npos) << args;
    EXPECT_NE(args.find(" --roi "), std::string::npos) << args;
    EXPECT_NE(args.find("--left '" + left + "' --right '"), std::string::npos) << args;
    const testing::Result match = testing::RunCli(args);
    ASSERT_EQ(match.code, 0) << args << ": " << match.err;
    EXPECT_EQ(match.err, "") << args;
    EXPECT_TRUE(std::filesystem::exists(rect + "/module" + std::to_string(m) + "_disparity.pfm"));
  }
  // One capture only: a batch has many pairs per module.
  ExpectRefusedInOneLine("reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ + "/capture --out-dir " + dir_ +
                             "/rect_batch --rectified-out '" + rect + "'",
                         "--out-dir excludes --rectified-out");
}

// --rectified-out creates its folder; the cloud, mesh and report may go in
// it (--rectified-out r --out r/x.ply was refused, "its folder does not
// exist", though the run makes it). A folder below it that nobody makes is
// still refused, and so is the folder itself as a file; a capture found
// bad after the claims leaves no folder behind.
TEST_F(ReconstructCli, OutputsMayGoInTheFolderRectifiedOutCreates) {
  namespace fs = std::filesystem;
  ASSERT_EQ(RunCli(Args(dir_ + "/capture")), 0);
  const std::string plain_cloud = ReadFileBytes(dir_ + "/out.ply");
  const std::string rect = dir_ + "/rect_outputs/pairs";
  fs::remove_all(dir_ + "/rect_outputs");
  const std::string reconstruct = "reconstruct --rig " + dir_ + "/rig.yaml --capture ";
  const testing::Result r = testing::RunCli(reconstruct + dir_ + "/capture --rectified-out " + rect + " --out " + rect +
                                            "/x.ply --mesh " + rect + "/x.stl --report " + rect + "/x.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(ReadFileBytes(rect + "/x.ply"), plain_cloud);
  EXPECT_TRUE(fs::is_regular_file(rect + "/x.stl"));
  EXPECT_TRUE(fs::is_regular_file(rect + "/x.json"));
  EXPECT_TRUE(fs::is_regular_file(rect + "/module1_right.png"));
  fs::remove_all(dir_ + "/rect_outputs");
  ExpectRefusedInOneLine(reconstruct + dir_ + "/capture --rectified-out " + rect + " --out " + rect + "/sub/x.ply",
                         rect + "/sub/x.ply: its folder does not exist");
  ExpectRefusedInOneLine(reconstruct + dir_ + "/capture --rectified-out " + rect + " --out " + rect,
                         rect +
                             ": is a folder this command creates for the rectified pairs (--rectified-out), not a "
                             "file to write");
  const std::string broken = BrokenCapture("rect_outputs_broken");
  WriteFileAtomically(broken + "/cam1.png", "not a png");  // found only when decoded
  const testing::Result bad =
      testing::RunCli(reconstruct + broken + " --rectified-out " + rect + " --out " + rect + "/x.ply");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find(broken + "/cam1.png"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir_ + "/rect_outputs"));
}

// A grey PNG of 1, 2 or 4 bits decodes to 8 bits (0/255 for 1 bit): a 1-bit
// capture gave 0 points and a 4-bit one fewer, exit 0 both. Refused now as
// formats.md says (8-bit grey only), naming the file and its depth; so is
// such an image given to match.
TEST_F(ReconstructCli, GreyImagesOfFewerThan8BitsAreRefusedNamingTheirDepth) {
  for (const int bits : {1, 2, 4}) {
    const std::string capture = BrokenCapture("bits" + std::to_string(bits));
    const std::string image = capture + "/cam3.png";
    std::string raw;  // 8 x 2 px: per row a filter byte and 8 samples packed
    for (int row = 0; row < 2; ++row) raw += '\0' + std::string(size_t(bits), '\x5a');
    std::ofstream(image, std::ios::binary)
        << testing::kPngSignature + testing::Chunk("IHDR", testing::Ihdr(8, 2, bits, 0)) +
               testing::Chunk("IDAT", testing::Deflate(raw, 9)) + testing::Chunk("IEND", "");
    const std::string says = image + ": is a " + std::to_string(bits) + "-bit grey PNG: captures must be 8-bit grey";
    ExpectRefusedInOneLine(Args(capture), says);
    ExpectNoOutput();
    ExpectRefusedInOneLine("match --left " + image + " --right " + image +
                               " --min-disparity 0 --num-disparities 16 --out " + dir_ + "/bits.pfm",
                           says);
  }
}

// An image of another type says what it is, as calibrate and check say it
// (calib/capture_folder.cc): reconstruct and match answered "must be an
// 8-bit single-channel (grey) image" alike for 16-bit, RGB, grey with alpha
// and palette PNGs. Channels as decoded (png_reader.h: grey with alpha as
// G, G, G, A); refused from the header, so the image data is a stand-in.
TEST_F(ReconstructCli, ImagesOfAnotherTypeAreRefusedSayingWhatTheyAre) {
  struct Kind {
    const char* name;
    int bit_depth, colour_type;
    const char* says;
  };
  for (const Kind& kind :
       {Kind{"grey16", 16, 0, "1 channel(s) of 16 bits"}, Kind{"rgb", 8, 2, "3 channel(s) of 8 bits"},
        Kind{"grey_alpha", 8, 4, "4 channel(s) of 8 bits"}, Kind{"palette", 8, 3, "3 channel(s) of 8 bits"}}) {
    const std::string capture = BrokenCapture(std::string("type_") + kind.name);
    const std::string image = capture + "/cam2.png";
    const std::string palette = kind.colour_type == 3 ? testing::Chunk("PLTE", std::string(3, '\x40')) : "";
    std::ofstream(image, std::ios::binary)
        << testing::kPngSignature + testing::Chunk("IHDR", testing::Ihdr(8, 2, kind.bit_depth, kind.colour_type)) +
               palette + testing::Chunk("IDAT", testing::Deflate("", 9)) + testing::Chunk("IEND", "");
    const std::string says =
        image + ": must be an 8-bit single-channel (grey) image (this one has " + std::string(kind.says) + ")";
    ExpectRefusedInOneLine(Args(capture), says);
    ExpectNoOutput();
    ExpectRefusedInOneLine("match --left " + image + " --right " + image +
                               " --min-disparity 0 --num-disparities 16 --out " + dir_ + "/type.pfm",
                           says);
  }
}

// shape_model fills holes only from a mesh: without --mesh nothing was
// filled and nothing said. Now one note; with --mesh none. The summary's
// "wrote" names every file written, the report too (it left it out).
TEST_F(ReconstructCli, AShapeModelWithoutAMeshIsNotedAndTheSummaryNamesEveryOutput) {
  WriteFileAtomically(dir_ + "/sphere_model.yaml", "shape_model: sphere\n");
  const testing::Result r = testing::RunCli(Args(dir_ + "/capture", "--options " + dir_ + "/sphere_model.yaml"));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string note = "note: shape_model sphere fills holes only with a mesh (--mesh";
  EXPECT_NE(r.out.find(note), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(note), r.out.rfind(note)) << r.out;
  EXPECT_NE(r.out.find("; wrote " + dir_ + "/out.ply, " + dir_ + "/out.json\n"), std::string::npos) << r.out;
  const testing::Result meshed =
      testing::RunCli(Args(dir_ + "/capture", "--options " + dir_ + "/sphere_model.yaml --mesh " + dir_ + "/out.stl"));
  ASSERT_EQ(meshed.code, 0) << meshed.err;
  EXPECT_EQ(meshed.out.find("note: shape_model"), std::string::npos) << meshed.out;
  EXPECT_TRUE(std::regex_search(meshed.out, std::regex("; wrote [^\n]*/out\\.ply, [^\n]*/out\\.stl \\([0-9]+ "
                                                       "triangles\\), [^\n]*/out\\.json\n")))
      << meshed.out;
}

// `stereorig verify`'s filled column (the table's row of position 1).
int VerifyFilledCount(const std::string& out) {
  std::smatch m;
  // position figure value_mm u_mm mpe_mm pass cloud filled
  if (!std::regex_search(out, m, std::regex("\n1 +[^ ]+ +[^ ]+ +[^ ]+ +[^ ]+ +[^ ]+ +[0-9]+ +([0-9]+) "))) return -1;
  return std::stoi(m[1]);
}

// A mesh PLY written with hole filling keeps each vertex's module: verify
// skips as many filled points in it as in the cloud (the filled count
// reconstruct reports). The mesh held x, y, z only, and verify took all its
// vertices as measured ("filled 0"): the shape model's points entered the fit.
TEST_F(ReconstructCli, AMeshKeepsHoleFillingsModuleSoVerifySkipsItsFilledPointsAsInTheCloud) {
  WriteFileAtomically(dir_ + "/sphere_fill.yaml", "shape_model: sphere\n");
  const std::string mesh = dir_ + "/fill_mesh.ply";
  const testing::Result r =
      testing::RunCli(Args(dir_ + "/capture", "--options " + dir_ + "/sphere_fill.yaml --mesh " + mesh));
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream report_file(dir_ + "/out.json");
  const int filled = nlohmann::json::parse(report_file)["filled_points"].get<int>();
  ASSERT_GT(filled, 100) << r.out;  // two modules leave the sphere's sides and back to the model
  const std::string artifact = dir_ + "/sphere_artifact.yaml";
  WriteFileAtomically(artifact,
                      "format: stereorig-artifact\nversion: 1\nunits: mm\nname: rendered sphere\ntype: sphere\n"
                      "diameter_mm: 50\ndiameter_uncertainty_mm: 0.002\n");
  const testing::Result of_cloud = testing::RunCli("verify --artifact " + artifact + " --cloud " + dir_ + "/out.ply");
  const testing::Result of_mesh = testing::RunCli("verify --artifact " + artifact + " --cloud " + mesh);
  EXPECT_EQ(VerifyFilledCount(of_cloud.out), filled) << of_cloud.out << of_cloud.err;
  EXPECT_EQ(VerifyFilledCount(of_mesh.out), filled) << of_mesh.out << of_mesh.err;
  EXPECT_EQ(of_mesh.code, of_cloud.code) << of_mesh.out << of_cloud.out;
  EXPECT_EQ(of_mesh.out.find("note: position 1"), std::string::npos) << of_mesh.out;  // it has its modules
  std::filesystem::remove(mesh);
}

// A capture folder or image this process may not read was named in
// std::filesystem's words ("filesystem error: directory iterator cannot
// open directory: Permission denied [DIR]") or without the reason ("cannot
// be opened"). Now the folder is named as a capture folder that cannot be
// read, and the image's reason is given. Root reads any folder: the folder
// is then read as the unprivileged user `nobody`; a sysctl file open for
// writing only refuses reading even to root.
TEST_F(ReconstructCli, AFolderOrImageThatCannotBeReadSaysWhy) {
  const std::string locked = BrokenCapture("locked");
  std::filesystem::permissions(locked, std::filesystem::perms::none);
  const std::string as_nobody = geteuid() == 0 ? "--reuid=65534 --regid=65534 --clear-groups " : "";
  const std::string out = "/tmp/stereorig_locked_" + std::to_string(getpid()) + ".ply";
  const std::string command = (as_nobody.empty() ? kBin : "setpriv " + as_nobody + kBin) + " reconstruct --rig " +
                              dir_ + "/rig.yaml --capture " + locked + " --out " + out + " 2>&1 >/dev/null";
  FILE* p = popen(command.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string err;
  for (char buf[256]; std::fgets(buf, sizeof buf, p);) err += buf;
  const int status = pclose(p);
  std::filesystem::permissions(locked, std::filesystem::perms::owner_all);
  EXPECT_EQ(WEXITSTATUS(status), 2) << err;
  EXPECT_EQ(err, "stereorig reconstruct: " + locked + ": the capture folder cannot be read: Permission denied\n");
  EXPECT_FALSE(std::filesystem::exists(out));
  const std::string write_only = "/proc/sys/vm/drop_caches";
  if (access(write_only.c_str(), R_OK) == 0) GTEST_SKIP() << write_only << " is readable here";
  ExpectRefusedInOneLine("match --left " + write_only + " --right " + write_only +
                             " --min-disparity 0 --num-disparities 16 --out " + dir_ + "/locked.pfm",
                         write_only + ": cannot be opened: Permission denied");
}

// working_distance_mm: 300 on the facing rig puts the volume ~100 mm from
// module 1, which then needs more than 1024 disparities. The refusal said
// "move it farther from the cameras (working_distance_mm, ...)": a larger
// working distance brings it nearer still to module 1. Now it says which
// way moves it away from module 1; module 0, looking along its own axis,
// keeps the plain advice.
TEST_F(ReconstructCli, AVolumeTooNearAFacingModuleIsNotToldToGoFarther) {
  WriteFileAtomically(dir_ + "/far.yaml", "working_distance_mm: 300\n");
  const testing::Result r = testing::RunCli(Args(dir_ + "/capture", "--options " + dir_ + "/far.yaml"));
  ASSERT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("module1's cameras, which face module 0's: volume_center_mm (a larger working_distance_mm "
                       "moves it away from module 0, nearer to module1)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("farther from the cameras"), std::string::npos) << r.err;
}

// match on a module's rectified pair of the rendered sphere, its range
// ending halfway into the sphere's disparities (the walkthrough's: true
// 472-549 px searched in [300, 500), 63 568 disparities, ~99 % a grid
// period or more off, exit 0 and no word): the laser grid matches at a
// copy of itself inside the range and the band pass's matches pile up at
// its near end. match now warns as reconstruct warns of a module
// (range_end_reached), on stderr and in its summary line; on the
// runtime's own range it does not.
TEST_F(ReconstructCli, MatchWarnsOfARangeThatMissesTheObject) {
  const std::string rect = dir_ + "/rect_miss";
  std::filesystem::remove_all(rect);
  ASSERT_EQ(RunCli(Args(dir_ + "/capture", "--rectified-out " + rect)), 0);
  std::ifstream f(dir_ + "/out.json");
  const nlohmann::json module0 = nlohmann::json::parse(f)["modules"][0];
  ASSERT_TRUE(module0.contains("occupied_disparity_px")) << module0.dump();
  const int middle_px =
      (module0["occupied_disparity_px"][0].get<int>() + module0["occupied_disparity_px"][1].get<int>()) / 2;
  const auto match = [&](int min_px, int end_px) {
    return testing::RunCli("match --left " + rect + "/module0_left.png --right " + rect +
                           "/module0_right.png --min-disparity " + std::to_string(min_px) + " --num-disparities " +
                           std::to_string(end_px - min_px) + " --out " + rect + "/d.pfm");
  };
  const int range_min_px = module0["disparity_range_px"][0], range_end_px = module0["disparity_range_px"][1];
  const testing::Result right = match(range_min_px, range_end_px);
  ASSERT_EQ(right.code, 0) << right.err;
  EXPECT_EQ(right.err, "");
  EXPECT_EQ(right.out.find("warning"), std::string::npos) << right.out;
  const testing::Result missing = match(middle_px - 200, middle_px);
  ASSERT_EQ(missing.code, 0) << missing.err;
  EXPECT_NE(missing.err.find("stereorig match: warning: the disparities pile up at the near end (largest "
                             "disparities) of the range [" +
                             std::to_string(middle_px - 200) + ", " + std::to_string(middle_px) +
                             ") px (--min-disparity, --num-disparities): the range likely misses the object"),
            std::string::npos)
      << missing.err;
  EXPECT_NE(missing.out.find("; warning: they reach the near end (largest disparities) of the range\n"),
            std::string::npos)
      << missing.out;
}

// match on the rendered sphere's module 0 in [0, 100) px: the sphere's
// disparities (16-66 px) lie well inside, but the half-resolution band pass
// also matches the unlit backdrop around it (the runtime crops it away),
// and those matches pile up at 0-12 px: match warned "the disparities pile
// up at the far end" though no disparity it wrote was near it (the
// walkthrough's: the demo cup in [-20, 140), final 43-105 px). It now
// warns only of an end its final disparities reach too.
TEST_F(ReconstructCli, MatchDoesNotWarnOfAnEndOnlyTheBackdropReaches) {
  const std::string rect = dir_ + "/rect_backdrop";
  std::filesystem::remove_all(rect);
  ASSERT_EQ(RunCli(Args(dir_ + "/capture", "--rectified-out " + rect)), 0);
  const int min_px = 0, end_px = 100;
  const testing::Result r = testing::RunCli(
      "match --left " + rect + "/module0_left.png --right " + rect + "/module0_right.png --min-disparity " +
      std::to_string(min_px) + " --num-disparities " + std::to_string(end_px - min_px) + " --out " + rect + "/d.pfm");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out.find("warning"), std::string::npos) << r.out;
  // What the warning would claim, read from the map: no disparity within
  // the band's 4 px bin (kBandBinPx) of either end.
  const cv::Mat d = ReadPfm(rect + "/d.pfm");
  double lo = 1e9, hi = -1e9;
  int valid = 0;
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x)
      if (const float v = d.at<float>(y, x); std::isfinite(v))
        lo = std::min(lo, double(v)), hi = std::max(hi, double(v)), ++valid;
  ASSERT_GT(valid, 10000);
  EXPECT_GE(lo, min_px + 4);
  EXPECT_LT(hi, end_px - 4);
}

TEST_F(ReconstructCli, MissingCameraExitsTwoAndWritesNothing) {
  const std::string d = BrokenCapture("missing");
  std::filesystem::remove(d + "/cam2.png");
  EXPECT_EQ(RunCli(Args(d)), 2);
  ExpectNoOutput();
}

// A capture of a rig with fewer cameras (the ring's six-camera rig file on a
// two-module capture, or this rig on a one-module one): said so. Before, the
// first absent image's line read like that camera's fault; a missing
// camera among the others still reads so (above).
TEST_F(ReconstructCli, ACaptureOfFewerCamerasThanTheRigIsSaidSo) {
  const std::string d = BrokenCapture("fewer_cameras");
  std::filesystem::remove(d + "/cam2.png");
  std::filesystem::remove(d + "/cam3.png");
  const testing::Result r = testing::RunCli(Args(d));
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(d + "/cam2.png: missing camera image (camera 2); the capture holds cam0.png to cam1.png only "
                           "and the rig has 4 cameras (2 modules): a capture of another rig, the wrong rig file"),
            std::string::npos)
      << r.err;
  ExpectNoOutput();
  std::filesystem::remove(d + "/cam1.png");
  std::filesystem::copy_file(dir_ + "/capture/cam3.png", d + "/cam3.png");
  const testing::Result one_missing = testing::RunCli(Args(d));
  EXPECT_EQ(one_missing.code, 2);
  EXPECT_NE(one_missing.err.find(d + "/cam1.png: missing camera image (camera 1)\n"), std::string::npos)
      << one_missing.err;
}

TEST_F(ReconstructCli, WrongImageSizeExitsTwoAndWritesNothing) {
  const std::string d = BrokenCapture("wrong_size");
  cv::imwrite(d + "/cam1.png", cv::Mat(480, 640, CV_8UC1, cv::Scalar(10)));
  EXPECT_EQ(RunCli(Args(d)), 2);
  ExpectNoOutput();
}

// A capture image whose header declares another size than its camera's is
// refused from the header, before its pixels are allocated or decoded: here
// 16000 x 16000 px (256 MB decoded) in a 70-byte file whose image data
// holds one row. Before, the whole image was allocated and decoded first:
// this file was refused as damaged ("its image data ends before the image
// does"), and a whole one of that size took 2.7 s and 270 MB before "is
// 16000x16000". So is a 16-bit colour header (2 GiB decoded).
TEST_F(ReconstructCli, AnImageHeaderOfAnotherSizeIsRefusedBeforeDecoding) {
  const std::string d = BrokenCapture("declared_size");
  const std::string row(1 + 16000, '\0');  // a filter byte and one row
  WriteFileAtomically(d + "/cam1.png", testing::kPngSignature + testing::Chunk("IHDR", testing::Ihdr(16000, 16000)) +
                                           testing::Chunk("IDAT", testing::Deflate(row, 9)) +
                                           testing::Chunk("IEND", ""));
  ExpectRefusedInOneLine(Args(d), d + "/cam1.png: is 16000x16000, the rig says 752x582");
  WriteFileAtomically(d + "/cam1.png",
                      testing::kPngSignature + testing::Chunk("IHDR", testing::Ihdr(16384, 16384, 16, 6)) +
                          testing::Chunk("IDAT", testing::Deflate(row, 9)) + testing::Chunk("IEND", ""));
  ExpectRefusedInOneLine(Args(d), d + "/cam1.png: must be an 8-bit single-channel (grey) image");
  ExpectNoOutput();
}

// A capture image cut short (a camera still writing it) is named in one
// line; libpng used to print its own "libpng error: Read Error" line first.
// So is one with a byte flipped in its image data (a disk's or a copy's
// damage): libpng printed "libpng error: bad adaptive filter value" above
// our "cannot read the image (not an image, or a damaged one)". Here the
// chunk's CRC names it, at the end of the chunk (cv::imwrite's IDATs are
// 8 KB); a flip zlib trips over first is named by zlib's complaint
// (calib/core/png_reader_test.cc).
TEST_F(ReconstructCli, AnImageCutShortOrDamagedIsNamedInOneLine) {
  const std::string d = BrokenCapture("cut_short");
  const auto size = std::filesystem::file_size(d + "/cam1.png");
  std::filesystem::resize_file(d + "/cam1.png", size / 2);
  testing::Result r = testing::RunCli(Args(d));
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(d + "/cam1.png: a PNG cut short"), std::string::npos) << r.err;
  ExpectNoOutput();

  const std::string damaged = BrokenCapture("damaged");
  std::fstream f(damaged + "/cam2.png", std::ios::in | std::ios::out | std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(f), {}};
  const size_t idat = bytes.find("IDAT");  // its type; its data follows
  ASSERT_NE(idat, std::string::npos);
  f.seekp(std::streamoff(idat + 100));
  f.put(char(bytes[idat + 100] ^ 0x10));
  f.close();
  r = testing::RunCli(Args(damaged));
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(damaged + "/cam2.png: a damaged PNG (its IDAT chunk at byte " + std::to_string(idat - 4) +
                       " fails its CRC check)"),
            std::string::npos)
      << r.err;
  ExpectNoOutput();
}

// Image data damaged under valid CRCs (the chunk's CRC redone after the
// damage, as a faulty tool rewriting the file would) is named in one line
// too: libpng used to print "libpng error: IDAT: invalid block type" (or
// "... invalid distance too far back") above our "cannot read the image".
TEST_F(ReconstructCli, ImageDataDamagedUnderValidCrcsIsNamedInOneLine) {
  const std::string d = BrokenCapture("deflate_damaged");
  std::fstream f(d + "/cam3.png", std::ios::in | std::ios::out | std::ios::binary);
  std::string bytes{std::istreambuf_iterator<char>(f), {}};
  const size_t idat = bytes.find("IDAT");  // the first IDAT's type; its data follows
  ASSERT_NE(idat, std::string::npos);
  bytes[idat + 4 + 2] |= 0x06;  // after zlib's 2-byte header, the first block's type: 11, reserved
  testing::RedoCrc(bytes, idat - 4);
  f.seekp(0);
  f.write(bytes.data(), std::streamsize(bytes.size()));
  f.close();
  const testing::Result r = testing::RunCli(Args(d));
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.find("libpng"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(d + "/cam3.png: a damaged PNG (its image data (IDAT chunk at byte " + std::to_string(idat - 4) +
                       "): invalid block type)\n"),
            std::string::npos)
      << r.err;
  ExpectNoOutput();
}

// Inputs of the wrong kind, each named in one line as what it is, before any
// work and with no output. Before: JPEG bytes named cam1.png printed
// libjpeg's "Premature end of JPEG file" first; a header of 60000 x 60000 px
// printed OpenCV's two-line assertion; a folder for a file read "no such
// file"; a file for --capture "capture folder not found". (The header of
// 60000 x 60000 px is past the PNG reader's 2^28 px, calib/core/
// png_reader.h: refused from its header, before any image data is read.)
TEST_F(ReconstructCli, InputsOfTheWrongKindAreNamedInOneLine) {
  const std::string jpeg = BrokenCapture("jpeg_named_png");
  std::vector<uchar> bytes;
  ASSERT_TRUE(cv::imencode(".jpg", cv::Mat(582, 752, CV_8UC1, cv::Scalar(90)), bytes));
  {
    std::ofstream(jpeg + "/cam1.png", std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  }
  const std::string huge = BrokenCapture("huge_header");
  {  // a whole PNG (signature, IHDR, an empty IDAT, IEND, with their CRCs) claiming 60000 x 60000 px
    std::ofstream(huge + "/cam1.png", std::ios::binary) << testing::kPngSignature +
                                                               testing::Chunk("IHDR", testing::Ihdr(60000, 60000)) +
                                                               testing::Chunk("IDAT", "") + testing::Chunk("IEND", "");
  }
  const std::string empty = BrokenCapture("empty_image");  // a file the camera has only just created
  std::ofstream(empty + "/cam1.png", std::ios::binary | std::ios::trunc).close();
  const std::string folder = BrokenCapture("folder_for_image");
  std::filesystem::remove(folder + "/cam1.png");
  std::filesystem::create_directory(folder + "/cam1.png");
  const std::string base = "reconstruct --out " + dir_ + "/out.ply ";
  const std::pair<std::string, std::string> cases[] = {
      {base + "--rig " + dir_ + "/rig.yaml --capture " + jpeg,
       jpeg + "/cam1.png: is not a PNG file, though named .png"},
      {base + "--rig " + dir_ + "/rig.yaml --capture " + empty,
       empty + "/cam1.png: is empty (0 bytes: still being written?)"},
      {base + "--rig " + dir_ + "/rig.yaml --capture " + huge,
       huge + "/cam1.png: a PNG too large to read (its IHDR gives an image of 60000 x 60000 px; this reader takes "
              "up to 1000000 px a side and 268435456 px in all)"},
      {base + "--rig " + dir_ + "/rig.yaml --capture " + folder,
       folder + "/cam1.png: is a folder, not camera 1's image"},
      {base + "--rig " + dir_ + "/capture --capture " + dir_ + "/capture", dir_ + "/capture: is a folder, not a file"},
      {base + "--rig " + dir_ + "/rig.yaml --capture " + dir_ + "/rig.yaml",
       dir_ + "/rig.yaml: is a file, not a capture folder"}};
  for (const auto& [args, says] : cases) {
    ExpectRefusedInOneLine(args, says);
    ExpectNoOutput();
  }
}

TEST_F(ReconstructCli, CaptureFromALargerRigExitsTwo) {
  const std::string d = BrokenCapture("extra_camera");
  std::filesystem::copy(d + "/cam0.png", d + "/cam4.png");
  EXPECT_EQ(RunCli(Args(d)), 2);
  ExpectNoOutput();
}

TEST_F(ReconstructCli, BadOptionsOrMeshNameExitTwo) {
  WriteFileAtomically(dir_ + "/bad.yaml", "object_size_mm: 80\nvolume_sise_mm: [1, 2, 3]\n");
  EXPECT_EQ(RunCli(Args(dir_ + "/capture", "--options " + dir_ + "/bad.yaml")), 2);
  EXPECT_EQ(RunCli(Args(dir_ + "/capture", "--mesh " + dir_ + "/out.obj")), 2);
  ExpectNoOutput();
}

// The cloud is always binary PLY: a cloud named for another format would
// hold bytes its reader cannot parse. (Before, `--out cloud.xyz` wrote PLY
// there and exited 0.) Refused before any work, in one line naming it.
TEST_F(ReconstructCli, ACloudNotNamedPlyExitsTwo) {
  for (const char* name : {"/out.xyz", "/out.pcd", "/out.ply.tmp"}) {
    const testing::Result r =
        testing::RunCli("reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ + "/capture --out " + dir_ + name);
    EXPECT_EQ(r.code, 2) << name;
    EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(dir_ + name + ": cloud output must end in .ply"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir_ + name)) << name;
  }
}

// The suffix picks the format whatever its case, as users type it:
// "out.PLY" is binary PLY, "out.STL" binary STL. (Before, both were refused
// as not .ply / .stl.)
TEST_F(ReconstructCli, UpperCaseSuffixesNameTheSameFormats) {
  const std::string cloud = dir_ + "/upper.PLY", mesh = dir_ + "/upper.STL";
  for (const std::string& f : {cloud, mesh}) std::filesystem::remove(f);
  const testing::Result r = testing::RunCli("reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ +
                                            "/capture --out " + cloud + " --mesh " + mesh);
  ASSERT_EQ(r.code, 0) << r.err;
  // The metrology library's PLY reader, independent of our writer.
  EXPECT_GT(ReadPlyPoints(cloud).size(), 40000u);
  // Binary STL, not PLY: 80-byte header, count, 50 bytes per triangle.
  std::ifstream in(mesh, std::ios::binary);
  std::string head(84, '\0');
  ASSERT_TRUE(in.read(head.data(), 84));
  EXPECT_NE(head.substr(0, 3), "ply");
  uint32_t triangles = 0;
  std::memcpy(&triangles, head.data() + 80, 4);
  EXPECT_GT(triangles, 10000u);
  EXPECT_EQ(std::filesystem::file_size(mesh), 84u + 50u * triangles);
  for (const std::string& f : {cloud, mesh}) std::filesystem::remove(f);
}

// The cloud, mesh and report of one capture are written all or none: a
// report that cannot be written (in a folder where no file can be created,
// testing::UnwritablePath) leaves an earlier run's cloud as it was, no mesh
// and no temporary file. (Once, the new cloud and mesh were in place and the
// run exited 2.) Root too is now refused before any work, a file being
// created and removed there when the outputs are claimed; a write that fails
// late (a full disk) is AtomicOutputSet's, tested in atomic_file_test.cc.
TEST_F(ReconstructCli, AReportThatCannotBeWrittenLeavesTheEarlierCloud) {
  const std::string dir = dir_ + "/all_or_none";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/out.ply") << "earlier run";
  const std::string unwritable = testing::UnwritablePath("reconstruct-report.json");
  const testing::Result r =
      testing::RunCli("reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ + "/capture --out " + dir +
                      "/out.ply --mesh " + dir + "/out.stl --report " + unwritable);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(unwritable + ": cannot write the report (--report) in its folder /proc: "), std::string::npos)
      << r.err;
  std::ifstream cloud(dir + "/out.ply");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(cloud), {}), "earlier run");
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) names.push_back(entry.path().filename());
  EXPECT_EQ(names, std::vector<std::string>{"out.ply"});  // no mesh or temporary file
}

// A stdout that cannot be written (/dev/full) makes a run that printed its
// summary there exit 2, in one line saying so (exit 0 before): the caller did
// not get the summary. The outputs are committed before the summary is
// printed, so they are whole: the cloud the same bytes as a run whose stdout
// is written, the report there too (docs/formats.md, "CLI").
TEST_F(ReconstructCli, AStdoutThatCannotBeWrittenExitsTwoWithTheOutputsWhole) {
  const std::string dir = dir_ + "/stdout_full";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string args = "reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ + "/capture --out " + dir;
  ASSERT_EQ(testing::RunCli(args + "/written.ply").code, 0);
  const std::string err = dir + "/err.txt";
  const int status =
      std::system((kBin + " " + args + "/full.ply --report " + dir + "/full.json >/dev/full 2>" + err).c_str());
  EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 2);
  EXPECT_EQ(ReadFileBytes(err), "stereorig reconstruct: standard output: cannot be written: No space left on device\n");
  EXPECT_EQ(ReadFileBytes(dir + "/full.ply"), ReadFileBytes(dir + "/written.ply"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/full.json"));
}

// A report whose name takes the file system's whole 255 bytes is written
// beside the cloud, nothing else left. (Before, any name over about 235
// bytes failed: its temporary file's name, ".tmp-<pid>-<n>-<name>", passed
// 255.)
TEST_F(ReconstructCli, AReportNameOf255BytesIsWritten) {
  const std::string dir = dir_ + "/long_report_name";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string name = std::string(250, 'r') + ".json";
  const testing::Result r = testing::RunCli("reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ +
                                            "/capture --out " + dir + "/out.ply --report " + dir + "/" + name);
  EXPECT_EQ(r.code, 0) << r.err;
  std::ifstream report(dir + "/" + name);
  EXPECT_GT(nlohmann::json::parse(report, nullptr, false).value("points", 0), 40000) << "not the report";
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"out.ply", name}));
}

// Where each output goes is checked before any work (apps/output_paths.h):
// a mesh in a missing folder, or two outputs naming one file, exit 2 with
// one line naming the path, and nothing is written. (Before, the whole
// capture was reconstructed, the cloud written, then the mesh failed, or
// the mesh silently replaced the cloud.)
TEST_F(ReconstructCli, OutputPathsAreCheckedBeforeAnyWork) {
  const std::string base =
      "reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ + "/capture --out " + dir_ + "/out.ply ";
  const std::pair<std::string, std::string> cases[] = {
      {"--mesh " + dir_ + "/no_such_folder/m.stl", "its folder does not exist"},
      {"--mesh " + dir_ + "/out.ply", "would be written twice"},
      {"--report " + dir_ + "/./out.ply", "would be written twice"},
      {"--report " + dir_, "is a folder"}};
  for (const auto& [extra, says] : cases) {
    const testing::Result r = testing::RunCli(base + extra);
    EXPECT_EQ(r.code, 2) << extra;
    EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    ExpectNoOutput();
  }
  // No output over an input: the rig file named as the report (directly, or
  // through a symbolic link to it), or the options file as the cloud, would
  // be replaced by JSON or PLY. Both inputs stay byte-identical.
  auto bytes = [](const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
  };
  WriteFileAtomically(dir_ + "/o.yaml", "object_size_mm: 80\n");
  std::filesystem::remove(dir_ + "/rig_link.yaml");
  std::filesystem::create_symlink(dir_ + "/rig.yaml", dir_ + "/rig_link.yaml");
  const std::string rig_bytes = bytes(dir_ + "/rig.yaml");
  const std::pair<std::string, std::string> over_inputs[] = {
      {base + "--report " + dir_ + "/rig.yaml", "rig.yaml: is the rig file (--rig)"},
      {base + "--report " + dir_ + "/rig_link.yaml", "rig_link.yaml: is the rig file (--rig)"},
      {"reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ + "/capture --options " + dir_ + "/o.yaml --out " +
           dir_ + "/o.yaml",
       "o.yaml: is the options file (--options)"}};
  for (const auto& [args, says] : over_inputs) {
    const testing::Result r = testing::RunCli(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
  }
  EXPECT_EQ(bytes(dir_ + "/rig.yaml"), rig_bytes);
  EXPECT_EQ(bytes(dir_ + "/o.yaml"), "object_size_mm: 80\n");
  ExpectNoOutput();
}

// The capture's own images are inputs too: an output named like one of them
// (--out DIR/cam0.png, --report DIR/cam1.png, through a symbolic link, or a
// batch's --report in one of its captures) would replace it. Refused before
// any work, one line naming the path; every image byte-identical, nothing
// written. (The single run used to reconstruct and write the cloud over
// cam0.png; the batch deleted the summary's path first.)
TEST_F(ReconstructCli, AnOutputOverACaptureImageIsRefused) {
  const std::string d = BrokenCapture("own_images");
  auto bytes = [](const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
  };
  std::vector<std::string> images;
  for (int k = 0; k < 4; ++k) images.push_back(bytes(d + "/cam" + std::to_string(k) + ".png"));
  std::filesystem::remove(dir_ + "/image_link.png");
  std::filesystem::create_symlink(d + "/cam3.png", dir_ + "/image_link.png");
  const std::string head = "reconstruct --rig " + dir_ + "/rig.yaml --capture " + d;
  const std::pair<std::string, std::string> cases[] = {
      {head + " --out " + d + "/cam0.png", d + "/cam0.png: is a capture image (--capture)"},
      {head + " --out " + dir_ + "/out.ply --report " + d + "/./cam1.png", d + "/./cam1.png: is a capture image"},
      {head + " --out " + dir_ + "/image_link.png", "image_link.png: is a capture image"},
      {head + " " + dir_ + "/capture --out-dir " + dir_ + "/own_images_out --report " + d + "/cam2.png",
       d + "/cam2.png: is a capture image"}};
  for (const auto& [args, says] : cases) ExpectRefusedInOneLine(args, says);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(bytes(d + "/cam" + std::to_string(k) + ".png"), images[k]) << k;
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/own_images_out"));
  ExpectNoOutput();
}

// score reads the dataset's truth rig (the scorer's frame and fill) even
// with --rig, the rest of its truth (surfaces, maps: replaced by a report
// before) and the dataset's capture images; its --diagnose images are
// outputs too. Each collision is refused before any scoring, in one line,
// the inputs byte-identical. A batch's per-capture outputs may not be the
// rig or options file either.
TEST_F(ReconstructCli, ScoreAndBatchOutputsOverTheirInputsAreRefused) {
  auto bytes = [](const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
  };
  const std::string d = ScoreDataset("score_dataset");
  std::filesystem::create_directories(d + "/truth/scenes/cup");
  { std::ofstream(d + "/truth/scenes/cup/surface.ply") << "the truth surface\n"; }
  const std::string rig = bytes(d + "/truth/rig.yaml"), image = bytes(d + "/scenes/cup/active/cam0.png");
  const std::string score = "score --dataset " + d + " --scenes cup --no-passive";
  const std::pair<std::string, std::string> cases[] = {
      {score + " --rig " + dir_ + "/rig.yaml --report " + d + "/truth/rig.yaml",
       d + "/truth/rig.yaml: is the dataset's truth rig file"},
      {score + " --report " + d + "/scenes/cup/active/cam0.png", "cam0.png: is a capture image of the dataset"},
      {score + " --report " + d + "/truth/scenes/cup/surface.ply", "surface.ply: is a truth file of the dataset"},
      {score + " --diagnose " + dir_ + "/diag --report " + dir_ + "/diag/cup_m1_status.png",
       "cup_m1_status.png: would be written twice (the report (--report) and a diagnosis image (--diagnose))"},
      {"reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ + "/capture --out-dir " + dir_ +
           "/batch_opts --options " + dir_ + "/batch_opts/capture.json",
       "capture.json: is the options file (--options)"}};
  std::filesystem::create_directories(dir_ + "/batch_opts");
  { std::ofstream(dir_ + "/batch_opts/capture.json") << "match: {}\n"; }
  for (const auto& [args, says] : cases) ExpectRefusedInOneLine(args, says);
  EXPECT_EQ(bytes(d + "/truth/rig.yaml"), rig);
  EXPECT_EQ(bytes(d + "/scenes/cup/active/cam0.png"), image);
  EXPECT_EQ(bytes(d + "/truth/scenes/cup/surface.ply"), "the truth surface\n");
  EXPECT_EQ(bytes(dir_ + "/batch_opts/capture.json"), "match: {}\n");
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/batch_opts/capture.ply"));
}

// score takes the truth rig's module m (its fill target, its left camera's
// depth) for the cloud's module m. A --rig pairing other cameras in its
// modules (another layout's: module 0 on cameras 2 and 3) was scored
// against the wrong module's truth, exit 0. Refused before any scoring,
// naming both rigs; the truth rig's own layout goes on (to the capture here,
// which holds cam0.png alone).
TEST_F(ReconstructCli, ScoreRefusesARigWhoseModulesPairOtherCameras) {
  const std::string d = ScoreDataset("score_other_layout");
  WriteRigFile(testing::DefaultRigInAnotherLayout(), dir_ + "/other_layout.yaml");
  const std::string score = "score --dataset " + d + " --scenes cup --no-passive --rig ";
  ExpectRefusedInOneLine(score + dir_ + "/other_layout.yaml",
                         dir_ + "/other_layout.yaml: module 0 has cameras 2 and 3; in the dataset's truth rig (" + d +
                             "/truth/rig.yaml) module 0 has cameras 0 and 1: score compares each module with the "
                             "truth's of its number");
  // Fewer modules than the truth's: said as a whole clause too.
  {
    const SimulatedRig sim = MakeDefaultRig();
    const Rig one(std::vector<Camera>(sim.rig.cameras().begin(), sim.rig.cameras().begin() + 2),
                  std::vector<std::string>(sim.rig.camera_names().begin(), sim.rig.camera_names().begin() + 2),
                  std::vector<StereoModule>{sim.rig.modules()[0]}, {{sim.rig.S()[0][0]}}, "test");
    WriteRigFile(one, dir_ + "/one_module.yaml");
  }
  ExpectRefusedInOneLine(score + dir_ + "/one_module.yaml",
                         dir_ + "/one_module.yaml: there is no module 1; in the dataset's truth rig (" + d +
                             "/truth/rig.yaml) module 1 has cameras 2 and 3");
  const testing::Result same = testing::RunCli(score + dir_ + "/rig.yaml");
  EXPECT_EQ(same.code, 2);
  EXPECT_NE(same.err.find("cam1.png: missing camera image"), std::string::npos) << same.err;
}

// score creates its --diagnose folder, but only once the input is known
// good: a refused --report, a --diagnose under a file, a scene the dataset
// lacks each exit 2 in one line and leave no folder behind (score used to
// create the folder first, and left it empty on every such refusal).
TEST_F(ReconstructCli, ScoreBadInputLeavesNoDiagnoseFolder) {
  const std::string d = ScoreDataset("score_dataset_diag");
  const std::string diag = dir_ + "/diag_new";
  const std::string score = "score --dataset " + d + " --no-passive --diagnose " + diag + "/deeper";
  // A scene that passes the checks made before the folder is created (its
  // camera images there, a truth surface file) but fails once read: the
  // folder, made by then, goes again.
  std::filesystem::create_directories(d + "/scenes/broken/active");
  for (int k = 0; k < 4; ++k)
    std::filesystem::copy_file(dir_ + "/capture/cam" + std::to_string(k) + ".png",
                               d + "/scenes/broken/active/cam" + std::to_string(k) + ".png");
  std::filesystem::create_directories(d + "/truth/scenes/broken");
  WriteFileAtomically(d + "/truth/scenes/broken/surface.ply", "not a ply\n");
  const std::pair<std::string, std::string> cases[] = {
      {score + " --scenes cup --report " + dir_ + "/no_such_folder/s.json",
       "no_such_folder/s.json: its folder does not exist"},
      {score + " --scenes cup --rig " + dir_ + "/rig.yaml --report " + dir_ + "/rig.yaml",
       "rig.yaml: is the rig file (--rig)"},
      {score + " --scenes cup --report " + diag + "/deeper/cup_m0_left.png", "cup_m0_left.png: would be written twice"},
      // The report at the folder --diagnose creates, or at one above it.
      {score + " --scenes cup --report " + diag + "/deeper", "is a folder --diagnose creates"},
      {score + " --scenes cup --report " + diag, "is a folder --diagnose creates"},
      {score + " --scenes no_such_scene", "scenes/no_such_scene: no such scene in the dataset"},
      // A path, not a scene's name: its images would go under DIR/cup/.
      {score + " --scenes cup/", "--scenes cup/: 'cup/' is not a scene name"},
      {score + " --scenes broken", "broken/surface.ply"},
      // Too long a name for the file system: refused when claimed.
      {"score --dataset " + d + " --no-passive --scenes broken --diagnose " + diag + "/" + std::string(300, 'x'),
       "cannot create this folder for the diagnosis images (--diagnose)"},
      {"score --dataset " + d + " --scenes cup --diagnose " + dir_ + "/rig.yaml/diag", "rig.yaml is a file"}};
  for (const auto& [args, says] : cases) {
    std::filesystem::remove_all(diag);
    const testing::Result r = testing::RunCli(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(diag)) << args;
  }
  EXPECT_TRUE(std::filesystem::is_regular_file(dir_ + "/rig.yaml"));
}

// score checks every scene of --scenes before it scores any: a misnamed
// one after a good one exits 2 in one line and leaves no --diagnose folder.
// It used to be found only once the good scene was scored, whose diagnosis
// images stayed in the new folder.
TEST_F(ReconstructCli, ScoreChecksEverySceneBeforeScoringAny) {
  const std::string d = dir_ + "/score_sim";
  std::filesystem::remove_all(d);
  SimSpec spec = DefaultSimSpec();
  spec.scenes.names = {"sphere"};
  SimulateOptions sim;
  sim.out_dir = d;
  sim.calibration_captures = 0;
  sim.threads = 2;
  Simulate(spec, sim);
  const std::string diag = dir_ + "/score_sim_diag";
  std::filesystem::remove_all(diag);
  const testing::Result r =
      testing::RunCli("score --dataset " + d + " --scenes sphere,spher --no-passive --diagnose " + diag + "/deeper");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("scenes/spher: no such scene in the dataset (--scenes)"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("points"), std::string::npos) << "a scene was scored: " << r.out;
  EXPECT_FALSE(std::filesystem::exists(diag)) << "bad input left the --diagnose folder behind";
}

// A later scene whose input fails only once read (a truth map cut short):
// score exits 2 in one line, and neither its report nor the earlier scene's
// diagnosis images are written: not in a new --diagnose folder (gone again),
// nor over an earlier run's images in an existing one. They used to be
// written as each scene was scored, and stayed. A passive capture image
// missing is found before any scene is scored.
TEST_F(ReconstructCli, ScoreThatFailsOnALaterSceneWritesNoDiagnosisImageNorReport) {
  namespace fs = std::filesystem;
  const std::string d = testing::SimulateOneScene("sphere", 1, "score_later");
  // A second scene, the sphere's copy, with a lit map cut short.
  fs::copy(d + "/scenes/sphere", d + "/scenes/later", fs::copy_options::recursive);
  fs::copy(d + "/truth/scenes/sphere", d + "/truth/scenes/later", fs::copy_options::recursive);
  const std::string lit = d + "/truth/scenes/later/lit_cam1.png";
  fs::resize_file(lit, fs::file_size(lit) / 2);
  const std::string report = dir_ + "/score_later.json";
  WriteFileAtomically(report, "an earlier run's\n");
  const std::string score = "score --dataset " + d + " --scenes sphere,later --no-passive --report " + report;

  const std::string new_diag = dir_ + "/score_later_new_diag";
  fs::remove_all(new_diag);
  testing::Result r = testing::RunCli(score + " --diagnose " + new_diag + "/deeper");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(lit + ": a PNG cut short or damaged"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(new_diag)) << "the failed run left its --diagnose folder";

  const std::string old_diag = dir_ + "/score_later_old_diag";
  fs::remove_all(old_diag);
  fs::create_directories(old_diag);
  WriteFileAtomically(old_diag + "/sphere_m0_left.png", "an earlier run's\n");
  r = testing::RunCli(score + " --diagnose " + old_diag);
  EXPECT_EQ(r.code, 2) << r.err;
  std::vector<std::string> left;
  for (const fs::directory_entry& e : fs::directory_iterator(old_diag)) left.push_back(e.path().filename());
  EXPECT_EQ(left, std::vector<std::string>{"sphere_m0_left.png"}) << "the failed run wrote diagnosis images";
  EXPECT_EQ(ReadFileBytes(old_diag + "/sphere_m0_left.png"), "an earlier run's\n");
  EXPECT_EQ(ReadFileBytes(report), "an earlier run's\n");

  fs::copy_file(d + "/truth/scenes/sphere/lit_cam1.png", lit, fs::copy_options::overwrite_existing);
  fs::remove(d + "/scenes/later/passive/cam2.png");
  r = testing::RunCli("score --dataset " + d + " --scenes sphere,later --diagnose " + new_diag);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(d + "/scenes/later/passive/cam2.png: missing camera image"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("points"), std::string::npos) << "a scene was scored: " << r.out;
  EXPECT_FALSE(fs::exists(new_diag));
  fs::remove_all(d);
}

// Module 0's left image dark: no lit pixel, no match ROI, so no diagnosis
// image of it. An earlier run's four images of the module, left in the
// --diagnose folder, stayed beside this run's as if they were its own; they
// are removed, and the run says the module has none.
TEST_F(ReconstructCli, ScoreRemovesAnEarlierRunsImagesOfAModuleThatMakesNone) {
  namespace fs = std::filesystem;
  const std::string d = testing::SimulateOneScene("sphere", 1, "score_dark_module");
  const std::string left = d + "/scenes/sphere/active/cam0.png";
  cv::imwrite(left, cv::Mat::zeros(cv::imread(left, cv::IMREAD_UNCHANGED).size(), CV_8UC1));
  const std::string diag = dir_ + "/score_dark_module_diag";
  fs::remove_all(diag);
  fs::create_directories(diag);
  for (const char* image : {"left", "status", "lost", "error"})
    WriteFileAtomically(diag + "/sphere_m0_" + image + ".png", "an earlier run's\n");
  const testing::Result r =
      testing::RunCli("score --dataset " + d + " --scenes sphere --no-passive --diagnose " + diag);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("  m0 diagnosis images: none (the module searched no pixel)\n"), std::string::npos) << r.out;
  std::vector<std::string> images;
  for (const fs::directory_entry& e : fs::directory_iterator(diag)) images.push_back(e.path().filename());
  std::sort(images.begin(), images.end());
  EXPECT_EQ(images, (std::vector<std::string>{"sphere_m1_error.png", "sphere_m1_left.png", "sphere_m1_lost.png",
                                              "sphere_m1_status.png"}));
  fs::remove_all(d);
}

// A measurement volume deeper than the matcher can search (150 x 150 x 300
// mm at 200 mm: disparities -203 to 1535 px on this rig, past its 1024)
// is refused when the runtime is built, naming the volume. It used to reach
// the matcher's own check on a module's thread mid-capture, which with the
// modules in parallel ended the process by std::terminate (exit 134).
TEST_F(ReconstructCli, AVolumeTooDeepForTheMatcherExitsTwo) {
  for (const char* parallel : {"true", "false"}) {
    WriteFileAtomically(dir_ + "/deep.yaml",
                        std::string("volume_size_mm: [150, 150, 300]\nparallel_modules: ") + parallel + "\n");
    const testing::Result r = testing::RunCli(Args(dir_ + "/capture", "--options " + dir_ + "/deep.yaml"));
    EXPECT_EQ(r.code, 2) << "parallel_modules " << parallel << ": " << r.err;
    EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(dir_ + "/deep.yaml (runtime options): the measurement volume needs disparities"),
              std::string::npos)
        << r.err;
    ExpectNoOutput();
  }
}

// A rig file whose module cannot be rectified, and a measurement volume
// behind a module: one line naming the file that is wrong and the module, no
// output. The module of zero baseline is refused by the rig file's reader
// (under 1 mm, docs/formats.md), before rectification would.
TEST_F(ReconstructCli, ADegenerateModuleOrAVolumeBehindItNamesTheFileAndModule) {
  const SimulatedRig sim = MakeDefaultRig();
  std::vector<StereoModule> modules = sim.rig.modules();
  modules[1].right_from_left = Pose(modules[1].right_from_left.rotation(), Eigen::Vector3d::Zero());
  const Rig flat(sim.rig.cameras(), sim.rig.camera_names(), modules, sim.rig.S(), "test");
  WriteRigFile(flat, dir_ + "/flat.yaml");
  testing::Result r = testing::RunCli("reconstruct --rig " + dir_ + "/flat.yaml --capture " + dir_ + "/capture --out " +
                                      dir_ + "/out.ply --report " + dir_ + "/out.json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(dir_ + "/flat.yaml: modules[1].right_from_left: baseline 0 mm, under the 1 mm two cameras' "
                              "centres stand apart at the least: they share one centre\n"),
            std::string::npos)
      << r.err;
  ExpectNoOutput();

  // The reference frame is module 0's left camera: z < 0 is behind it. The
  // message names the option and its value, and how far off the module's
  // view the centre is.
  WriteFileAtomically(dir_ + "/behind.yaml", "volume_center_mm: [0, 0, -300]\n");
  r = testing::RunCli(Args(dir_ + "/capture", "--options " + dir_ + "/behind.yaml"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_TRUE(std::regex_search(
      r.err, std::regex(dir_ +
                        "/behind.yaml \\(runtime options\\): the measurement volume's centre \\(volume_center_mm "
                        "\\[0, 0, -300\\]\\) is not in front of " +
                        sim.rig.module(0).name +
                        ": it lies 1[4-8][0-9] deg off the module's viewing direction \\(behind it; its view reaches "
                        "about [0-9]+ deg either side\\); check volume_center_mm\n")))
      << r.err;  // module 0's pose is the reference frame itself: nothing more to check
  ExpectNoOutput();

  // Far to the side, in front of the cameras' plane but past the side of
  // their view (the modules are verged): it was "behind module0" too.
  WriteFileAtomically(dir_ + "/side.yaml", "volume_center_mm: [5000, 0, 200]\n");
  r = testing::RunCli(Args(dir_ + "/capture", "--options " + dir_ + "/side.yaml"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_TRUE(std::regex_search(
      r.err,
      std::regex("the measurement volume's centre \\(volume_center_mm \\[5000, 0, 200\\]\\) is not in front of " +
                 sim.rig.module(0).name +
                 ": it lies (9|1[0-3])[0-9] deg off the module's viewing direction \\(to its side; its view "
                 "reaches about [0-9]+ deg either side\\); check volume_center_mm\n")))
      << r.err;
  ExpectNoOutput();

  // Module 1 turned about its own vertical axis to face away, in a rig file
  // that is otherwise right: the default volume is behind it, and its pose
  // is as likely the cause as the options.
  const Eigen::Matrix3d half_turn_y = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Rig turned(sim.rig.cameras(), sim.rig.camera_names(), sim.rig.modules(),
                   {Pose(), sim.rig.S(0, 1) * Pose(half_turn_y, Eigen::Vector3d::Zero())});
  WriteRigFile(turned, dir_ + "/turned.yaml");
  r = testing::RunCli("reconstruct --rig " + dir_ + "/turned.yaml --capture " + dir_ + "/capture --out " + dir_ +
                      "/out.ply --report " + dir_ + "/out.json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("the measurement volume's centre (working_distance_mm 200, ahead of module 0) is not in "
                       "front of " +
                       sim.rig.module(1).name + ": it lies "),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(" (behind it; its view reaches about "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("; check working_distance_mm, or " + sim.rig.module(1).name + "'s pose in " + dir_ +
                       "/turned.yaml (the volume is set in module 0's frame)\n"),
            std::string::npos)
      << r.err;
  ExpectNoOutput();
}

// Many captures, one runtime (apps/reconstruct_batch.h): each cloud is the
// one a single-capture run writes, byte for byte (the runtime keeps no state
// between captures); a capture with a broken image gets no output while the
// others do, and the run exits 2.
TEST_F(ReconstructCli, ABatchWritesEachCapturesOwnCloudAndSkipsABrokenOne) {
  ASSERT_EQ(RunCli(Args(dir_ + "/capture")), 0);
  const std::string batch = dir_ + "/batch";
  std::filesystem::remove_all(batch);
  std::filesystem::create_directories(batch);
  for (const char* name : {"0001", "0002", "0003"}) std::filesystem::copy(dir_ + "/capture", batch + "/" + name);
  WriteFileAtomically(batch + "/0002/cam1.png", "not a png");  // found only when decoded
  const std::string out = dir_ + "/batch_out";
  std::filesystem::remove_all(out);
  EXPECT_EQ(RunCli("reconstruct --rig " + dir_ + "/rig.yaml --capture " + batch + "/0001 " + batch + "/0002 " + batch +
                   "/0003 --out-dir " + out + " --mesh-format STL --report " + out + "/batch.json"),  // any case
            2);
  auto bytes = [](const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
  };
  const std::string single = bytes(dir_ + "/out.ply");
  ASSERT_GT(single.size(), 1000000u);
  for (const char* name : {"0001", "0003"}) {
    EXPECT_EQ(bytes(out + "/" + name + ".ply"), single) << name;
    EXPECT_TRUE(std::filesystem::exists(out + "/" + name + ".json")) << name;
    EXPECT_TRUE(std::filesystem::exists(out + "/" + name + ".mesh.stl")) << name;
  }
  for (const char* ext : {".ply", ".json", ".mesh.stl"}) EXPECT_FALSE(std::filesystem::exists(out + "/0002" + ext));
  // Each capture's report is the single run's, the surface fit's window included.
  const nlohmann::json report = nlohmann::json::parse(bytes(out + "/0001.json"));
  ASSERT_EQ(report["modules"].size(), 2u);
  EXPECT_EQ(report["modules"][0]["surface_fit"]["window_px"].size(), 2u);
  EXPECT_GT(report["modules"][0]["surface_fit"]["pixels_fitted"].get<int>(), 10000);
  const nlohmann::json summary = nlohmann::json::parse(bytes(out + "/batch.json"));
  EXPECT_EQ(summary["reconstructed"], 2);
  EXPECT_EQ(summary["failed"], 1);
  EXPECT_EQ(summary["captures"][1]["ok"], false);
  EXPECT_NE(summary["captures"][1]["error"].get<std::string>().find("0002/cam1.png"), std::string::npos);
}

// A batch whose every capture is broken in a way found only when decoded
// (a PNG cut short, one that is not a PNG) exits 2 and leaves no new
// --out-dir behind, nor the missing folders above it (FolderToCreate,
// calib/core/folder_to_create.h); the batch used to leave them, empty. A folder that
// was there before stays, and so does one holding another capture's output
// (ABatchWritesEachCapturesOwnCloudAndSkipsABrokenOne).
TEST_F(ReconstructCli, ABatchWhoseEveryCaptureFailsLeavesNoNewFolder) {
  const std::string cut = BrokenCapture("batch_all_cut"), junk = BrokenCapture("batch_all_junk");
  {
    std::ifstream in(dir_ + "/capture/cam2.png", std::ios::binary);
    std::string bytes(std::istreambuf_iterator<char>(in), {});
    WriteFileAtomically(cut + "/cam2.png", bytes.substr(0, bytes.size() / 2));
  }
  WriteFileAtomically(junk + "/cam1.png", "not a png");
  const std::string head = "reconstruct --rig " + dir_ + "/rig.yaml --capture " + cut + " " + junk + " --out-dir ";
  const std::string fresh = dir_ + "/batch_all_new";
  std::filesystem::remove_all(fresh);
  const testing::Result r = testing::RunCli(head + fresh + "/deeper");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("batch_all_cut/cam2.png"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("batch_all_junk/cam1.png"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(fresh)) << "bad input left the --out-dir folder behind";
  const std::string existing = dir_ + "/batch_all_existing";
  std::filesystem::remove_all(existing);
  std::filesystem::create_directories(existing);
  EXPECT_EQ(RunCli(head + existing), 2);
  EXPECT_TRUE(std::filesystem::is_directory(existing)) << "a folder that was there before was removed";
}

// A batch's failed capture has its line on stdout too, as the stream's has
// ("[k/N] DIR: no output (<why>)"), beside stderr's: docs/reconstruct.md
// promises one line per capture there, and a failed one used to have none.
TEST_F(ReconstructCli, ABatchPrintsALineOnStdoutForEachFailedCapture) {
  const std::string junk = BrokenCapture("batch_line_junk"), cut = BrokenCapture("batch_line_cut");
  WriteFileAtomically(junk + "/cam1.png", "not a png");
  WriteFileAtomically(cut + "/cam2.png", ReadFileBytes(dir_ + "/capture/cam2.png").substr(0, 1000));
  const std::string out = dir_ + "/batch_line_out";
  std::filesystem::remove_all(out);
  const testing::Result r =
      testing::RunCli("reconstruct --rig " + dir_ + "/rig.yaml --capture " + junk + " " + cut + " --out-dir " + out);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.out.find("[1/2] " + junk + ": no output (" + junk + "/cam1.png: is not a PNG file"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("[2/2] " + cut + ": no output (" + cut + "/cam2.png: "), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("stereorig reconstruct: [1/2] " + junk + "/cam1.png"), std::string::npos) << r.err;
}

// An --out-dir that cannot be made (a name longer than the file system's
// 255 characters) exits 2 in one line naming it, and leaves no folder above
// it: refused when claimed (OutputPaths::ClaimFolder), before the runtime
// is built; it used to be found once it was built, and the folder made
// above it on the way stayed, empty.
TEST_F(ReconstructCli, ABatchOutDirThatCannotBeMadeLeavesNoFolder) {
  const std::string fresh = dir_ + "/batch_long";
  std::filesystem::remove_all(fresh);
  const std::string out = fresh + "/" + std::string(300, 'x');
  const testing::Result r =
      testing::RunCli("reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ + "/capture --out-dir " + out);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(out + ": cannot create this folder for the output folder (--out-dir)"), std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(fresh)) << "the folder made on the way was left behind";
}

// Sets or clears a file's immutable attribute (chattr +i, -i); false where
// the file system or the process's capabilities (CAP_LINUX_IMMUTABLE) do not
// allow it.
bool SetImmutable(const std::string& path, bool immutable) {
  const int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return false;
  int flags = 0;
  bool done = ioctl(fd, FS_IOC_GETFLAGS, &flags) == 0;
  flags = immutable ? flags | FS_IMMUTABLE_FL : flags & ~FS_IMMUTABLE_FL;
  done = done && ioctl(fd, FS_IOC_SETFLAGS, &flags) == 0;
  close(fd);
  return done;
}

// A capture whose outputs cannot be written has none, not a partial nor a
// stale one, and the batch goes on. The trigger: an earlier run's mesh of
// the second capture that is immutable (chattr +i), so its cloud is written,
// then renaming the new mesh over the old fails with EPERM, late, as a full
// disk would fail a write (root ignores permissions, and the claim refuses a
// folder at an output path, so these tests cannot use them; a name whose
// temporary file's name was too long for the file system served before,
// until temporary names were made to fit). The written cloud must go too;
// the immutable mesh stays as it was.
TEST_F(ReconstructCli, ABatchCaptureWhoseOutputsCannotBeWrittenHasNone) {
  const std::string batch = dir_ + "/batch_write", out = dir_ + "/batch_write_out";
  const std::string old_mesh = out + "/0002.mesh.stl";
  SetImmutable(old_mesh, false);  // left by a run that crashed
  std::filesystem::remove_all(batch);
  std::filesystem::remove_all(out);
  std::filesystem::create_directories(batch);
  std::filesystem::create_directories(out);
  for (const char* name : {"0001", "0002"}) std::filesystem::copy(dir_ + "/capture", batch + "/" + name);
  std::ofstream(out + "/0002.json") << "a report from an earlier run\n";
  std::ofstream(old_mesh) << "a mesh from an earlier run\n";
  if (!SetImmutable(old_mesh, true)) GTEST_SKIP() << "cannot make a file immutable here (CAP_LINUX_IMMUTABLE?)";
  struct Mutable {
    std::string path;
    ~Mutable() { SetImmutable(path, false); }  // whatever the test found: the next run can remove it
  } undo{old_mesh};
  const testing::Result r =
      testing::RunCli("reconstruct --rig " + dir_ + "/rig.yaml --capture " + batch + "/0001 " + batch +
                      "/0002 --out-dir " + out + " --mesh-format stl --report " + out + "/batch.json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("[2/2] " + old_mesh + ": cannot write: Operation not permitted"), std::string::npos) << r.err;
  for (const char* ext : {".ply", ".json", ".mesh.stl"})
    EXPECT_TRUE(std::filesystem::exists(out + "/0001" + ext)) << ext;
  for (const char* ext : {".ply", ".json"}) EXPECT_FALSE(std::filesystem::exists(out + "/0002" + ext)) << ext;
  std::ifstream mesh(old_mesh);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(mesh), {}), "a mesh from an earlier run\n");
  std::ifstream f(out + "/batch.json");
  const nlohmann::json summary = nlohmann::json::parse(f);
  EXPECT_EQ(summary["reconstructed"], 1);
  EXPECT_EQ(summary["failed"], 1);
  EXPECT_EQ(summary["captures"][0]["ok"], true);
  EXPECT_EQ(summary["captures"][1]["ok"], false);
  EXPECT_NE(summary["captures"][1]["error"].get<std::string>().find("cannot write"), std::string::npos);
  for (const auto& entry : std::filesystem::directory_iterator(out))  // no temporary left behind
    EXPECT_NE(entry.path().filename().string().rfind(".tmp-", 0), 0u) << entry.path();
}

// What needs no decoding is checked for every capture first: a missing
// camera in the last folder, a folder given twice, or --out with several
// captures write nothing at all.
TEST_F(ReconstructCli, ABatchWithAMissingCameraOrARepeatedFolderWritesNothing) {
  const std::string missing = BrokenCapture("batch_missing");
  std::filesystem::remove(missing + "/cam3.png");
  const std::string out = dir_ + "/batch_nothing";
  std::filesystem::remove_all(out);
  const std::string head = "reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ + "/capture ";
  EXPECT_EQ(RunCli(head + missing + " --out-dir " + out), 2);
  EXPECT_EQ(RunCli(head + dir_ + "/capture/ --out-dir " + out), 2);
  EXPECT_EQ(RunCli(head + missing + " --out " + dir_ + "/out.ply"), 2);
  EXPECT_EQ(RunCli(head + "--out-dir " + out + " --mesh-format obj"), 2);
  // Folders "x" and "x.mesh": x's mesh would be x.mesh's cloud.
  const std::string clash = dir_ + "/batch_clash";
  std::filesystem::remove_all(clash);
  std::filesystem::create_directories(clash);
  std::filesystem::copy(dir_ + "/capture", clash + "/x");
  std::filesystem::copy(dir_ + "/capture", clash + "/x.mesh");
  EXPECT_EQ(RunCli("reconstruct --rig " + dir_ + "/rig.yaml --capture " + clash + "/x " + clash + "/x.mesh --out-dir " +
                   out + " --mesh-format ply"),
            2);
  // The summary's folder does not exist: found before the first cloud.
  EXPECT_EQ(RunCli(head + "--out-dir " + out + " --report " + dir_ + "/no_such_folder/batch.json"), 2);
  // An --out-dir that is a file, or under one: refused with the paths
  // (apps/output_paths.h ClaimFolder), not when the runtime is built and the
  // folder cannot be made; the file is left as it was.
  const std::string file = dir_ + "/batch_a_file";
  { std::ofstream(file) << "not a folder\n"; }
  for (const std::string& bad : {file, file + "/sub"}) {
    const testing::Result r = testing::RunCli(head + "--out-dir " + bad);
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(bad + ": "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("is a file, not a folder for the output folder (--out-dir)"), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("reconstruct"), std::string::npos) << r.out;  // no capture begun
  }
  std::ifstream f(file);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(f), {}), "not a folder\n");
  EXPECT_FALSE(std::filesystem::exists(out));
  ExpectNoOutput();
}

// A capture in which a module gives no point (its lasers off, a camera not
// triggered, its cables swapped) is no measurement there: a batch, as a
// line runs it, warns of each such module on the capture's own lines, on
// stdout and on stderr, and its summary and last line count those captures;
// the exit code stays 0 (the captures were reconstructed and written:
// docs/formats.md). Before, an all-black capture gave "0 points (fill m0
// 0.0%, m1 0.0%)", "2 of 2 captures" and not a word; a single capture's
// hint was on stdout only.
TEST_F(ReconstructCli, ABatchWarnsOfEachModuleThatGaveNoPointAndCountsThem) {
  const std::string dark = BrokenCapture("batch_dark"), half = BrokenCapture("batch_half_dark");
  for (int k = 0; k < 4; ++k) {
    const std::string image = "/cam" + std::to_string(k) + ".png";
    const cv::Mat black = cv::Mat::zeros(cv::imread(dark + image).size(), CV_8UC1);
    ASSERT_TRUE(cv::imwrite(dark + image, black));
    if (k >= 2) {
      ASSERT_TRUE(cv::imwrite(half + image, black));  // module 1's cameras
    }
  }
  const std::string out = dir_ + "/batch_dark_out";
  std::filesystem::remove_all(out);
  const testing::Result r = testing::RunCli("reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ + "/capture " +
                                            dark + " " + half + " --out-dir " + out + " --report " + out + "/run.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string no_lit = "gave no point (" + out + "/batch_dark.json): no lit pixels: is the projector on";
  for (const std::string& says : std::vector<std::string>{
           "[2/3] " + dark + ": 0 points (fill m0 0.0%, m1 0.0%), ", "\n  warning: module 0 " + no_lit,
           "\n  warning: module 1 " + no_lit,
           "\n  warning: module 1 gave no point (" + out + "/batch_half_dark.json): ", "3 of 3 captures in ",
           "; 2 with a module that gave no point\n"})
    EXPECT_NE(r.out.find(says), std::string::npos) << says << "\n" << r.out;
  EXPECT_EQ(r.out.find("module 0 gave no point (" + out + "/batch_half_dark.json)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("(" + out + "/capture.json): "), std::string::npos) << r.out;  // the lit capture: no warning
  for (const std::string& says :
       std::vector<std::string>{"stereorig reconstruct: [2/3] " + dark + ": warning: module 0 gave no point: no lit",
                                "stereorig reconstruct: [3/3] " + half + ": warning: module 1 gave no point: ",
                                "stereorig reconstruct: warning: 2 of 3 captures written have a module that gave no "
                                "point"})
    EXPECT_NE(r.err.find(says), std::string::npos) << says << "\n" << r.err;
  std::ifstream f(out + "/run.json");
  const nlohmann::json summary = nlohmann::json::parse(f);
  EXPECT_EQ(summary["reconstructed"], 3);
  EXPECT_EQ(summary["with_modules_without_points"], 2);
  EXPECT_EQ(summary["captures"][0]["modules_without_points"], nlohmann::json::array());
  EXPECT_EQ(summary["captures"][1]["modules_without_points"], nlohmann::json({0, 1}));
  EXPECT_EQ(summary["captures"][2]["modules_without_points"], nlohmann::json({1}));
  // One capture: its hint on stderr too, exit 0.
  const testing::Result single = testing::RunCli(Args(dark));
  EXPECT_EQ(single.code, 0) << single.err;
  EXPECT_NE(single.err.find("stereorig reconstruct: warning: module 1 gave no point: no lit pixels: is the projector "
                            "on"),
            std::string::npos)
      << single.err;
}

// One folder given through two paths (a link to its parent) is given twice:
// refused before anything is written, as the same path twice is. Before,
// the paths' text was compared, and the folder reconstructed twice.
TEST_F(ReconstructCli, ABatchRefusesOneFolderGivenThroughALinkToo) {
  const std::string link = dir_ + "/link_to_dir", out = dir_ + "/batch_link_out";
  std::filesystem::remove(link);
  std::filesystem::create_directory_symlink(dir_, link);
  std::filesystem::remove_all(out);
  const testing::Result r = testing::RunCli("reconstruct --rig " + dir_ + "/rig.yaml --capture " + dir_ + "/capture " +
                                            link + "/capture --out-dir " + out);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--capture: " + link + "/capture is given twice (as " + dir_ + "/capture)"), std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

// A --report that is a link to a stream (here /proc/self/fd/1, as
// /dev/stdout is) is refused before any work even when the stream is a file
// (cron's "--report /dev/stdout >> log"), and the link is left a link: the
// rename replaced it with the report (as root, /dev/stdout itself). A link
// in a scratch folder stands for /dev/stdout here.
TEST_F(ReconstructCli, AReportLinkedToARedirectedStdoutIsRefusedAndTheLinkKept) {
  const std::string dir = dir_ + "/stdout_link";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::filesystem::create_symlink("/proc/self/fd/1", dir + "/stdout");
  const int status = std::system(("cd " + dir + " && " + kBin + " reconstruct --rig " + dir_ + "/rig.yaml --capture " +
                                  dir_ + "/capture --out out.ply --report stdout >>log.txt 2>err.txt")
                                     .c_str());
  EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 2);
  std::ifstream err_file(dir + "/err.txt");
  const std::string err(std::istreambuf_iterator<char>(err_file), {});
  EXPECT_EQ(testing::Lines(err), 1) << err;
  EXPECT_NE(err.find("stdout: leads to /proc/self/fd/1 through a symbolic link, in /dev or /proc"), std::string::npos)
      << err;
  EXPECT_TRUE(std::filesystem::is_symlink(dir + "/stdout"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/out.ply"));
}

// A batch's capture, written or failed, leaves no earlier run's mesh of its
// name beside this run's outputs: neither one of the other format than this
// run's --mesh-format, nor either without one. (An earlier <name>.mesh.stl
// stayed beside the new <name>.ply, or as the only file of a failed
// capture, although the run promises "an earlier run's files of its name
// are removed, so none is mistaken for this run's".) A file this run writes
// stays: folders "bad" and "bad.mesh" without --mesh-format, bad.mesh.ply is
// a cloud.
TEST_F(ReconstructCli, ABatchRemovesAnEarlierRunsMeshOfTheOtherFormat) {
  const std::string root = dir_ + "/batch_mesh";
  std::filesystem::remove_all(root);
  std::filesystem::create_directories(root);
  for (const char* name : {"good", "bad", "bad.mesh"}) std::filesystem::copy(dir_ + "/capture", root + "/" + name);
  WriteFileAtomically(root + "/bad/cam1.png", "not a png");  // found only when decoded
  const std::string out = root + "/out";
  auto earlier_run = [&] {
    std::filesystem::remove_all(out);
    std::filesystem::create_directories(out);
    for (const char* name : {"good", "bad"})
      for (const char* ext : {".ply", ".json", ".mesh.ply", ".mesh.stl"})
        WriteFileAtomically(out + "/" + name + ext, "earlier run");
  };
  auto names = [&] {
    std::vector<std::string> found;
    for (const auto& e : std::filesystem::directory_iterator(out)) found.push_back(e.path().filename());
    std::sort(found.begin(), found.end());
    return found;
  };
  const std::string head = "reconstruct --rig " + dir_ + "/rig.yaml --out-dir " + out + " --capture ";
  earlier_run();
  testing::Result r = testing::RunCli(head + root + "/good " + root + "/bad --mesh-format ply");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(names(), (std::vector<std::string>{"good.json", "good.mesh.ply", "good.ply"})) << r.out;
  earlier_run();
  r = testing::RunCli(head + root + "/good " + root + "/bad");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(names(), (std::vector<std::string>{"good.json", "good.ply"})) << r.out;
  earlier_run();
  r = testing::RunCli(head + root + "/bad.mesh " + root + "/bad");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(names(), (std::vector<std::string>{"bad.mesh.json", "bad.mesh.ply", "good.json", "good.mesh.ply",
                                               "good.mesh.stl", "good.ply"}))
      << r.out;
  EXPECT_GT(std::filesystem::file_size(out + "/bad.mesh.ply"), 1000000u);  // the cloud this run wrote
}

// An earlier run's cloud is not a mesh, whatever its name: folders nm/x.mesh
// and caps/a are named nm_x.mesh and caps_a, so the cloud of the first is
// nm_x.mesh.ply, where a later batch's capture nm/x (named nm_x) would put
// its PLY mesh. That batch, with no --mesh-format, removed nm_x.mesh.ply as
// an earlier mesh of nm_x, exit 0, leaving nm_x.mesh.json without its
// cloud. A real mesh of that name (the PLY header's face element) is still
// removed by a batch that writes none of that format.
TEST_F(ReconstructCli, ABatchKeepsAnEarlierRunsCloudNamedLikeAMesh) {
  const std::string root = dir_ + "/batch_cloud_named_mesh";
  std::filesystem::remove_all(root);
  for (const char* name : {"nm/x.mesh", "nm/x", "caps/a", "caps/b"}) {
    std::filesystem::create_directories(std::filesystem::path(root + "/" + name).parent_path());
    std::filesystem::copy(dir_ + "/capture", root + "/" + name);
  }
  const std::string out = root + "/out", head = "reconstruct --rig " + dir_ + "/rig.yaml --out-dir " + out;
  testing::Result r = testing::RunCli(head + " --capture " + root + "/nm/x.mesh " + root + "/caps/a");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string cloud = ReadFileBytes(out + "/nm_x.mesh.ply");
  ASSERT_GT(cloud.size(), 1000000u);  // the capture's cloud, not an empty file
  r = testing::RunCli(head + " --capture " + root + "/nm/x " + root + "/caps/b");
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(std::filesystem::exists(out + "/nm_x.mesh.ply")) << r.out;
  EXPECT_EQ(ReadFileBytes(out + "/nm_x.mesh.ply"), cloud);
  EXPECT_TRUE(std::filesystem::exists(out + "/nm_x.mesh.json"));
  EXPECT_TRUE(std::filesystem::exists(out + "/nm_x.ply"));
  // With --mesh-format ply, nm_x's mesh would be written over that cloud
  // (second reading: it replaced it, or its capture failing removed it):
  // the capture fails naming it, and the cloud and its report stay.
  r = testing::RunCli(head + " --mesh-format ply --capture " + root + "/nm/x " + root + "/caps/b");
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find(out + "/nm_x.mesh.ply: is an earlier run's point cloud (of a capture named like this one's "
                             "mesh): not replaced"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(ReadFileBytes(out + "/nm_x.mesh.ply"), cloud);
  EXPECT_TRUE(std::filesystem::exists(out + "/nm_x.mesh.json"));
  EXPECT_TRUE(std::filesystem::exists(out + "/caps_b.mesh.ply")) << r.out;  // the other capture goes on

  // A PLY mesh of nm_x, then a batch writing STL meshes: the PLY one goes.
  const std::string meshes = root + "/meshes",
                    mesh_head = "reconstruct --rig " + dir_ + "/rig.yaml --out-dir " + meshes;
  r = testing::RunCli(mesh_head + " --mesh-format ply --capture " + root + "/nm/x " + root + "/caps/b");
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(std::filesystem::exists(meshes + "/nm_x.mesh.ply"));
  r = testing::RunCli(mesh_head + " --mesh-format stl --capture " + root + "/nm/x " + root + "/caps/b");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(std::filesystem::exists(meshes + "/nm_x.mesh.ply")) << r.out;
  EXPECT_TRUE(std::filesystem::exists(meshes + "/nm_x.mesh.stl")) << r.out;
}

// Module 0's right camera (cam1) not triggered: its image black, the left's
// grid-lit. The left's pixels all end no_sgm_match, and the summary used to
// send the user to the measurement volume; it names the dark right image.
TEST_F(ReconstructCli, ADarkRightImageIsNamedNotTheVolume) {
  const std::string capture = BrokenCapture("dark_right");
  const std::string image = capture + "/cam1.png";
  ASSERT_TRUE(cv::imwrite(image, cv::Mat::zeros(cv::imread(image).size(), CV_8UC1)));
  const testing::Result r = testing::RunCli(Args(capture));
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string says =
      "no point: no pixel of the right camera's image (cam1.png) is grid-lit (9x9 std above "
      "lit_contrast_dn), while the left camera's (cam0.png) is: a dark or flat right image";
  const size_t at = r.out.find("module 0: 0 points"), next = r.out.find("\nmodule 1: ");
  ASSERT_NE(at, std::string::npos) << r.out;
  ASSERT_NE(next, std::string::npos) << r.out;
  const std::string summary = r.out.substr(at, next - at);
  EXPECT_NE(summary.find("\n  " + says), std::string::npos) << summary;
  EXPECT_EQ(summary.find("working_distance_mm"), std::string::npos) << summary;
  EXPECT_NE(r.err.find("stereorig reconstruct: warning: module 0 gave no point: " + says.substr(10)), std::string::npos)
      << r.err;
  EXPECT_EQ(r.out.find("module 1: 0 points"), std::string::npos) << r.out;  // module 1's cameras are lit
  // The report says it too: a line reading only the JSON must not blame the volume.
  std::ifstream f(dir_ + "/out.json");
  const nlohmann::json modules = nlohmann::json::parse(f)["modules"];
  EXPECT_EQ(modules[0]["right_camera_lit_pixels"], 0) << modules[0].dump();
  EXPECT_FALSE(modules[0].contains("left_camera_lit_pixels")) << modules[0].dump();   // lit in the volume's ROI
  EXPECT_FALSE(modules[1].contains("right_camera_lit_pixels")) << modules[1].dump();  // it kept points
}

// Images too small for the matcher's coarse level (1 px high; narrower than
// its halvings): OpenCV's resize to 0 px aborted the process (exit 134).
// Now exit 2 naming the image and the smallest size the options allow: a
// census window (5x7 px by default) at the coarsest level, so 10x14 px with
// the band pass's halving, 40x56 with 3 pyramid levels; at that size it
// matches.
TEST(MatchCli, ImagesTooSmallForTheCoarseLevelExitTwoNamingTheMinimum) {
  const std::string dir = ::testing::TempDir() + "/match_cli_tiny";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  cv::Mat ramp(1, 100, CV_8UC1);
  for (int x = 0; x < ramp.cols; ++x) ramp.at<uint8_t>(0, x) = uint8_t(x);
  ASSERT_TRUE(cv::imwrite(dir + "/row.png", ramp));
  ASSERT_TRUE(cv::imwrite(dir + "/column.png", ramp.t()));
  ASSERT_TRUE(cv::imwrite(dir + "/32.png", cv::Mat(32, 32, CV_8UC1, cv::Scalar(100))));
  ASSERT_TRUE(cv::imwrite(dir + "/10x14.png", cv::Mat(14, 10, CV_8UC1, cv::Scalar(100))));
  const std::string out = dir + "/d.pfm";
  auto match = [&](const std::string& image, const std::string& extra = "") {
    return testing::RunCli("match --left " + dir + "/" + image + " --right " + dir + "/" + image +
                           " --min-disparity 0 --num-disparities 16 --out " + out + extra);
  };
  const std::tuple<std::string, std::string, std::string> refused[] = {
      {"row.png", "", "row.png: is 100x1 px (the right image too), smaller than the 10x14 px match needs"},
      {"column.png", "", "column.png: is 1x100 px (the right image too), smaller than the 10x14 px match needs"},
      {"32.png", " --pyramid-levels 3",
       "32.png: is 32x32 px (the right image too), smaller than the 40x56 px match needs with these options: its "
       "coarsest level, the images halved 3 times (pyramid_levels), must hold a census window of 5x7 px"}};
  for (const auto& [image, extra, says] : refused) {
    const testing::Result r = match(image, extra);
    EXPECT_EQ(r.code, 2) << image << extra << ": " << r.err;
    EXPECT_EQ(testing::Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << image;
  }
  for (const auto& [image, extra] : {std::pair{"10x14.png", ""}, {"32.png", " --pyramid-levels 1"}}) {
    std::filesystem::remove(out);
    const testing::Result r = match(image, extra);
    EXPECT_EQ(r.code, 0) << image << extra << ": " << r.err;
    EXPECT_TRUE(std::filesystem::exists(out)) << image;
  }
}

// An options file whose `match:` keys are all commented out was refused
// ("match: expected a mapping"), though docs/formats.md says a file with
// every key commented out reads as the defaults. It reconstructs as they do.
TEST_F(ReconstructCli, AnOptionsSectionWithEveryKeyCommentedOutIsTheDefaults) {
  WriteFileAtomically(dir_ + "/commented_match.yaml", "object_size_mm: 60\nmatch:\n#  min_zncc: 0.7\n");
  const testing::Result r = testing::RunCli(Args(dir_ + "/capture", "--options " + dir_ + "/commented_match.yaml"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir_ + "/out.ply"));
}

// A one-row vernier window was accepted, and module 1 of the sphere lost
// every point (wrong_line): refused before any work, saying why.
TEST_F(ReconstructCli, AOneRowVernierWindowIsRefused) {
  WriteFileAtomically(dir_ + "/one_row.yaml", "match:\n  line_index_window_half_height_px: 0\n");
  ExpectRefusedInOneLine(Args(dir_ + "/capture", "--options " + dir_ + "/one_row.yaml"),
                         "one_row.yaml: match.line_index_window_half_height_px: must be in [1, 30] (3 to 61 rows): "
                         "the vernier fits a row offset between the views, which a window of one row (0) cannot read");
  ExpectNoOutput();
}

}  // namespace
}  // namespace stereorig

namespace stereorig {
namespace {

// A camera turned since calibration: module 0's right camera turned about
// its x axis by an angle that moves its rows 0.12 px (fx * angle), written
// as a rig file that still says where it was. The capture is the sphere
// rendered with the true rig. Rectifying with the old pose, the right view's
// rows come out fx * angle lower: the vernier reads +0.12 px (-0.12 turned
// back). Below the ~0.18 px where the line index goes a period off, so the
// points stay on their lines: a warning, exit 0. Tolerance on the reading:
// 3 standard errors of the difference (the report's own) plus 20 % of the
// turn, the bound docs/reconstruct.md states for the vernier's gain (its
// cubic row blend over-reads sub-row shifts by 7-15 %: row_drift_test.cc).
TEST_F(ReconstructCli, ACameraTurnedSinceCalibrationIsWarnedOfByItsRowDrift) {
  auto drift_of = [&](const std::string& rig_path, testing::Result* r) {
    *r = testing::RunCli("reconstruct --rig " + rig_path + " --capture " + dir_ + "/capture --out " + dir_ +
                         "/out.ply --report " + dir_ + "/out.json");
    std::ifstream f(dir_ + "/out.json");
    return nlohmann::json::parse(f)["modules"];
  };
  testing::Result r;
  const nlohmann::json right = drift_of(dir_ + "/rig.yaml", &r);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const auto& m : right) {
    ASSERT_TRUE(m["row_drift"].is_object()) << m.dump();
    EXPECT_GE(m["row_drift"]["components"].get<int>(), 1) << m.dump();
    EXPECT_FALSE(m["row_drift"]["warned"].get<bool>()) << m.dump();
  }
  EXPECT_EQ(r.out.find("rectified rows read"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("rectified rows read"), std::string::npos) << r.err;

  const SimulatedRig sim = MakeDefaultRig();
  const int right_camera = sim.rig.module(0).right_camera;
  const double turn_rad = 0.12 / sim.rig.camera(right_camera).fx();
  double reading[2], se[2];
  for (int k = 0; k < 2; ++k) {
    const double sign = k == 0 ? 1 : -1;
    std::vector<StereoModule> modules = sim.rig.modules();
    const Pose turn = Pose::FromRotationVector(Eigen::Vector3d(sign * turn_rad, 0, 0), Eigen::Vector3d::Zero());
    modules[0].right_from_left = turn * modules[0].right_from_left;
    const Rig turned(sim.rig.cameras(), sim.rig.camera_names(), modules, sim.rig.S(), "test");
    const std::string path = dir_ + "/turned" + std::to_string(k) + ".yaml";
    WriteRigFile(turned, path);
    const nlohmann::json modules_json = drift_of(path, &r);
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json& drift = modules_json[0]["row_drift"];
    ASSERT_TRUE(drift.is_object()) << modules_json.dump();
    EXPECT_TRUE(drift["warned"].get<bool>()) << drift.dump();
    reading[k] = drift["row_offset_px"].get<double>() - right[0]["row_drift"]["row_offset_px"].get<double>();
    se[k] =
        std::hypot(drift["standard_error_px"].get<double>(), right[0]["row_drift"]["standard_error_px"].get<double>());
    EXPECT_NE(r.out.find("\n  warning: its rectified rows read " + std::string(sign > 0 ? "+" : "-")),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("run `stereorig check --rig RIG --captures DIR --target BOARD`"), std::string::npos) << r.out;
    // On stderr too, as a module with no point is: a log keeps the problems.
    EXPECT_NE(r.err.find("stereorig reconstruct: warning: module 0's rectified rows read " +
                         std::string(sign > 0 ? "+" : "-")),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("module 1's rectified rows"), std::string::npos) << r.err;
    EXPECT_FALSE(modules_json[1]["row_drift"]["warned"].get<bool>()) << modules_json.dump();  // not turned
  }
  std::printf("turned +-0.12 px: read %+.4f (se %.4f), %+.4f (se %.4f) px over the true rig's\n", reading[0], se[0],
              reading[1], se[1]);
  EXPECT_NEAR(reading[0], 0.12, 3 * se[0] + 0.2 * 0.12);
  EXPECT_NEAR(reading[1], -0.12, 3 * se[1] + 0.2 * 0.12);

  // A batch (what a line runs) says it in a line naming the module, from the
  // mean of the module's readings over its last captures (three copies of
  // the capture here: the same reading thrice), and lists it in the capture's
  // entry of the summary.
  std::vector<std::string> copies;
  for (const char* name : {"/turned_a", "/turned_b", "/turned_c"}) {
    std::filesystem::remove_all(dir_ + name);
    std::filesystem::copy(dir_ + "/capture", dir_ + name);
    copies.push_back(dir_ + name);
  }
  r = testing::RunCli("reconstruct --rig " + dir_ + "/turned0.yaml --capture " + copies[0] + " " + copies[1] + " " +
                      copies[2] + " --out-dir " + dir_ + "/batch_turned --report " + dir_ + "/batch_turned.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\n  warning: module 0's rectified rows read 0."), std::string::npos) << r.out;
  for (const std::string last : {"1 capture's", "2 captures'", "3 captures'"})
    EXPECT_NE(r.out.find("the mean size of its last " + last + " readings (standard error "), std::string::npos)
        << r.out;
  std::ifstream summary_file(dir_ + "/batch_turned.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  ASSERT_EQ(summary["captures"].size(), 3u) << summary.dump();
  EXPECT_EQ(summary["with_row_drift"], 3);
  for (const auto& c : summary["captures"])
    EXPECT_EQ(c["modules_with_row_drift"], nlohmann::json::array({0})) << c.dump();
  EXPECT_EQ(r.out.find("warning: module 1's rectified rows"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace stereorig
