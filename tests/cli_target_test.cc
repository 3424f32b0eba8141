// `stereorig target`, run as the real binary: it writes a true-scale SVG
// atomically, the target file it used, and refuses bad input with exit 2.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/cli_runner.h"

namespace {

using stereorig::testing::Result;

std::string Slurp(const std::string& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

Result RunStereorig(const std::string& args) { return stereorig::testing::RunCli(args); }

TEST(CliTarget, WritesTheDefaultBoardAndItsTargetFile) {
  const std::string dir = ::testing::TempDir() + "/cli_target";
  std::filesystem::create_directories(dir);
  const Result r = RunStereorig("target --out " + dir + "/board.svg --write-target " + dir + "/board.yaml");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string svg = Slurp(dir + "/board.svg");
  EXPECT_NE(svg.find("viewBox=\"0 0 "), std::string::npos);
  EXPECT_NE(svg.find("id=\"front\""), std::string::npos);
  EXPECT_NE(svg.find("id=\"back\""), std::string::npos);
  EXPECT_NE(svg.find("check: this bar is 100.0 mm"), std::string::npos);
  EXPECT_NE(r.out.find("print at 100 %"), std::string::npos);
  // The target file written reads back: draw its back face alone from it.
  const Result back = RunStereorig("target --target " + dir + "/board.yaml --face back --out " + dir + "/back.svg");
  ASSERT_EQ(back.code, 0) << back.err;
  const std::string back_svg = Slurp(dir + "/back.svg");
  EXPECT_EQ(back_svg.find("id=\"front\""), std::string::npos);
  EXPECT_NE(back_svg.find("id=\"back\""), std::string::npos);
}

// The default's design at another size (a user's own board): the corner
// grid, the tags in the margins (4 a margin, spread over the grid's width
// plus a square each side: centres at -s + (cx + 1) s (k + 1/2) / 4, and
// -s - margin / 2 above) and the back in register through the plate
// (back_from_front = diag(-1, 1, -1), ((cx - 1) s, 0, thickness)), worked
// out by hand from docs/targets.md's frames; the file reads back. Boards too
// small for the tags, and a size given with --target, are refused.
TEST(CliTarget, TheDefaultsDesignAtAnotherSize) {
  const std::string dir = ::testing::TempDir() + "/cli_target_resized";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const Result r = RunStereorig("target --corners 8 6 --square-mm 20 --thickness-mm 6 --out " + dir +
                                "/b.svg --write-target " + dir + "/b.yaml");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string yaml = Slurp(dir + "/b.yaml");
  for (const char* line : {"corners_x: 8 ", "corners_y: 6 ", "square_size_mm: 20\n", "{id: 0, center_mm: [2.5, -27.5]}",
                           "{id: 3, center_mm: [137.5, -27.5]}", "{id: 107, center_mm: [137.5, 127.5]}",
                           "back_from_front: [[-1, 0, 0, 140], [0, 1, 0, -0], [0, 0, -1, 6], [0, 0, 0, 1]]"})
    EXPECT_NE(yaml.find(line), std::string::npos) << line << "\n" << yaml;
  const Result back = RunStereorig("target --target " + dir + "/b.yaml --out " + dir + "/again.svg");
  EXPECT_EQ(back.code, 0) << back.err;
  EXPECT_EQ(Slurp(dir + "/again.svg"), Slurp(dir + "/b.svg"));

  const Result tiny = RunStereorig("target --corners 4 3 --square-mm 3 --out " + dir + "/tiny.svg");
  EXPECT_EQ(tiny.code, 2);
  EXPECT_EQ(std::count(tiny.err.begin(), tiny.err.end(), '\n'), 1) << tiny.err;
  EXPECT_NE(tiny.err.find("--corners, --square-mm: "), std::string::npos) << tiny.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/tiny.svg"));
  // A size under 1 mm names the unit it was likely typed in, as the target
  // file's square_size_mm does (it read "Value 0.9 not in range 1.000000 to
  // 500.000000"); above the range, CLI11's words still.
  for (const auto& [size, unit] : {std::pair{"0.9", "centimetres"}, std::pair{"0.009", "metres"}}) {
    const Result small = RunStereorig(std::string("target --square-mm ") + size + " --out " + dir + "/small.svg");
    EXPECT_EQ(small.code, 2) << size;
    EXPECT_EQ(small.err, std::string("stereorig target: --square-mm: ") + size + ": squares of " +
                             (unit == std::string("metres") ? "9" : "900") +
                             " um, under the 1 mm a camera resolves; is it in " + unit +
                             "? the unit is mm (see --help)\n");
    EXPECT_FALSE(std::filesystem::exists(dir + "/small.svg"));
  }
  // NaN passed CLI11's range checks (its comparisons fail) and was refused
  // later as "back_from_front: contains NaN or Inf", naming no flag's value.
  for (const char* flag : {"--square-mm", "--thickness-mm"}) {
    const Result nan = RunStereorig(std::string("target ") + flag + " nan --out " + dir + "/nan.svg");
    EXPECT_EQ(nan.code, 2) << flag;
    EXPECT_NE(nan.err.find(std::string(flag) + ": must be positive and finite, got nan"), std::string::npos) << nan.err;
  }
  EXPECT_NE(RunStereorig("target --square-mm 600 --out " + dir + "/large.svg").err.find("not in range"),
            std::string::npos);
  const Result both = RunStereorig("target --target " + dir + "/b.yaml --square-mm 12 --out " + dir + "/x.svg");
  EXPECT_EQ(both.code, 2);
  EXPECT_NE(both.err.find("--target excludes --square-mm"), std::string::npos) << both.err;
}

TEST(CliTarget, BadTargetFileExitsTwoAndWritesNothing) {
  const std::string dir = ::testing::TempDir() + "/cli_target_bad";
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/bad.yaml") << "format: stereorig-target\nversion: 1\nunits: mm\ncorners_x: 11\n";
  const Result r = RunStereorig("target --target " + dir + "/bad.yaml --out " + dir + "/board.svg");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.yaml"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);
  EXPECT_FALSE(std::filesystem::exists(dir + "/board.svg"));
  EXPECT_EQ(RunStereorig("target --out " + dir + "/x.svg --face sideways").code, 2);
  EXPECT_EQ(RunStereorig("target").code, 2);  // --out is required
}

// A double-sided board whose back_from_front keeps z (the rotation left at
// the identity: a back face facing the way the front does) was drawn, exit
// 0, and calibrate refused it only after its whole solve. Refused when read.
TEST(CliTarget, ABackFaceFacingTheWayTheFrontDoesIsRefused) {
  const std::string dir = ::testing::TempDir() + "/cli_target_back_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ASSERT_EQ(RunStereorig("target --out " + dir + "/default.svg --write-target " + dir + "/t.yaml").code, 0);
  std::ifstream in(dir + "/t.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string flat = text.str();
  const size_t at = flat.find("\nback_from_front: ");
  ASSERT_NE(at, std::string::npos) << flat;
  flat.replace(at, flat.find('\n', at + 1) - at,
               "\nback_from_front: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 5], [0, 0, 0, 1]]");
  std::ofstream(dir + "/flat.yaml") << flat;
  const Result r = RunStereorig("target --target " + dir + "/flat.yaml --out " + dir + "/board.svg");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "stereorig target: " + dir +
                       "/flat.yaml: back_from_front: its rotation turns the back face's z axis 0 deg from the "
                       "front's: a back face faces away from the front (z into the plate on each face), turned about "
                       "180 deg (about y: diag(-1, 1, -1))\n");
  EXPECT_FALSE(std::filesystem::exists(dir + "/board.svg"));
  std::filesystem::remove_all(dir);
}

// --face back of a plain (one-sided) board is refused naming the flag and
// the target file (the SVG writer's "board svg: ..." named neither).
TEST(CliTarget, BackFaceOfAPlainBoardNamesTheFlagAndTheFile) {
  const std::string dir = ::testing::TempDir() + "/cli_target_plain";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/plain.yaml") << "format: stereorig-target\nversion: 1\nunits: mm\ncorners_x: 8\n"
                                        "corners_y: 6\nsquare_size_mm: 20\ndouble_sided: false\n";
  ASSERT_EQ(RunStereorig("target --target " + dir + "/plain.yaml --out " + dir + "/front.svg").code, 0);
  const Result r = RunStereorig("target --target " + dir + "/plain.yaml --face back --out " + dir + "/b.svg");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "stereorig target: --face: back: " + dir + "/plain.yaml is a plain (one-sided) board, with no back face\n");
  EXPECT_FALSE(std::filesystem::exists(dir + "/b.svg"));
}

// Both outputs or neither: a target file that cannot be written (in a
// folder where no file can be created, UnwritablePath) leaves an earlier
// run's SVG as it was and no temporary file. (Once, the new SVG was in place
// and the run exited 2.) Root too is now refused before any work (a file is
// created and removed there when the outputs are claimed); a write that
// fails late is AtomicOutputSet's, tested in atomic_file_test.cc.
TEST(CliTarget, ATargetFileThatCannotBeWrittenLeavesTheEarlierSvg) {
  const std::string dir = ::testing::TempDir() + "/cli_target_all_or_none";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/board.svg") << "earlier run";
  const std::string unwritable = stereorig::testing::UnwritablePath("cli-target.yaml");
  const Result r = RunStereorig("target --out " + dir + "/board.svg --write-target " + unwritable);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(unwritable + ": cannot write the target file (--write-target) in its folder /proc: "),
            std::string::npos)
      << r.err;
  EXPECT_EQ(Slurp(dir + "/board.svg"), "earlier run");
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) ++files, (void)entry;
  EXPECT_EQ(files, 1);  // board.svg alone: no temporary file
}

// A target file's name of up to the file system's 255 bytes is written,
// and nothing else is left beside it. (Before, one of 250 failed: its
// temporary file's name, ".tmp-<pid>-<n>-<name>", passed 255.)
TEST(CliTarget, ATargetFileNameOf255BytesIsWritten) {
  const std::string dir = ::testing::TempDir() + "/cli_target_long_name";
  for (const size_t name_bytes : {250u, 255u}) {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const std::string name = std::string(name_bytes - 5, 't') + ".yaml";
    const Result r = RunStereorig("target --out " + dir + "/board.svg --write-target " + dir + "/" + name);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(Slurp(dir + "/" + name).find("stereorig-target"), std::string::npos) << name_bytes;
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) names.push_back(entry.path().filename());
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"board.svg", name}));
  }
}

// Its outputs are checked before anything is drawn: one path for both, or
// the target file it reads as the SVG, would leave the SVG replaced by YAML
// (or the target file by the SVG) with exit 0.
TEST(CliTarget, OutputsThatCollideOrOverwriteTheTargetFileAreRefused) {
  const std::string dir = ::testing::TempDir() + "/cli_target_paths";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  Result r = RunStereorig("target --out " + dir + "/board.svg --write-target " + dir + "/board.svg");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("board.svg: would be written twice"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/board.svg"));

  ASSERT_EQ(RunStereorig("target --out " + dir + "/first.svg --write-target " + dir + "/board.yaml").code, 0);
  const std::string yaml = Slurp(dir + "/board.yaml");
  r = RunStereorig("target --target " + dir + "/board.yaml --out " + dir + "/board.yaml");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("board.yaml: is the target file (--target)"), std::string::npos) << r.err;
  EXPECT_EQ(Slurp(dir + "/board.yaml"), yaml);

  // --write-target over the target file: CliTarget.WriteTargetOverTheTargetFileIsRefused.
  // Through a symbolic link the SVG would still land on the target file.
  std::filesystem::create_symlink(dir + "/board.yaml", dir + "/link.yaml");
  r = RunStereorig("target --target " + dir + "/board.yaml --out " + dir + "/link.yaml");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("link.yaml: is the target file (--target)"), std::string::npos) << r.err;
  EXPECT_EQ(Slurp(dir + "/board.yaml"), yaml);

  r = RunStereorig("target --out " + dir + "/missing/board.svg");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("its folder does not exist"), std::string::npos) << r.err;
}

// --- Robustness walkthrough 44 (fuzz-bounds): target's outputs and sizes ---

// --write-target naming the --target file rewrote it, exit 0, and the
// user's comments ("# MEASURED with calipers") were gone. Refused as every
// output over an input is (apps/output_paths.h), the file byte-identical.
TEST(CliTarget, WriteTargetOverTheTargetFileIsRefused) {
  const std::string dir = ::testing::TempDir() + "/cli_target_write_back_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ASSERT_EQ(RunStereorig("target --out " + dir + "/first.svg --write-target " + dir + "/board.yaml").code, 0);
  std::ofstream(dir + "/board.yaml", std::ios::app) << "# MEASURED with calipers\n";
  const std::string measured = Slurp(dir + "/board.yaml");
  const Result r = RunStereorig("target --target " + dir + "/board.yaml --out " + dir + "/second.svg --write-target " +
                                dir + "/board.yaml");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "stereorig target: " + dir +
                       "/board.yaml: is the target file (--target): writing the target file (--write-target) there "
                       "would overwrite an input\n");
  EXPECT_EQ(Slurp(dir + "/board.yaml"), measured);
  EXPECT_FALSE(std::filesystem::exists(dir + "/second.svg"));
  std::filesystem::remove_all(dir);
}

// The SVG's suffix: --out board.txt wrote an SVG under that name, while
// every other output named by its format requires its suffix. Any case of
// .svg is one.
TEST(CliTarget, TheOutputMustBeNamedSvg) {
  const std::string dir = ::testing::TempDir() + "/cli_target_suffix_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  for (const char* name : {"board.txt", "board", "board.svg.pdf"}) {
    const Result r = RunStereorig("target --out " + dir + "/" + name);
    EXPECT_EQ(r.code, 2) << name;
    EXPECT_EQ(r.err,
              "stereorig target: " + dir + "/" + name + ": the target output must end in .svg (it is written as SVG)\n")
        << name;
    EXPECT_FALSE(std::filesystem::exists(dir + "/" + name)) << name;
  }
  EXPECT_EQ(RunStereorig("target --out " + dir + "/board.SVG").code, 0);
  std::filesystem::remove_all(dir);
}

// --corners is held to 200 a side, a target file's corners_x and corners_y
// were not: 100000 drew a 64 MB SVG, exit 0. The same bound for both
// (targets/target_file.h, kMaxInnerCorners); 200 itself is drawn.
TEST(CliTarget, ATargetFilesCornersAreHeldToTheCornersOptionsBound) {
  const std::string dir = ::testing::TempDir() + "/cli_target_corners_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ASSERT_EQ(RunStereorig("target --out " + dir + "/a.svg --write-target " + dir + "/board.yaml").code, 0);
  const std::string board = Slurp(dir + "/board.yaml");
  const size_t at = board.find("corners_x: 11");
  ASSERT_NE(at, std::string::npos) << board;
  for (const char* corners : {"100000", "201"}) {
    std::string big = board;
    big.replace(at, 13, std::string("corners_x: ") + corners);
    std::ofstream(dir + "/big.yaml") << big;
    const Result r = RunStereorig("target --target " + dir + "/big.yaml --out " + dir + "/big.svg");
    EXPECT_EQ(r.code, 2) << corners;
    EXPECT_EQ(r.err, "stereorig target: " + dir + "/big.yaml: corners_x: " + corners +
                         ": more than 200, the most inner corners a side (as `stereorig target --corners`): 200 "
                         "squares across a 752 px imager leave under 4 px each\n");
    EXPECT_FALSE(std::filesystem::exists(dir + "/big.svg"));
  }
  std::string most = board;
  most.replace(at, 13, "corners_x: 200");
  std::ofstream(dir + "/most.yaml") << most;
  const Result r = RunStereorig("target --target " + dir + "/most.yaml --out " + dir + "/most.svg");
  EXPECT_EQ(r.code, 0) << r.err;
  std::filesystem::remove_all(dir);
}

}  // namespace
