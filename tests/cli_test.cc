// The CLI contract (docs/formats.md, "CLI"): exit codes, one-line errors that
// name the file and key, and no output left behind on failure. Runs the real
// `stereorig` binary.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <vector>

#include "calib/core/png_testing.h"
#include "calib/core/rig_file.h"
#include "datasets/default_rig.h"
#include "tests/cli_runner.h"

namespace {

using stereorig::testing::Lines;
using stereorig::testing::Result;
using stereorig::testing::RunCli;

// The embedded default rig, as the simulator writes its truth.
std::string GoodRigText() {
  stereorig::SimulatedRig sim = stereorig::MakeDefaultRig();
  sim.rig.provenance().date_utc = "2026-11-23T00:00:00Z";
  return stereorig::RigToYaml(sim.rig);
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(Cli, HelpListsEveryCommandAndExitsZero) {
  const Result r = RunCli("--help");
  EXPECT_EQ(r.code, 0);
  for (const char* c : {"simulate", "target", "calibrate", "reconstruct", "match", "verify", "check", "bench", "demo"})
    EXPECT_NE(r.out.find(c), std::string::npos) << c;
  const Result sub = RunCli("rig --help");
  EXPECT_EQ(sub.code, 0);
  EXPECT_NE(sub.out.find("Example"), std::string::npos);
}

TEST(Cli, UnknownCommandAndBadFlagsExitTwoWithOneLine) {
  Result r = RunCli("frobnicate");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1);
  r = RunCli("rig --no-such-flag");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
}

// A binary file given where YAML is expected put its raw bytes into the
// error line (yaml-cpp quotes the character it stopped at): they are
// written as \xNN, while a path's valid UTF-8 ('å') stays as it is.
TEST(Cli, AnErrorLineHoldsNoRawBinaryBytes) {
  const std::string dir = ::testing::TempDir() + "/kåsa_" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  const std::string binary = dir + "/artifact.yaml";
  {
    std::ofstream f(binary, std::ios::binary);
    f << "format: \"\\\xAB\x01\"\n";  // an escape YAML does not know, then a control byte
  }
  const Result r = RunCli("verify --artifact " + binary + " --cloud " + binary);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("kåsa_"), std::string::npos) << r.err;  // UTF-8 kept
  EXPECT_NE(r.err.find("\\xAB"), std::string::npos) << r.err;
  for (size_t i = 0; i + 1 < r.err.size(); ++i) {
    const auto c = static_cast<unsigned char>(r.err[i]);
    EXPECT_FALSE(c < 0x20 || c == 0x7F || c == 0xAB) << "byte " << i << " of " << r.err;
  }
  std::filesystem::remove_all(dir);
  // An option's own error echoes the user's text, and an unknown command its
  // name: a C1 control (U+009B, CSI: C2 9B) and an ESC in them are escaped
  // too (a second reading: they bypassed the escaping at first).
  for (const std::string& args : {std::string("verify --capture-band-mm 'x\xC2\x9B\x1B' --artifact a --cloud b"),
                                  std::string("'no-such-command\xC2\x9B\x1B'")}) {
    const Result bad = RunCli(args);
    EXPECT_EQ(bad.code, 2);
    EXPECT_NE(bad.err.find("\\xC2\\x9B\\x1B"), std::string::npos) << bad.err;
    for (size_t i = 0; i + 1 < bad.err.size(); ++i) {
      const auto c = static_cast<unsigned char>(bad.err[i]);
      EXPECT_FALSE(c < 0x20 || c == 0x9B || c == 0xC2) << "byte " << i << " of " << bad.err;
    }
  }
}

TEST(Cli, GoodRigFileIsAccepted) {
  const std::string path = ::testing::TempDir() + "/good_rig.yaml";
  std::ofstream(path) << GoodRigText();
  const Result r = RunCli("rig --rig " + path);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("2 module(s)"), std::string::npos);
  EXPECT_NE(r.out.find("calibration target: not recorded"), std::string::npos) << r.out;
  // One that records its board says which, and how far stage 3 moved the
  // faces' transform from the file's.
  stereorig::Rig rig = stereorig::MakeDefaultRig().rig;
  const stereorig::Pose file_pose = stereorig::Pose::FromRotationVector({0, M_PI, 0}, {90, 0, 5});
  rig.provenance().target = stereorig::CalibrationTarget{
      "lab/board.yaml",
      11,
      9,
      9,
      true,
      stereorig::Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0.003, 0.004)) * file_pose,
      file_pose,
      Eigen::Matrix<double, 6, 1>::Constant(0.01)};
  std::ofstream(path) << stereorig::RigToYaml(rig);
  const Result recorded = RunCli("rig --rig " + path);
  EXPECT_EQ(recorded.code, 0) << recorded.err;
  EXPECT_NE(recorded.out.find("calibrated with: 11x9 inner corners of 9 mm, double-sided (target file lab/board.yaml)"),
            std::string::npos)
      << recorded.out;
  EXPECT_NE(recorded.out.find("back_from_front as calibrated: 0.0050 mm, 0.0000 deg"), std::string::npos)
      << recorded.out;
}

// `stereorig <args>` with its stdout going to `stdout_to` (a shell
// redirection's target: "/dev/full", "&-"): its exit code and stderr.
Result RunWithStdout(const std::string& args, const std::string& stdout_to) {
  const std::string err = ::testing::TempDir() + "/cli_stdout_err_" + std::to_string(getpid()) + ".txt";
  const int status = std::system((stereorig::testing::kBin + " " + args + " >" + stdout_to + " 2>" + err).c_str());
  std::ifstream f(err);
  Result r{WIFEXITED(status) ? WEXITSTATUS(status) : -1, "", std::string(std::istreambuf_iterator<char>(f), {})};
  std::filesystem::remove(err);
  return r;
}

// Every command whose stdout cannot be written (a full disk, /dev/full, a
// closed descriptor) exits 2 with one line saying so: what it printed (a
// table, a verdict, the help) did not reach the caller. Only verify did
// before; the others, --help and --version exited 0.
TEST(Cli, AStdoutThatCannotBeWrittenIsNoSuccess) {
  const std::string rig = ::testing::TempDir() + "/stdout_rig.yaml";
  std::ofstream(rig) << GoodRigText();
  Result r = RunWithStdout("rig --rig " + rig, "/dev/full");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "stereorig rig: standard output: cannot be written: No space left on device\n");
  r = RunWithStdout("--help", "/dev/full");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "stereorig: standard output: cannot be written: No space left on device\n");
  r = RunWithStdout("reconstruct --help", "/dev/full");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("stereorig reconstruct: standard output: cannot be written", 0), 0u) << r.err;
  r = RunWithStdout("--version", "&-");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "stereorig: standard output: cannot be written: Bad file descriptor\n");
  // The demo stops before its first step, in one line (its steps would each
  // have failed on the lost stdout and run for minutes), its --out not left.
  const std::string demo_out = ::testing::TempDir() + "/stdout_demo_" + std::to_string(getpid());
  std::filesystem::remove_all(demo_out);
  r = RunWithStdout("demo --out " + demo_out, "/dev/full");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("stereorig demo: standard output: cannot be written: No space left on device; the demo stops "
                        "before `stereorig simulate",
                        0),
            0u)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(demo_out));
  // Its command lines are shell-quoted, to be pasted as they are: an --out
  // with a space was printed bare before, two arguments in a shell.
  const std::string spaced_out = ::testing::TempDir() + "/stdout demo " + std::to_string(getpid());
  r = RunWithStdout("demo --out '" + spaced_out + "'", "/dev/full");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "stereorig demo: standard output: cannot be written: No space left on device; the demo stops "
            "before `stereorig simulate --out '" +
                spaced_out + "/dataset' --seed 1`\n");
  EXPECT_FALSE(std::filesystem::exists(spaced_out));
  // Bad input keeps its own exit code and line.
  r = RunWithStdout("rig --rig " + rig + ".missing", "/dev/full");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.find("standard output"), std::string::npos) << r.err;
}

// An image `match` cannot read is named in one line: a missing file without
// OpenCV's own warning above it (imread of a missing file warns on stderr;
// reconstruct and score check that their files exist first, and now match
// does too), a file that is not an image as such.
TEST(Cli, UnreadableImagesAreNamedInOneLine) {
  const std::string dir = ::testing::TempDir() + "/cli_unreadable";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/junk.png") << "not a png";
  for (const char* name : {"missing.png", "junk.png"}) {
    const std::string path = dir + "/" + name;
    const Result r = RunCli("match --left " + path + " --right " + path +
                            " --min-disparity 0 --num-disparities 16 --out " + dir + "/d.pfm");
    EXPECT_EQ(r.code, 2) << name;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(path), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("WARN"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir + "/d.pfm"));
  }
}

// A fresh scratch folder holding l.png, a flat 64x32 grey image: a pair
// (left = right) for match's argument checks.
std::string MatchScratch(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "/" + name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  EXPECT_TRUE(cv::imwrite(dir + "/l.png", cv::Mat(32, 64, CV_8UC1, cv::Scalar(100))));
  return dir;
}

// --roi must lie inside the image and have a positive size: a region partly
// outside was clipped, and an empty one (or one wholly outside) matched the
// whole image, each with exit 0. Now exit 2, one line naming --roi, before
// any matching; a region inside is matched, and the summary counts over it.
TEST(Cli, MatchRefusesARegionNotInsideTheImage) {
  const std::string dir = MatchScratch("cli_match_roi");
  const std::string base =
      "match --left " + dir + "/l.png --right " + dir + "/l.png --min-disparity 0 --num-disparities 16 --out " + dir;
  // An empty or negative size is refused before the images are read (no
  // size to name yet), one outside the image after.
  const std::pair<std::string, std::string> cases[] = {
      {"40 10 30 10", "the 64x32 image"}, {"0 0 100000 100000", "the 64x32 image"},
      {"-1 0 64 32", "the 64x32 image"},  {"70 40 5 5", "the 64x32 image"},
      {"10 10 0 5", "the image"},         {"0 0 0 0", "the image"},
      {"10 10 -5 5", "the image"}};
  for (const auto& [roi, image] : cases) {
    const Result r = RunCli(base + "/d.pfm --roi " + roi);
    EXPECT_EQ(r.code, 2) << roi;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("--roi: " + roi + " must have a positive size and lie inside " + image), std::string::npos)
        << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir + "/d.pfm")) << roi;
  }
  const Result ok = RunCli(base + "/d.pfm --roi 0 0 64 32");
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.out.find(" of 2048 px in --roi ("), std::string::npos) << ok.out;
  const Result part = RunCli(base + "/p.pfm --roi 8 4 20 10");
  EXPECT_EQ(part.code, 0) << part.err;
  EXPECT_NE(part.out.find(" of 200 px in --roi ("), std::string::npos) << part.out;
}

// match's whole-number flags name themselves, their rule and the value
// given: a fraction or a number past an int said CLI11's bare "Could not
// convert: --min-disparity = 1.5". Refused before the images are read (the
// left one is missing here), nothing written; a zero-padded value is
// decimal and goes on to the images.
TEST(Cli, MatchNamesAWholeNumberFlagItsRuleAndTheValue) {
  const std::string dir = MatchScratch("cli_match_whole_numbers");
  const std::string base = "match --left " + dir + "/missing.png --right " + dir + "/l.png --out " + dir + "/d.pfm";
  const std::pair<std::string, std::string> refused[] = {
      {"--min-disparity 1.5 --num-disparities 16", "--min-disparity: must be a whole number in [-1024, 2048], got 1.5"},
      {"--min-disparity 0 --num-disparities 99999999999", "--num-disparities: must be in [2, 1024], got 99999999999"},
      {"--min-disparity -99999999999999999999 --num-disparities 16",
       "--min-disparity: must be in [-1024, 2048], got -99999999999999999999"},
      {"--min-disparity 0 --num-disparities 2000", "--num-disparities: must be in [2, 1024], got 2000"},
      {"--min-disparity 0 --num-disparities 16 --threads x", "--threads: must be a whole number in [1, 64], got x"},
      {"--min-disparity 0 --num-disparities 16 --pyramid-levels 0.5",
       "--pyramid-levels: must be a whole number in [0, 3], got 0.5"},
      {"--min-disparity 0 --num-disparities 16 --roi 0 0 32 1e3", "--roi: must be a whole number, got 1e3"},
      {"--min-disparity 0 --num-disparities 16 --roi 0 0 32 4294967312",
       "--roi: must be at most 2147483647, got 4294967312"}};
  for (const auto& [args, says] : refused) {
    const Result r = RunCli(base + " " + args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("stereorig match: " + says), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir + "/d.pfm")) << args;
  }
  const Result padded = RunCli(base + " --min-disparity -010 --num-disparities 016");
  EXPECT_EQ(padded.code, 2);
  EXPECT_NE(padded.err.find(dir + "/missing.png"), std::string::npos) << padded.err;
}

// The disparity map is always PFM: `--out d.png` would hold PFM bytes an
// image viewer cannot open. (Before, it was written there and match exited
// 0.) Refused before the matching, in one line naming the path.
TEST(Cli, MatchRefusesADisparityMapNotNamedPfm) {
  const std::string dir = MatchScratch("cli_match_out");
  const cv::Size grey(64, 32);  // MatchScratch's image
  for (const char* name : {"/d.png", "/d.tiff"}) {
    const Result r = RunCli("match --left " + dir + "/l.png --right " + dir +
                            "/l.png --min-disparity 0 --num-disparities 16 --out " + dir + name);
    EXPECT_EQ(r.code, 2) << name;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(dir + name + ": disparity output must end in .pfm"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir + name)) << name;
  }
  const Result ok = RunCli("match --left " + dir + "/l.png --right " + dir +
                           "/l.png --min-disparity 0 --num-disparities 16 --out " + dir + "/d.pfm");
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_TRUE(std::filesystem::exists(dir + "/d.pfm"));
  // The suffix in any case ("D.PFM", as users type it) is PFM too.
  const Result upper = RunCli("match --left " + dir + "/l.png --right " + dir +
                              "/l.png --min-disparity 0 --num-disparities 16 --out " + dir + "/D.PFM");
  EXPECT_EQ(upper.code, 0) << upper.err;
  const cv::Mat by_opencv = cv::imread(dir + "/D.PFM", cv::IMREAD_UNCHANGED);  // OpenCV's own PFM reader
  EXPECT_EQ(by_opencv.type(), CV_32FC1);
  EXPECT_EQ(by_opencv.size(), grey);
}

// `rig --truth`: judged against itself every figure is 0; with module 1
// moved 0.1 mm in module 0's frame (S changed, each module untouched), the
// module 3D errors stay 0 and the agreement through S is exactly the 0.1 mm
// shift (every point module 1 triangulates lands 0.1 mm off): an analytic
// expectation, printed to 4 decimals.
TEST(Cli, RigAgainstTruthGivesZeroForItselfAndTheShiftOfAMovedModule) {
  const std::string truth_path = ::testing::TempDir() + "/truth_rig.yaml";
  const std::string moved_path = ::testing::TempDir() + "/moved_rig.yaml";
  const stereorig::SimulatedRig sim = stereorig::MakeDefaultRig();
  std::ofstream(truth_path) << GoodRigText();
  const stereorig::Rig& t = sim.rig;
  const stereorig::Pose module0_from_module1(t.S(0, 1).rotation(),
                                             t.S(0, 1).translation_mm() + Eigen::Vector3d(0.1, 0, 0));
  const stereorig::Rig moved(t.cameras(), t.camera_names(), t.modules(), {stereorig::Pose(), module0_from_module1});
  stereorig::WriteRigFile(moved, moved_path);

  Result r = RunCli("rig --rig " + truth_path + " --truth " + truth_path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("module 0: 3D error after rigid alignment 0.0000 mm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("module 1: 3D error after rigid alignment 0.0000 mm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("agreement through S 0.0000 mm"), std::string::npos) << r.out;

  r = RunCli("rig --rig " + moved_path + " --truth " + truth_path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("module 1: 3D error after rigid alignment 0.0000 mm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("agreement through S 0.1000 mm"), std::string::npos) << r.out;

  r = RunCli("rig --rig " + moved_path + " --truth " + truth_path + " --volume 75 75 0");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;

  // At its working distance (the default 200 mm) every point of the volume
  // is seen by both cameras of each module; 100 mm ahead, module 0's two
  // views overlap on a sliver of it (36 of 847 points, measured), and the
  // judgement says it is taken partly outside where the rig measures.
  r = RunCli("rig --rig " + truth_path + " --truth " + truth_path);
  EXPECT_EQ(r.out.find("see only"), std::string::npos) << r.out;
  r = RunCli("rig --rig " + truth_path + " --truth " + truth_path + " --distance 100");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("(module 0's two cameras see only 36 of the 847 points of the 75 x 75 x 50 mm volume centred "
                       "100 mm ahead of module 0: are --distance and --volume where this rig measures?)"),
            std::string::npos)
      << r.out;
  // Two thirds seen (170 mm ahead) is said too: a ring's side modules judged
  // 200 mm ahead of module 0 saw 561 and 594 and read a 3D error half again
  // their own volume's; only under half was. The count said is the test's
  // own: the 11 x 11 x 7 grid over the 75 x 75 x 50 mm box centred 170 mm
  // along module 0's mean axis from its baseline's midpoint, each point
  // projected by the OpenCV rational model written out here (the truth's
  // lenses are OPENCV8) and kept where both of module 0's cameras see it
  // inside the imager (pixel centres 0 .. size - 1, mrcal's convention).
  r = RunCli("rig --rig " + truth_path + " --truth " + truth_path + " --distance 170");
  ASSERT_EQ(r.code, 0) << r.err;
  const stereorig::StereoModule& module0 = t.module(0);
  auto seen = [](const stereorig::Camera& c, const Eigen::Vector3d& p) {
    if (p.z() <= 0) return false;
    EXPECT_EQ(c.lensmodel_name(), "LENSMODEL_OPENCV8");
    const std::vector<double>& k = c.intrinsics();  // fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6
    const double x = p.x() / p.z(), y = p.y() / p.z(), r2 = x * x + y * y;
    const double radial = (1 + r2 * (k[4] + r2 * (k[5] + r2 * k[8]))) / (1 + r2 * (k[9] + r2 * (k[10] + r2 * k[11])));
    const double u = k[0] * (x * radial + 2 * k[6] * x * y + k[7] * (r2 + 2 * x * x)) + k[2];
    const double v = k[1] * (y * radial + k[6] * (r2 + 2 * y * y) + 2 * k[7] * x * y) + k[3];
    return u >= 0 && v >= 0 && u <= c.imager_width_px() - 1 && v <= c.imager_height_px() - 1;
  };
  const stereorig::Pose left_from_right = module0.right_from_left.Inverse();
  const Eigen::Vector3d centre = 0.5 * left_from_right.translation_mm() +
                                 170 * (Eigen::Vector3d::UnitZ() + left_from_right.rotation().col(2)).normalized();
  int both = 0;
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j)
      for (int k = 0; k <= 6; ++k) {
        const Eigen::Vector3d p =
            centre + Eigen::Vector3d(75 * (i / 10.0 - 0.5), 75 * (j / 10.0 - 0.5), 50 * (k / 6.0 - 0.5));
        both +=
            seen(t.camera(module0.left_camera), p) && seen(t.camera(module0.right_camera), module0.right_from_left * p);
      }
  ASSERT_LT(5 * both, 4 * 847) << both << " seen: not under four fifths";
  EXPECT_NE(r.out.find("(module 0's two cameras see only " + std::to_string(both) + " of the 847 points"),
            std::string::npos)
      << both << " seen by the test's projection\n"
      << r.out;
  EXPECT_EQ(r.out.find("module 1's two cameras see only"), std::string::npos) << r.out;
}

// `rig` reads --truth and makes the models' folder before it prints: a
// --truth that is no rig file (a layout file), or a folder that cannot be
// made, printed the whole summary to stdout, then exited 2.
TEST(Cli, RigPrintsNothingWhenAnInputOrTheModelsFolderFails) {
  const std::string dir = ::testing::TempDir() + "/cli_rig_late_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/rig.yaml") << GoodRigText();
  std::ofstream(dir + "/layout.yaml") << "modules:\n  - {name: module0, left: 0, right: 1}\n";
  Result r = RunCli("rig --rig " + dir + "/rig.yaml --truth " + dir + "/layout.yaml");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(dir + "/layout.yaml"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  r = RunCli("rig --rig " + dir + "/rig.yaml --export-cameramodels " + stereorig::testing::UnwritablePath("models"));
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_EQ(r.out, "");
  std::filesystem::remove_all(dir);
}

// The options that only shape the --truth judgement are refused without it
// (they were ignored, exit 0), and the help says so.
TEST(Cli, RigRefusesTruthOnlyOptionsWithoutTruth) {
  const std::string rig = ::testing::TempDir() + "/truth_only_rig.yaml";
  std::ofstream(rig) << GoodRigText();
  for (const char* option : {"--distance 500", "--volume 10 10 10"}) {
    const Result r = RunCli("rig --rig " + rig + " " + std::string(option));
    EXPECT_EQ(r.code, 2) << option;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("--truth"), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "") << option;
  }
  const Result help = RunCli("rig --help");
  EXPECT_EQ(help.code, 0);
  int needs = 0;  // one per truth-only option
  for (size_t at = help.out.find("Needs: --truth"); at != std::string::npos;
       at = help.out.find("Needs: --truth", at + 1))
    ++needs;
  EXPECT_EQ(needs, 2) << help.out;
}

// Every malformed case of the rig-file contract: exit 2, one line on stderr
// naming the file and the offending key.
TEST(Cli, EveryMalformedRigFileExitsTwoNamingTheKey) {
  const std::string good = GoodRigText();
  struct Case {
    const char* name;
    std::string text;
    const char* expect_in_message;
  };
  const std::string cam0_intr = "intrinsics: [";
  const std::vector<Case> cases = {
      {"unknown key", Replace(good, "units: mm\n", "units: mm\ncolour: blue\n"), "colour: unknown key"},
      {"unknown nested key", Replace(good, "    left: 0\n", "    left: 0\n    lefty: 1\n"), "lefty: unknown key"},
      {"missing key", Replace(good, "units: mm\n", ""), "units: missing key"},
      // named by what it is missing as: a typo of a key was reported as the key missing alone
      {"misspelt key", Replace(good, "    right_from_left: ", "    right_from_lef: "),
       "modules[0].right_from_left: missing key (this map has right_from_lef instead: a typo?)"},
      {"missing camera key", Replace(good, "    imagersize: [752, 582]\n", "\n"), "imagersize: missing key"},
      {"wrong type", Replace(good, "    left: 0\n", "    left: zero\n"), "left: expected an integer"},
      {"NaN", Replace(good, cam0_intr, cam0_intr + std::string(".nan, ")), "NaN or Inf"},
      {"Inf", Replace(good, "[[1, 0, 0, 0]", "[[1, 0, 0, .inf]"), "NaN or Inf"},
      {"non-orthonormal rotation", Replace(good, "[[1, 0, 0, 0]", "[[1.01, 0, 0, 0]"), "orthonormal"},
      {"unknown lens model", Replace(good, "LENSMODEL_OPENCV8", "LENSMODEL_FISHEYE9"), "unknown lens model"},
      {"wrong number of intrinsics", Replace(good, cam0_intr, cam0_intr + std::string("1.5, ")), "takes 12 intrinsics"},
      {"inconsistent S",
       Replace(good, "[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]  # module1_from_module1",
               "[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 2.5], [0, 0, 0, 1]]  # module1_from_module1"),
       "S[1][1] is not the identity"},
      {"not YAML", "format: [unclosed\n", "not valid YAML"},
      {"wrong version", Replace(good, "version: 2", "version: 99"), "unsupported version 99"},
  };
  for (const Case& c : cases) {
    const std::string path = ::testing::TempDir() + "/bad_rig.yaml";
    std::ofstream(path) << c.text;
    const Result r = RunCli("rig --rig " + path);
    EXPECT_EQ(r.code, 2) << c.name;
    EXPECT_EQ(Lines(r.err), 1) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(path), std::string::npos) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.expect_in_message), std::string::npos) << c.name << ": " << r.err;
  }
  const Result missing = RunCli("rig --rig /nonexistent/rig.yaml");
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("no such file"), std::string::npos);
}

// A module's translation typed in metres (a 90 mm baseline as 0.09) was
// read: exit 0, "baseline 0.0900 mm". Refused like a square size in metres.
TEST(Cli, RigRefusesABaselineTypedInMetres) {
  stereorig::SimulatedRig sim = stereorig::MakeDefaultRig();
  std::vector<stereorig::StereoModule> modules = sim.rig.modules();
  modules[0].right_from_left = stereorig::Pose(modules[0].right_from_left.rotation(), Eigen::Vector3d(-0.09, 0, 0));
  const stereorig::Rig metres(sim.rig.cameras(), sim.rig.camera_names(), modules, sim.rig.S(), "test");
  const std::string path = ::testing::TempDir() + "/rig_metres.yaml";
  std::ofstream(path) << stereorig::RigToYaml(metres);
  const Result r = RunCli("rig --rig " + path);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "stereorig rig: " + path +
                       ": modules[0].right_from_left: baseline 0.09 mm, under the 1 mm two cameras' centres stand "
                       "apart at the least; is it in metres? the unit is mm\n");
  EXPECT_EQ(r.out, "");
}

TEST(Cli, AnInconsistentOffDiagonalSIsRejected) {
  // Shift S[0][1]'s translation by 1 mm while S[1][0] stays: S_10 != S_01^-1.
  const std::string good = GoodRigText();
  const size_t s_at = good.find("\nS:\n");
  ASSERT_NE(s_at, std::string::npos);
  const size_t row = good.find("# module0_from_module1", s_at);
  ASSERT_NE(row, std::string::npos);
  const size_t line_start = good.rfind("\n", row) + 1;
  std::string line = good.substr(line_start, row - line_start);
  const size_t first_t = line.find("], [");  // end of the first row of the 4x4
  const size_t comma = line.rfind(", ", first_t);
  line.replace(comma + 2, first_t - comma - 2, "123.456");
  std::string bad = good;
  bad.replace(line_start, row - line_start, line);
  const std::string path = ::testing::TempDir() + "/bad_s.yaml";
  std::ofstream(path) << bad;
  const Result r = RunCli("rig --rig " + path);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1);
  EXPECT_NE(r.err.find("is not the inverse of"), std::string::npos) << r.err;
}

TEST(Cli, EverySubcommandsHelpTeachesWithAnExample) {
  for (const char* c : {"simulate", "target", "calibrate", "reconstruct", "match", "verify", "check", "bench", "score",
                        "tune", "rig", "demo"}) {
    const Result r = RunCli(std::string(c) + " --help");
    EXPECT_EQ(r.code, 0) << c;
    EXPECT_NE(r.out.find("xample"), std::string::npos) << c << " --help has no example";
    EXPECT_NE(r.out.find("--"), std::string::npos) << c << " --help lists no options";
  }
}

// The match command `reconstruct --rectified-out` prints searches the range
// and ROI the measurement volume gives, which the runtime narrows per capture
// (the demo cup's module 0: ROI [148, 8, 428, 535] and d [35, 120) searched
// of the printed 0 0 752 582 and [-100, 174)); match's help said it held
// "the disparity range and ROI the runtime searches".
TEST(Cli, MatchsHelpSaysThePrintedRangeIsTheVolumesBeforeTheRuntimeNarrowsIt) {
  const Result match = RunCli("match --help");
  EXPECT_EQ(match.out.find("the runtime searches in it"), std::string::npos) << match.out;
  EXPECT_NE(match.out.find("the runtime derives for it from the measurement volume (before its per-capture "
                           "lit-region crop and band pass, which search less)"),
            std::string::npos)
      << match.out;
  EXPECT_NE(RunCli("reconstruct --help")
                .out.find("derives from the measurement volume (before its lit-region crop "
                          "and band pass)"),
            std::string::npos);
}

// The commands whose exit 1 means something other than bad input say what
// in their help, 2 included: demo's said only when it exits 0 (and left out
// the score step it runs), though it exits 1 on a step that misbehaves and
// 2 on bad usage (docs/formats.md, "CLI").
TEST(Cli, TheHelpOfEveryCommandThatExitsOneSaysWhen) {
  for (const auto& [command, one] : {std::pair{"verify", "1 a figure of a judged position fails"},
                                     std::pair{"check", "1 recalibrate"}, std::pair{"demo", "1 a step did not"}}) {
    const Result r = RunCli(std::string(command) + " --help");
    EXPECT_NE(r.out.find(one), std::string::npos) << command << ": " << r.out;
    EXPECT_NE(r.out.find("2 bad"), std::string::npos) << command << ": " << r.out;
  }
  EXPECT_NE(RunCli("demo --help").out.find("score it against the simulator's truth"), std::string::npos);
  // The top-level help's exit codes say demo's 1 too (they named only verify
  // and check).
  const Result top = RunCli("--help");
  EXPECT_NE(top.out.find("1 a check that ran and failed (verify, check), or a demo step that did not exit as expected"),
            std::string::npos)
      << top.out;
}

// Every command's help gives its exit codes in the top-level help's words:
// only check, verify and demo said theirs, and reconstruct's batch, which
// exits 2 with the other captures' outputs written, said it nowhere a user
// would look. Those that never exit 1 say 0 and 2 only.
TEST(Cli, EveryCommandsHelpGivesItsExitCodes) {
  for (const auto& [command, codes] :
       {std::pair{"calibrate",
                  "Exit codes: 0 ok (the rig file written); 2 bad usage or input, or a calibration "
                  "refused as above."},
        std::pair{"reconstruct",
                  "Exit codes: 0 ok (a module that gave no point or whose rows read off too: warned of on "
                  "stderr); 2 bad usage "
                  "or input, or a capture of a batch or stream that failed (it has no output; the "
                  "others' outputs are written)."},
        std::pair{"score", "Exit codes: 0 ok (score judges nothing: no figure fails); 2 bad usage or input."},
        std::pair{"bench", "Exit codes: 0 ok; 2 bad usage or input."},
        std::pair{"tune",
                  "Exit codes: 0 ok (its warnings too); 2 bad usage or input (a capture that shows no grid "
                  "period included)."},
        std::pair{"match", "Exit codes: 0 ok (with a range warning too); 2 bad usage or input."},
        std::pair{"rig",
                  "Exit codes: 0 ok (the rig file valid; --truth's figures judge nothing); 2 bad usage or "
                  "input (an invalid rig file included)."},
        std::pair{"target", "Exit codes: 0 ok; 2 bad usage or input."},
        std::pair{"check", "Exit codes: 0 ok; 1 recalibrate or recapture; 2 bad usage or input."},
        std::pair{"simulate",
                  "Exit codes: 0 ok (its warnings too); 2 bad usage or input (a folder it refuses to replace "
                  "included)."}}) {
    const Result r = RunCli(std::string(command) + " --help");
    EXPECT_NE(r.out.find(std::string("\n") + codes + "\n"), std::string::npos) << command << ": " << r.out;
  }
  // And every command the top-level help lists (verify's and demo's own
  // wording aside): simulate's had none while this test's list lacked it.
  const std::string top = RunCli("--help").out;
  for (const char* command : {"simulate", "target", "calibrate", "reconstruct", "match", "verify", "check", "bench",
                              "score", "tune", "rig", "demo"}) {
    ASSERT_NE(top.find(std::string("\n  ") + command + " "), std::string::npos) << command;
    EXPECT_NE(RunCli(std::string(command) + " --help").out.find("\nExit codes: "), std::string::npos) << command;
  }
}

// check's --rig, --captures and --target are required unless --history, as
// its refusal says ("--rig, --captures and --target are required"); its
// help showed them as optional.
TEST(Cli, ChecksHelpSaysWhichOptionsAreRequired) {
  const Result r = RunCli("check --help");
  EXPECT_NE(r.out.find("the stored rig file (from stereorig calibrate); required, but with --history only where the "
                       "history is looked for by default (give it or --history-db)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("whose calibration/ folder is used); required unless --history"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("another board is refused); required unless --history"), std::string::npos) << r.out;
  const Result refused = RunCli("check --rig r.yaml");
  EXPECT_EQ(refused.code, 2);
  EXPECT_NE(refused.err.find("--rig, --captures and --target are required"), std::string::npos) << refused.err;
}

// Each (command, option) given '' exits 2 with one line naming the option
// and `why`, before any work (nothing on stdout).
template <size_t N>
void ExpectEachEmptyRefused(const std::pair<const char*, const char*> (&options)[N], const std::string& why) {
  for (const auto& [command, option] : options) {
    const Result r = RunCli(std::string(command) + " " + option + " ''");
    EXPECT_EQ(r.code, 2) << command << " " << option;
    EXPECT_EQ(r.err, std::string("stereorig ") + command + ": " + option + ": " + why + " (see --help)\n");
    EXPECT_EQ(r.out, "") << command << " " << option;
  }
}

// Every file or folder a command writes, given as an empty path (a shell
// variable left unset): refused by the option's name, exit 2, before any
// work. Before, `verify --report ""` wrote nothing and exited 0, and other
// commands read "" as not given or as a file of no name.
TEST(Cli, AnEmptyOutputPathIsRefusedByItsOptionsName) {
  const std::pair<const char*, const char*> options[] = {{"verify", "--report"},
                                                         {"check", "--report"},
                                                         {"bench", "--report"},
                                                         {"score", "--report"},
                                                         {"score", "--diagnose"},
                                                         {"reconstruct", "--out"},
                                                         {"reconstruct", "--mesh"},
                                                         {"reconstruct", "--report"},
                                                         {"reconstruct", "--out-dir"},
                                                         {"reconstruct", "--rectified-out"},
                                                         {"check", "--history-db"},
                                                         {"calibrate", "--out"},
                                                         {"calibrate", "--report"},
                                                         {"calibrate", "--export-cameramodels"},
                                                         {"rig", "--export-cameramodels"},
                                                         {"tune", "--out"},
                                                         {"demo", "--out"},
                                                         {"simulate", "--out"},
                                                         {"target", "--out"},
                                                         {"match", "--out"}};
  ExpectEachEmptyRefused(options, "an empty path");
}

// Every other option that takes a value refuses an empty one too, by name,
// before any work and with nothing on stdout: an input path given as ''
// read as not given and the run went on with exit 0 (target drew the
// built-in board, score scored the truth rig, reconstruct and tune ran on
// the built-in options, rig skipped --truth, bench benched the built-in
// sphere, a stream's --capture-root named captures by their last folder).
TEST(Cli, AnEmptyValueIsRefusedByItsOptionsName) {
  const std::pair<const char*, const char*> options[] = {{"target", "--target"},
                                                         {"check", "--rig"},
                                                         {"rig", "--rig"},
                                                         {"rig", "--truth"},
                                                         {"score", "--dataset"},
                                                         {"score", "--rig"},
                                                         {"score", "--options"},
                                                         {"tune", "--options"},
                                                         {"tune", "--capture"},
                                                         {"reconstruct", "--rig"},
                                                         {"reconstruct", "--capture"},
                                                         {"reconstruct", "--options"},
                                                         {"reconstruct", "--warm-up"},
                                                         {"reconstruct", "--capture-root"},
                                                         {"bench", "--dataset"},
                                                         {"bench", "--rig"},
                                                         {"match", "--left"},
                                                         {"check", "--target"},
                                                         {"check", "--captures"},
                                                         {"calibrate", "--captures"},
                                                         {"calibrate", "--lensmodel"},
                                                         {"simulate", "--spec"},
                                                         {"demo", "--seed"}};
  ExpectEachEmptyRefused(options, "an empty value");
}

// demo's --out is made before any step: under a file it is refused naming
// the file, and one that cannot be made (a name longer than the file
// system's 255 characters) leaves no folder above it (it used to leave
// those made on the way, empty). Exit 2, one line, no step run.
TEST(Cli, DemoOutThatCannotBeMadeLeavesNoFolder) {
  namespace fs = std::filesystem;
  const std::string dir = ::testing::TempDir() + "/cli_demo_out";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir + "/a_file") << "not a folder\n";
  const std::pair<std::string, std::string> cases[] = {
      {dir + "/a_file/demo", "/a_file is a file, not a folder for everything the demo writes (--out)"},
      {dir + "/new/" + std::string(300, 'x'), "File name too long"}};
  for (const auto& [out, says] : cases) {
    const Result r = RunCli("demo --out " + out);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("$ stereorig"), std::string::npos) << "a step ran: " << r.out;
  }
  EXPECT_FALSE(fs::exists(dir + "/new")) << "the folder made on the way was left behind";
}

TEST(Cli, RigExportWritesCameramodelsThatRoundTrip) {
  const std::string dir = ::testing::TempDir() + "/cli_export";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/rig.yaml";
  std::ofstream(path) << GoodRigText();
  const Result r = RunCli("rig --rig " + path + " --export-cameramodels " + dir);
  EXPECT_EQ(r.code, 0) << r.err;
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(std::filesystem::exists(dir + "/cam" + std::to_string(i) + ".cameramodel"));
  EXPECT_EQ(r.err, "");
}

// Models of another rig in the folder (a 3-module rig's cam4 and cam5, the
// folder exported into before) stayed beside this rig's fresh ones without
// a word: a folder of two rigs' models. Warned of on stderr, naming them;
// left as they are (the user's files).
TEST(Cli, RigExportWarnsOfOtherModelsInItsFolder) {
  const std::string dir = ::testing::TempDir() + "/cli_export_others_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir + "/models");
  std::ofstream(dir + "/rig.yaml") << GoodRigText();
  for (const char* name : {"cam5.cameramodel", "cam4.cameramodel", "notes.txt"})
    std::ofstream(dir + "/models/" + name) << "another rig's\n";
  const Result r = RunCli("rig --rig " + dir + "/rig.yaml --export-cameramodels " + dir + "/models");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "rig: warning: " + dir +
                       "/models also holds cam4.cameramodel, cam5.cameramodel, not written by this run: another "
                       "rig's models? (remove them, or export into a folder of its own)\n");
  EXPECT_TRUE(std::filesystem::exists(dir + "/models/cam4.cameramodel"));
  std::filesystem::remove_all(dir);
}

// `rig --export-cameramodels` checks its folder (created if needed) before
// it reads the rig file (apps/output_paths.h): the rig file's path, or a
// path under it, is refused, as is a folder in which a model would replace
// the rig or truth file (a rig file named cam0.cameramodel). Exit 2, one
// line naming the path, nothing printed, the input byte-identical.
TEST(Cli, RigExportRefusesAFolderOverItsInputsBeforeAnyWork) {
  namespace fs = std::filesystem;
  const std::string dir = ::testing::TempDir() + "/cli_export_inputs";
  fs::remove_all(dir);
  fs::create_directories(dir + "/models");
  const std::string rig = dir + "/rig.yaml", truth = dir + "/truth.yaml", named = dir + "/models/cam0.cameramodel";
  for (const std::string& path : {rig, truth, named}) std::ofstream(path) << GoodRigText();
  const std::string text = GoodRigText();
  auto bytes = [](const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
  };
  const std::pair<std::string, std::string> cases[] = {
      {"--rig " + rig + " --export-cameramodels " + rig, rig + ": is the rig file (--rig), not a folder"},
      {"--rig " + rig + " --export-cameramodels " + rig + "/models", "/rig.yaml is a file, not a folder"},
      {"--rig " + rig + " --truth " + truth + " --export-cameramodels " + truth,
       truth + ": is the true rig file (--truth), not a folder"},
      {"--rig " + named + " --export-cameramodels " + dir + "/models", named + ": is the rig file (--rig)"}};
  for (const auto& [args, says] : cases) {
    const Result r = RunCli("rig " + args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "") << args;  // refused before the rig was summarised
  }
  for (const std::string& path : {rig, truth, named}) EXPECT_EQ(bytes(path), text) << path;
  EXPECT_EQ(std::distance(fs::directory_iterator(dir + "/models"), fs::directory_iterator()), 1);
  // A folder that is not there yet is created, as calibrate's is.
  const Result r = RunCli("rig --rig " + rig + " --export-cameramodels " + dir + "/new/models");
  EXPECT_EQ(r.code, 0) << r.err;
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(fs::exists(dir + "/new/models/cam" + std::to_string(i) + ".cameramodel"));
  // A camera name is its model's file name: one that is not a plain name
  // ("../cam1": outside the folder) is refused before any model is written.
  std::string escaping = text;
  const size_t at = escaping.find("name: \"cam1\"");
  ASSERT_NE(at, std::string::npos);
  escaping.replace(at, 12, "name: \"../cam1\"");
  std::ofstream(dir + "/escaping.yaml") << escaping;
  const Result e = RunCli("rig --rig " + dir + "/escaping.yaml --export-cameramodels " + dir + "/esc/models");
  EXPECT_EQ(e.code, 2) << e.err;
  EXPECT_NE(e.err.find("camera 1's name \"../cam1\" is not a plain file name"), std::string::npos) << e.err;
  EXPECT_FALSE(fs::exists(dir + "/esc/models/cam0.cameramodel"));
  EXPECT_FALSE(fs::exists(dir + "/esc/cam1.cameramodel"));
  EXPECT_FALSE(fs::exists(dir + "/esc"));
}

// A models' folder that cannot be made (a name longer than the file
// system's 255 characters) exits 2 in one line naming it, and leaves no
// folder above it (refused when claimed, OutputPaths::ClaimFolder; a folder
// made on the way used to stay, empty).
TEST(Cli, RigExportToAFolderThatCannotBeMadeLeavesNoFolder) {
  namespace fs = std::filesystem;
  const std::string dir = ::testing::TempDir() + "/cli_export_long";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir + "/rig.yaml") << GoodRigText();
  const std::string folder = dir + "/new/" + std::string(300, 'x');
  const Result r = RunCli("rig --rig " + dir + "/rig.yaml --export-cameramodels " + folder);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(folder + ": cannot create this folder"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/new")) << "the folder made on the way was left behind";
}

// --- Robustness walkthrough 44 (fuzz-bounds): rig files and rig's options ---

// A rig file's camera with the first camera's model and `num_intrinsics`
// intrinsics (fx, fy, cx, cy of the default's camera 0, then zeros).
std::string RigWithCamera0Model(const std::string& lensmodel, size_t num_intrinsics) {
  std::string text = Replace(GoodRigText(), "lensmodel: \"LENSMODEL_OPENCV8\"", "lensmodel: \"" + lensmodel + "\"");
  const size_t from = text.find("intrinsics: [");
  const size_t to = text.find("]", from);
  std::string values;
  const char* core[] = {"1025", "1025", "375.5", "290.5"};
  for (size_t k = 0; k < num_intrinsics; ++k) values += (k ? ", " : "") + std::string(k < 4 ? core[k] : "0");
  return text.replace(from, to - from, "intrinsics: [" + values);
}

// A splined model mrcal cannot build was judged by its intrinsics' count
// alone, an int that wraps: Nx=1 or an order of 1 or 5 aborted in mrcal
// (SIGABRT, exit 134) in `rig` and `reconstruct`; 65536 x 65536 knots read
// as 0 x 0 and counted 4 intrinsics; Nx=-4 "takes -1048540 intrinsics";
// fov_x_deg=0 was accepted and reconstructed no point. Refused as
// `calibrate --lensmodel` refuses them (calib/core/lensmodel_config.h),
// naming the file and cameras[0].lensmodel.
TEST(Cli, ARigFilesSplinedModelMrcalCannotBuildIsRefused) {
  const std::string dir = ::testing::TempDir() + "/cli_rig_spline_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string spline = "LENSMODEL_SPLINED_STEREOGRAPHIC_";
  struct Case {
    std::string config;
    size_t num_intrinsics;
    std::string says;
  };
  const std::string wrapped = ": order, Nx, Ny and fov_x_deg are whole numbers from 0 to 65535, written plainly";
  const Case cases[] = {
      {"order=3_Nx=1_Ny=1_fov_x_deg=100", 6, "Nx=1 Ny=1: an order 3 spline needs Nx and Ny >= 4 (mrcal's minimum)"},
      {"order=5_Nx=4_Ny=4_fov_x_deg=100", 36, "order=5: mrcal's splines are of order 2 or 3"},
      {"order=1_Nx=4_Ny=4_fov_x_deg=100", 36, "order=1: mrcal's splines are of order 2 or 3"},
      {"order=3_Nx=65536_Ny=65536_fov_x_deg=100", 4,
       "mrcal reads it as '" + spline + "order=3_Nx=0_Ny=0_fov_x_deg=100'" + wrapped},
      {"order=3_Nx=-4_Ny=-4_fov_x_deg=100", 36,
       "mrcal reads it as '" + spline + "order=3_Nx=65532_Ny=65532_fov_x_deg=100'" + wrapped},
      {"order=3_Nx=65535_Ny=65535_fov_x_deg=100", 4,
       "Nx=65535 Ny=65535: 8589672454 intrinsics, more than mrcal counts (2147483647)"},
      // mrcal's int count of this one wraps to 65538 (4 + 2 x 2147450415
      // mod 2^32): a rig file giving 65538 intrinsics passes a count.
      {"order=3_Nx=65535_Ny=32769_fov_x_deg=100", 65538,
       "Nx=65535 Ny=32769: 4295032834 intrinsics, more than mrcal counts (2147483647)"},
      {"order=3_Nx=4_Ny=4_fov_x_deg=0", 36,
       "fov_x_deg=0: must be in (0, 360), the horizontal field of view the stereographic projection can span, deg"}};
  for (const Case& c : cases) {
    const std::string path = dir + "/rig.yaml";
    std::ofstream(path) << RigWithCamera0Model(spline + c.config, c.num_intrinsics);
    const Result r = RunCli("rig --rig " + path);
    EXPECT_EQ(r.code, 2) << c.config << ": " << r.err;
    EXPECT_EQ(r.err, "stereorig rig: " + path + ": cameras[0].lensmodel: '" + spline + c.config + "': " + c.says + "\n")
        << c.config;
    EXPECT_EQ(r.out, "") << c.config;
  }
  // A good splined model is read (its zero spline is a plausible lens).
  std::ofstream(dir + "/good.yaml") << RigWithCamera0Model(spline + "order=3_Nx=4_Ny=4_fov_x_deg=100", 36);
  const Result good = RunCli("rig --rig " + dir + "/good.yaml");
  EXPECT_EQ(good.code, 0) << good.err;
  std::filesystem::remove_all(dir);
}

// Two modules of one name were read (a calibrate run with such a layout
// wrote them so): every report names modules by it. Refused as the layout
// file refuses it.
TEST(Cli, ARigFileWithTwoModulesOfOneNameIsRefused) {
  const std::string path = ::testing::TempDir() + "/rig_dup_module_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(path) << Replace(GoodRigText(), "name: \"module1\"", "name: \"module0\"");
  const Result r = RunCli("rig --rig " + path);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(r.err, "stereorig rig: " + path +
                       ": modules[1].name: module0 is used twice (modules[0] too): each module needs a name of its "
                       "own\n");
  EXPECT_EQ(r.out, "");
  std::filesystem::remove(path);
}

// Two cameras of one name were read, exit 0 (two modules of one name were
// refused): the check names the camera that moved by it. Refused alike.
// So is a negative residual or uncertainty: an RMS and a standard
// deviation are >= 0, and the check squares them into its thresholds (-1
// px read as 1 px, a threshold no night could fail).
TEST(Cli, ARigFileWithTwoCamerasOfOneNameOrANegativeUncertaintyIsRefused) {
  const std::string path = ::testing::TempDir() + "/rig_dup_camera_" + std::to_string(getpid()) + ".yaml";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {Replace(GoodRigText(), "name: \"cam2\"", "name: \"cam1\""),
       "cameras[2].name: cam1 is used twice (cameras[1] too): each camera needs a name of its own"},
      {Replace(GoodRigText(), "uncertainties: {}", "uncertainties: {cam0_projection_center_px: -1}"),
       "provenance.uncertainties.cam0_projection_center_px: must be >= 0, got -1"},
      {Replace(GoodRigText(), "residuals: {}", "residuals: {cam0_rms_px: -0.02}"),
       "provenance.residuals.cam0_rms_px: must be >= 0, got -0.02"}};
  for (const auto& [text, says] : cases) {
    std::ofstream(path) << text;
    const Result r = RunCli("rig --rig " + path);
    EXPECT_EQ(r.code, 2) << says;
    EXPECT_EQ(r.err, "stereorig rig: " + path + ": " + says + "\n");
    EXPECT_EQ(r.out, "");
  }
  std::filesystem::remove(path);
}

// --volume and --distance had no upper bound: 1e308 printed "3D error
// after rigid alignment inf mm", exit 0. At most 100 000 mm (100 m) each.
TEST(Cli, RigRefusesATruthVolumeBeyondAHundredMetres) {
  const std::string rig = ::testing::TempDir() + "/rig_volume_bound_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(rig) << GoodRigText();
  const std::string range = "must be > 0 mm and at most 100000 mm (100 m, beyond any volume a stereo module measures)";
  const std::pair<std::string, std::string> refused[] = {
      {"--volume 1e308 1e308 1e308", "--volume: 1e+308: each size " + range},
      {"--volume 75 75 100001", "--volume: 100001: each size " + range},
      {"--distance 1e308", "--distance: 1e+308: " + range},
      {"--distance 100001", "--distance: 100001: " + range}};
  for (const auto& [options, says] : refused) {
    const Result r = RunCli("rig --rig " + rig + " --truth " + rig + " " + options);
    EXPECT_EQ(r.code, 2) << options;
    EXPECT_EQ(r.err, "stereorig rig: " + says + "\n") << options;
    EXPECT_EQ(r.out, "") << options;
  }
  // The bound itself is accepted, and its figures are numbers.
  const Result edge = RunCli("rig --rig " + rig + " --truth " + rig + " --distance 100000 --volume 100000 100000 1");
  EXPECT_EQ(edge.code, 0) << edge.err;
  EXPECT_EQ(edge.out.find("inf"), std::string::npos) << edge.out;
  EXPECT_EQ(edge.out.find("nan"), std::string::npos) << edge.out;
  std::filesystem::remove(rig);
}

// `demo --out` into a folder of the user's wrote the demo's dozen files
// beside theirs, replacing any of the same name; simulate refuses such a
// folder (apps/demo_out.h). Exit 2, one line naming the file, no step run,
// the folder as it was.
TEST(Cli, DemoOutHoldingTheUsersFilesIsRefused) {
  namespace fs = std::filesystem;
  const std::string dir = ::testing::TempDir() + "/cli_demo_mine_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir + "/mine.txt") << "the user's\n";
  std::ofstream(dir + "/rig.yaml") << "the user's rig\n";
  const Result r = RunCli("demo --out " + dir);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(r.err, "stereorig demo: " + dir +
                       ": holds mine.txt, which the demo does not write; refusing to write into it (move it out, or "
                       "choose another --out)\n");
  EXPECT_EQ(r.out.find("$ stereorig"), std::string::npos) << "a step ran: " << r.out;
  std::ifstream rig(dir + "/rig.yaml");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(rig), {}), "the user's rig\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 2);
  fs::remove_all(dir);
}

// match caps the pixels of its images at 50 Mpx, read from the header
// before any pixel is decoded: a 249 KB PNG pair declaring 16000 x 16000 px
// took 5.8 GB and 24 s and wrote a 1 GB PFM. Here a 70-byte PNG declaring
// 8000 x 8000 px (64 Mpx; under png_reader.h's own 268 Mpx) whose image data
// holds one row: refused by its size, not read as the damaged file it also
// is (what a decode would have found first), and no PFM written.
TEST(Cli, MatchRefusesImagesOverItsPixelCapFromTheirHeader) {
  namespace fs = std::filesystem;
  const std::string dir = ::testing::TempDir() + "/match_cap_" + std::to_string(getpid());
  fs::create_directories(dir);
  const std::string big = dir + "/big.png";
  std::ofstream(big, std::ios::binary) << stereorig::testing::kPngSignature +
                                              stereorig::testing::Chunk("IHDR", stereorig::testing::Ihdr(8000, 8000)) +
                                              stereorig::testing::Chunk(
                                                  "IDAT", stereorig::testing::Deflate(std::string(1 + 8000, '\0'), 9)) +
                                              stereorig::testing::Chunk("IEND", "");
  cv::imwrite(dir + "/small.png", cv::Mat(64, 96, CV_8UC1, cv::Scalar(0)));
  for (const auto& [left, right] : {std::pair{big, big}, std::pair{dir + "/small.png", big}}) {
    const Result r = RunCli("match --left " + left + " --right " + right +
                            " --min-disparity 0 --num-disparities 64 --roi 0 0 32 32 --out " + dir + "/d.pfm");
    EXPECT_EQ(r.code, 2) << r.out << r.err;
    EXPECT_EQ(r.err, "stereorig match: " + big +
                         ": is 8000x8000 (64.0 Mpx), over the 50 Mpx match reads (twice the largest stereo camera's; "
                         "crop the pair to the region to match)\n");
    EXPECT_FALSE(fs::exists(dir + "/d.pfm"));
  }
}

// A TIFF is checked from its header too, before its samples are decoded: a
// 128 KB float TIFF declaring 16000 x 16000 px made match take 2 GB before
// it refused it as not 8-bit grey. Here a 64 KB uncompressed float32 TIFF
// declaring 16000 x 16000 px and holding one row: refused for what it is
// (not 8-bit grey), not read as the file cut short it also is (what decoding
// it, 1 GB of floats allocated first, found).
TEST(Cli, MatchRefusesAHugeTiffFromItsHeader) {
  namespace fs = std::filesystem;
  const std::string dir = ::testing::TempDir() + "/match_tiff_" + std::to_string(getpid());
  fs::create_directories(dir);
  std::string tiff = std::string("II*\0", 4);
  auto u16 = [&](uint16_t v) { tiff += char(v & 0xFF), tiff += char(v >> 8); };
  auto u32 = [&](uint32_t v) {
    for (int k = 0; k < 4; ++k) tiff += char((v >> (8 * k)) & 0xFF);
  };
  u32(8);  // the directory follows the header
  const uint32_t width_px = 16000, height_px = 16000, data_at = 8 + 2 + 10 * 12 + 4;
  const std::vector<std::array<uint32_t, 3>> entries = {
      // tag, type (3 SHORT, 4 LONG), value
      {256, 4, width_px}, {257, 4, height_px}, {258, 3, 32},           {259, 3, 1}, {262, 3, 1}, {273, 4, data_at},
      {277, 3, 1},        {278, 4, height_px}, {279, 4, width_px * 4}, {339, 3, 3}};
  u16(uint16_t(entries.size()));
  for (const auto& [tag, type, value] : entries) {
    u16(uint16_t(tag)), u16(uint16_t(type)), u32(1);
    if (type == 3)
      u16(uint16_t(value)), u16(0);
    else
      u32(value);
  }
  u32(0);                                   // no next directory
  tiff += std::string(width_px * 4, '\0');  // one row of the 16000
  const std::string big = dir + "/big.tiff";
  std::ofstream(big, std::ios::binary) << tiff;
  const Result r = RunCli("match --left " + big + " --right " + big + " --min-disparity 0 --num-disparities 64 --out " +
                          dir + "/d.pfm");
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_EQ(r.err.find("cut short"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(big + ": "), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/d.pfm"));
  fs::remove_all(dir);
}

// `rig --truth` compares the truth's modules by their cameras, not their
// place in the file: a rig calibrated with a layout listing the modules in
// the other order is right, and was judged against the other module's
// truth ("3D error 1.0172 / 1.0846 mm, agreement through S 2.4395 mm").
// The same rig so reordered is judged like with like (every figure 0, as
// against itself), and says which truth module each is compared with. A
// module whose left and right are swapped, or whose cameras no truth
// module has, cannot be compared: exit 2, naming it (a swapped one read
// "sees fewer than 3 points of the volume").
TEST(Cli, RigAgainstTruthMatchesModulesByTheirCameras) {
  const std::string dir = ::testing::TempDir() + "/truth_by_cameras";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string truth_path = dir + "/truth.yaml";
  std::ofstream(truth_path) << GoodRigText();
  const stereorig::Rig t = stereorig::MakeDefaultRig().rig;
  auto named = [](stereorig::StereoModule m, const std::string& name) {
    m.name = name;
    return m;
  };
  const stereorig::Rig reordered(t.cameras(), t.camera_names(), {named(t.module(1), "m0"), named(t.module(0), "m1")},
                                 {stereorig::Pose(), t.S(1, 0)});
  stereorig::WriteRigFile(reordered, dir + "/reordered.yaml");
  Result r = RunCli("rig --rig " + dir + "/reordered.yaml --truth " + truth_path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("  (module 0 is compared with the truth's module 1, module1: the same cameras 2,3)\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("module 0: 3D error after rigid alignment 0.0000 mm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("module 1: 3D error after rigid alignment 0.0000 mm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("agreement through S 0.0000 mm"), std::string::npos) << r.out;

  // Module 0's left and right swapped: its frame is camera 1's.
  stereorig::StereoModule swapped = t.module(0);
  std::swap(swapped.left_camera, swapped.right_camera);
  swapped.right_from_left = t.module(0).right_from_left.Inverse();
  const stereorig::Rig lr(t.cameras(), t.camera_names(), {swapped, t.module(1)},
                          {stereorig::Pose(), t.module(0).right_from_left * t.S(0, 1)});
  stereorig::WriteRigFile(lr, dir + "/swapped.yaml");
  r = RunCli("rig --rig " + dir + "/swapped.yaml --truth " + truth_path);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "stereorig rig: --truth: the rig's module 0 (module0) has left camera 1 and right camera 0, the truth's "
            "module 0 (module0) the same two the other way round (left 0, right 1): left and right swapped in the "
            "layout it was calibrated with?\n");
  EXPECT_EQ(r.out, "");

  // Modules of other camera pairs: (0, 2) and (1, 3).
  stereorig::StereoModule a = t.module(0), b = t.module(1);
  a.right_camera = 2;
  b.left_camera = 1;
  const stereorig::Rig other(t.cameras(), t.camera_names(), {a, b}, {stereorig::Pose(), t.S(0, 1)});
  stereorig::WriteRigFile(other, dir + "/other.yaml");
  r = RunCli("rig --rig " + dir + "/other.yaml --truth " + truth_path);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "stereorig rig: --truth: the rig's module 0 (module0) uses cameras 0,2 (left, right), which no module of "
            "the truth does (module 0 (module0) cameras 0,1; module 1 (module1) cameras 2,3): a rig of other "
            "cameras?\n");
  std::filesystem::remove_all(dir);
}

}  // namespace
