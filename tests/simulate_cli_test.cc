// `stereorig simulate` from the command line: the spec round trip through a
// file, bad specs (exit 2, one line naming the key), and (label e2e) the
// whole default dataset is in simulate_e2e_test.cc.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "tests/sim_cli_util.h"

namespace {

using namespace sim_cli;

// Each `simulate ARGS` exits 2 with one line that holds SAYS, and nothing
// is written into `dir` (the folder its --out is in).
void ExpectEachRefusedBeforeAnyWork(const std::vector<std::pair<std::string, std::string>>& cases,
                                    const std::string& dir) {
  for (const auto& [args, says] : cases) {
    const Result r = RunCli("simulate" + args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << ": " << r.err;
  }
  EXPECT_TRUE(fs::is_empty(dir));
}

TEST(SimulateCli, DefaultSpecFileRoundTripsAndBadKeysExitTwo) {
  const std::string dir = ::testing::TempDir();
  const std::string spec = dir + "/sim_default_spec.yaml";
  ASSERT_EQ(RunCli("simulate --write-default-spec " + spec).code, 0);
  const std::string text = Slurp(spec);
  ASSERT_NE(text.find("lines: 51"), std::string::npos);
  // The written default renders (one capture, no scenes).
  Result r = RunCli("simulate --spec " + spec + " --out " + dir + "/sim_cli_ds --calibration-captures 1 --no-scenes");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir + "/sim_cli_ds/calibration/000/cam3.png"));
  // A typo in a key: exit 2, one line naming the file and the key.
  std::string bad = text;
  bad.replace(bad.find("psf_sigma_px"), 12, "psf_sigma_pix");
  std::ofstream(dir + "/sim_bad_spec.yaml") << bad;
  r = RunCli("simulate --spec " + dir + "/sim_bad_spec.yaml --out " + dir + "/sim_cli_bad");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("psf_sigma_pix"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("sim_bad_spec.yaml"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/sim_cli_bad"));
  // A bad value.
  bad = text;
  bad.replace(bad.find("captures: 50"), 12, "captures: -4");
  std::ofstream(dir + "/sim_bad_spec2.yaml") << bad;
  r = RunCli("simulate --spec " + dir + "/sim_bad_spec2.yaml --out " + dir + "/sim_cli_bad");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("captures"), std::string::npos) << r.err;
}

// A spec's relative calibration.target is its neighbour, read from the
// spec file's folder wherever simulate runs: it was read from the current
// folder ("board12.yaml: no such file", naming no key), and the dataset's
// spec.yaml kept the name without the board, so it did not render again.
// Now the dataset's spec names the target.yaml written beside it, and
// renders the same images from there.
TEST(SimulateCli, ASpecsRelativeTargetIsReadFromItsFolderAndTheDatasetRendersAgain) {
  const std::string dir = ::testing::TempDir() + "/sim_relative_target";
  fs::remove_all(dir);
  fs::create_directories(dir + "/specdir");
  ASSERT_EQ(RunCli("target --corners 9 7 --square-mm 10 --out " + dir + "/board12.svg --write-target " + dir +
                   "/specdir/board12.yaml")
                .code,
            0);
  ASSERT_EQ(RunCli("simulate --write-default-spec " + dir + "/specdir/spec.yaml").code, 0);
  std::string spec = Slurp(dir + "/specdir/spec.yaml");
  const size_t at = spec.find("target: default");
  ASSERT_NE(at, std::string::npos) << "the default spec changed: " << spec;
  spec.replace(at, 15, "target: board12.yaml");
  std::ofstream(dir + "/specdir/spec.yaml") << spec;
  // The test runs in another folder than specdir.
  ASSERT_FALSE(fs::exists("board12.yaml"));
  const std::string one = " --calibration-captures 1 --no-scenes --threads 2";
  Result r = RunCli("simulate --spec " + dir + "/specdir/spec.yaml --out " + dir + "/a" + one);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(Slurp(dir + "/a/target.yaml"), Slurp(dir + "/specdir/board12.yaml"));
  r = RunCli("simulate --spec " + dir + "/a/spec.yaml --out " + dir + "/b" + one);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* file : {"spec.yaml", "target.yaml", "calibration/000/cam0.png", "calibration/000/cam3.png"})
    EXPECT_EQ(Slurp(dir + "/b/" + file), Slurp(dir + "/a/" + file)) << file;
  // A target that is not there: exit 2, one line naming the spec, the key
  // and where it looked.
  fs::remove(dir + "/specdir/board12.yaml");
  r = RunCli("simulate --spec " + dir + "/specdir/spec.yaml --out " + dir + "/c" + one);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(Lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(dir + "/specdir/spec.yaml: calibration.target: no file " + dir + "/specdir/board12.yaml"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir + "/c"));
}

// An --out with a trailing slash (as a shell's completion writes it) names
// the same folder as without one. simulate used to render the whole dataset
// and then fail to rename it into place ("cannot replace: Invalid
// argument", exit 2), leaving the new folder behind, empty. Written again
// over itself, the dataset is replaced whole, nothing left beside it.
TEST(SimulateCli, AnOutFolderWithATrailingSlashIsWritten) {
  const std::string dir = ::testing::TempDir() + "/sim_trailing_slash";
  fs::remove_all(dir);
  for (int run = 0; run < 2; ++run) {
    // Two captures, then one: the second dataset replaces the first whole
    // (swapped in one step where the file system can: simulate.cc), so its
    // capture 001 is gone.
    const Result r =
        RunCli("simulate --out " + dir + "/new/ds/ --calibration-captures " + (run ? "1" : "2") + " --no-scenes");
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir + "/new/ds/calibration/000/cam3.png")) << run;
    EXPECT_EQ(fs::exists(dir + "/new/ds/calibration/001"), run == 0) << run;
    int entries = 0;
    for (const auto& e : fs::directory_iterator(dir + "/new")) entries += e.path().filename() == "ds" ? 1 : 100;
    EXPECT_EQ(entries, 1) << "something beside the dataset, run " << run;
  }
}

// An --out that cannot be made (a name longer than the file system's 255
// bytes: a folder above it, or the folder itself) exits 2 in one line naming
// it and the name, before any rendering, and the folders made above it on
// the way are removed again (FolderToCreate, calib/core/folder_to_create.h);
// they used to stay, empty. The dataset's own name too long, in a folder
// there or one to make, used to be std::filesystem's "filesystem error:
// status: File name too long [path]".
TEST(SimulateCli, AnOutThatCannotBeMadeLeavesNoFolder) {
  const std::string dir = fs::path(::testing::TempDir() + "/sim_long").lexically_normal();  // as messages name it
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string x300(300, 'x'), z256(256, 'z');
  const struct {
    std::string out, name;
  } cases[] = {{dir + "/new/" + x300 + "/ds", x300}, {dir + "/new/" + z256, z256}, {dir + "/" + z256, z256}};
  for (const auto& [out, name] : cases) {
    const Result r = RunCli("simulate --out " + out + " --calibration-captures 1 --no-scenes");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(out + ": cannot create this folder for the dataset (--out): File name too long (" +
                         name.substr(0, 16) + "...: " + std::to_string(name.size()) +
                         " characters, more than the 255 the file system allows in " + dir + ")\n"),
              std::string::npos)
        << r.err;
    EXPECT_TRUE(fs::is_empty(dir)) << "the folder made on the way was left behind: " << out.substr(0, 80);
  }
  fs::remove_all(dir);
}

// An --out whose name takes up to the file system's 255 bytes is written,
// and written again over itself, nothing left beside it. (Before, one of 250
// bytes failed: the temporary folder's name, ".<name>.tmp-<pid>", passed
// 255, as did ".<name>.old-<pid>", the earlier dataset's while it is
// replaced.)
TEST(SimulateCli, AnOutNameOf255BytesIsWritten) {
  const std::string dir = ::testing::TempDir() + "/sim_long_name";
  fs::remove_all(dir);
  const std::pair<std::string, std::string> cases[] = {
      {std::string(250, 'y'), "--calibration-captures 1"},  // a whole capture in it
      {std::string(255, 'y'), "--calibration-captures 0"},
      {std::string(255, 'y'), "--calibration-captures 0"}};  // replacing the one before
  for (const auto& [name, captures] : cases) {
    const Result r = RunCli("simulate --out " + dir + "/" + name + " --no-scenes " + captures);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir + "/" + name + "/spec.yaml")) << name.size();
  }
  EXPECT_TRUE(fs::exists(dir + "/" + std::string(250, 'y') + "/calibration/000/cam3.png"));
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir)) ++entries, (void)e;
  EXPECT_EQ(entries, 2) << "something beside the two datasets";
}

// `stereorig simulate` stopped by SIGTERM mid-render dies of the signal and
// leaves neither its temporary folder (it used to leave .<name>.tmp-<pid>/
// with every image rendered so far: calib/core/pending_temporary.h) nor the
// dataset, nor the folders it made above them (new/sub: they used to stay,
// empty; calib/core/folder_to_create.h). 200 captures would take a minute: the signal comes once the first
// image is there, found by polling (the ray tables come first, a few seconds
// on a loaded machine).
TEST(SimulateCli, ATerminationSignalMidRenderLeavesNoTemporaryFolder) {
  const std::string dir = ::testing::TempDir() + "/sim_signal";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = dir + "/new/sub/ds";
  const char* argv[] = {"stereorig", "simulate",    "--out",     out.c_str(), "--calibration-captures",
                        "200",       "--no-scenes", "--threads", "2",         nullptr};
  posix_spawn_file_actions_t quiet;
  posix_spawn_file_actions_init(&quiet);
  posix_spawn_file_actions_addopen(&quiet, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&quiet, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int spawned =
      posix_spawn(&pid, stereorig::testing::kBin.c_str(), &quiet, nullptr, const_cast<char**>(argv), environ);
  posix_spawn_file_actions_destroy(&quiet);
  ASSERT_EQ(spawned, 0);
  // The wait status once it ends, or -1 if it still runs when `until` comes
  // true or `seconds` have passed.
  auto status_within = [pid](int seconds, const std::function<bool()>& until) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
    int status = 0;
    while (std::chrono::steady_clock::now() < deadline) {
      if (waitpid(pid, &status, WNOHANG) == pid) return status;
      if (until && until()) return -1;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return -1;
  };
  const fs::path first_image = dir + "/new/sub/.ds.tmp-" + std::to_string(pid) + "/calibration/000/cam0.png";
  const int early = status_within(60, [&] {
    std::error_code ec;
    return fs::exists(first_image, ec);
  });
  ASSERT_EQ(early, -1) << "simulate ended before its first image was seen";
  ASSERT_TRUE(fs::exists(first_image)) << "no image within a minute";
  kill(pid, SIGTERM);
  int status = status_within(20, nullptr);
  if (status == -1) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    FAIL() << "simulate did not end within 20 s of SIGTERM";
  }
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << WEXITSTATUS(status);
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(dir)) left.push_back(entry.path().filename());
  EXPECT_TRUE(left.empty()) << "left: " << (left.empty() ? "" : left[0]);
}

// simulate's errors about --out name it as the user typed it, relative and
// unnormalised; they used to name it absolute and normalised (./junk/ as
// /home/.../junk), a path the user never wrote. The work is still done on
// the normalised path. Each is refused before any rendering, in one line,
// nothing left behind.
TEST(SimulateCli, OutErrorsNameTheFolderAsTyped) {
  const std::string dir = ::testing::TempDir() + "/sim_typed";
  fs::remove_all(dir);
  fs::create_directories(dir + "/junk");
  std::ofstream(dir + "/junk/notes.txt") << "not a dataset\n";
  std::ofstream(dir + "/afile") << "a file\n";
  struct InFolder {  // the working folder for the relative --out, restored however the test ends
    fs::path before = fs::current_path();
    explicit InFolder(const std::string& folder) { fs::current_path(folder); }
    ~InFolder() { fs::current_path(before); }
  } in_dir(dir);
  const std::string z256(256, 'z');
  const std::string not_a_dataset = ": exists and is not a stereorig dataset (no spec.yaml); refusing to replace it\n";
  const std::pair<std::string, std::string> cases[] = {
      {"junk", "junk" + not_a_dataset},
      {"./junk/", "./junk/" + not_a_dataset},
      {"afile", "afile: exists and is not a folder\n"},
      {"afile/ds", "afile/ds: cannot create this folder for the dataset (--out): Not a directory\n"},
      {"new/" + z256, "new/" + z256 + ": cannot create this folder for the dataset (--out): File name too long ("}};
  for (const auto& [out, says] : cases) {
    const Result r = RunCli("simulate --out " + out + " --calibration-captures 0 --no-scenes");
    EXPECT_EQ(r.code, 2) << out;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_EQ(r.err.rfind("stereorig simulate: " + says, 0), 0u) << r.err;  // the line starts so
  }
  std::vector<std::string> left;
  for (const auto& e : fs::recursive_directory_iterator(dir)) left.push_back(fs::relative(e.path(), dir).string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"afile", "junk", "junk/notes.txt"}));
}

// Options that would be ignored, or read wrongly, are refused before any
// work, in one line naming the flag: a bump without what to move or by how
// much rendered an undisturbed rig; --write-default-spec ignored --out; a
// negative seed wrapped round to 2^64 - 1.
TEST(SimulateCli, OptionsThatWouldBeIgnoredAreRefused) {
  const std::string dir = ::testing::TempDir() + "/sim_ignored_options";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = " --out " + dir + "/ds";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {out + " --bump-rotation-deg 0.1", "--bump-rotation-deg: needs --bump-camera or --bump-module"},
      {out + " --bump-camera 1",
       "--bump-camera: needs --bump-rotation-deg, --bump-translation-mm, --bump-focal-percent or "
       "--bump-principal-point-px"},
      {out + " --bump-module 1", "--bump-module: needs --bump-rotation-deg or --bump-translation-mm"},
      {" --write-default-spec " + dir + "/s.yaml" + out, "--out: does not apply with --write-default-spec"},
      {" --write-default-spec " + dir + "/s.yaml --bump-camera 1", "--bump-camera: does not apply with"},
      {out + " --seed -1", "--seed: must be >= 0"},
      // Leading space: strtoull skips it and wrapped "-1" round to 2^64 - 1.
      {out + " --seed ' -1'", "--seed: must be >= 0"}};
  ExpectEachRefusedBeforeAnyWork(cases, dir);
}

// Numbers out of their range are refused by the flag's name before any
// work: --calibration-captures -1 (the options' "the spec's count") rendered
// the spec's captures, a seed above 2^64 - 1 was saturated to it, and
// --threads had no bound (100000 died of an uncaught std::system_error,
// exit 134, its temporary folder left behind; 1025 is the first refused,
// and is harmless to try on the unfixed binary).
TEST(SimulateCli, OutOfRangeNumbersAreRefusedByTheFlagsName) {
  const std::string dir = ::testing::TempDir() + "/sim_out_of_range";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = " --out " + dir + "/ds --no-scenes";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {out + " --calibration-captures -1", "--calibration-captures: must be in [0, 999]"},
      {out + " --calibration-captures 1000", "--calibration-captures: must be in [0, 999]"},
      {out + " --calibration-captures 0 --seed 18446744073709551616",
       "--seed: must be at most 18446744073709551615 (2^64 - 1)"},
      {out + " --calibration-captures 0 --seed 0x1ffffffffffffffff", "--seed: must be at most 18446744073709551615"},
      {out + " --calibration-captures 0 --threads 1025", "--threads: must be in [0, 1024] (0 = every core)"},
      {out + " --calibration-captures 0 --threads -1", "--threads: must be in [0, 1024]"}};
  ExpectEachRefusedBeforeAnyWork(cases, dir);
  // The largest seed is a seed, and recorded as given.
  const Result r = RunCli("simulate" + out + " --calibration-captures 0 --seed 18446744073709551615 --threads 1024");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(Slurp(dir + "/ds/truth/simulation.yaml").find("\nseed: 18446744073709551615\n"), std::string::npos);
}

// A seed is read as the user wrote it: CLI11 took a leading 0 as octal, so
// a script's zero-padded seeds (seq -w) made 010 seed 8 without a word and
// refused 08. Leading zeros are now zeros; hex needs 0x; anything else
// (0b101, a space, a sign) is refused by the flag's name.
TEST(SimulateCli, ZeroPaddedSeedsAreDecimal) {
  const std::string dir = ::testing::TempDir() + "/sim_seed_forms";
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const auto& [given, recorded] :
       std::vector<std::pair<std::string, std::string>>{{"010", "10"}, {"08", "8"}, {"0x10", "16"}, {"0010", "10"}}) {
    fs::remove_all(dir + "/ds");
    const Result r = RunCli("simulate --out " + dir + "/ds --no-scenes --calibration-captures 0 --seed " + given);
    ASSERT_EQ(r.code, 0) << given << ": " << r.err;
    EXPECT_NE(Slurp(dir + "/ds/truth/simulation.yaml").find("\nseed: " + recorded + "\n"), std::string::npos)
        << "--seed " << given << " should be seed " << recorded;
  }
  fs::remove_all(dir + "/ds");
  const std::string out = " --out " + dir + "/ds --no-scenes --calibration-captures 0";
  ExpectEachRefusedBeforeAnyWork(
      {{out + " --seed 0b101", "--seed: must be a whole number (decimal, or hex with 0x), not '0b101'"},
       {out + " --seed '+5'", "--seed: must be a whole number"},
       {out + " --seed ' 5'", "--seed: must be a whole number"},
       {out + " --seed -1", "--seed: must be >= 0"}},
      dir);
}

// Every whole-number option reads a leading 0 as a decimal zero, as --seed
// does: CLI11 took it as octal, so --calibration-captures 010 rendered 8
// captures and --threads 09 was refused ("Could not convert").
TEST(SimulateCli, ZeroPaddedCountsAreDecimal) {
  const std::string dir = ::testing::TempDir() + "/sim_count_forms";
  fs::remove_all(dir);
  const Result r = RunCli("simulate --out " + dir + " --no-scenes --calibration-captures 010 --threads 02");
  ASSERT_EQ(r.code, 0) << r.err;
  int captures = 0;
  for (const auto& entry : fs::directory_iterator(dir + "/calibration")) captures += entry.is_directory();
  EXPECT_EQ(captures, 10);
  fs::remove_all(dir);
}

// A project folder holding the user's own spec, its board and notes, given
// as --out: exit 2 before any work, naming the input it holds, every file
// as it was. It used to pass for an earlier dataset (it has a spec.yaml)
// and was replaced whole: the spec, the board and the notes were deleted.
// A folder with a spec.yaml that is not an input is refused as no dataset
// (no truth/simulation.yaml); an earlier dataset with a file the simulator
// does not write is refused naming it.
TEST(SimulateCli, AProjectFolderIsNotReplaced) {
  const std::string dir = ::testing::TempDir() + "/sim_project";
  fs::remove_all(dir);
  fs::create_directories(dir + "/proj");
  ASSERT_EQ(RunCli("target --corners 9 7 --square-mm 10 --out " + dir + "/board.svg --write-target " + dir +
                   "/proj/myboard.yaml")
                .code,
            0);
  ASSERT_EQ(RunCli("simulate --write-default-spec " + dir + "/proj/spec.yaml").code, 0);
  std::string spec = Slurp(dir + "/proj/spec.yaml");
  const size_t at = spec.find("target: default");
  ASSERT_NE(at, std::string::npos);
  spec.replace(at, 15, "target: myboard.yaml");
  std::ofstream(dir + "/proj/spec.yaml") << spec;
  std::ofstream(dir + "/proj/notes.txt") << "notes\n";
  const std::string board = Slurp(dir + "/proj/myboard.yaml");
  const std::string run = " --calibration-captures 0 --no-scenes";
  const std::pair<std::string, std::string> cases[] = {
      {"--spec " + dir + "/proj/spec.yaml --out " + dir + "/proj",
       dir + "/proj: holds the spec file (--spec) " + dir + "/proj/spec.yaml: replacing the folder"},
      {"--spec " + dir + "/proj/spec.yaml --out " + dir + "/proj/spec.yaml",
       dir + "/proj/spec.yaml: is the spec file (--spec), not a folder for the dataset (--out)"},
      {"--spec " + dir + "/proj/spec.yaml --out " + dir + "/proj/myboard.yaml",
       dir + "/proj/myboard.yaml: is the spec's target file (calibration.target)"},
      {"--out " + dir + "/proj",
       dir + "/proj: exists and is not a stereorig dataset (no truth/simulation.yaml of format stereorig-sim-info)"}};
  for (const auto& [args, says] : cases) {
    const Result r = RunCli("simulate " + args + run);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_EQ(r.err.rfind("stereorig simulate: " + says, 0), 0u) << r.err;
  }
  EXPECT_EQ(Slurp(dir + "/proj/spec.yaml"), spec);
  EXPECT_EQ(Slurp(dir + "/proj/myboard.yaml"), board);
  EXPECT_EQ(Slurp(dir + "/proj/notes.txt"), "notes\n");
  // An earlier dataset is replaced, unless it holds a file of the user's.
  ASSERT_EQ(RunCli("simulate --out " + dir + "/ds" + run).code, 0);
  ASSERT_EQ(RunCli("simulate --out " + dir + "/ds" + run).code, 0);
  std::ofstream(dir + "/ds/score.json") << "{}";
  const Result r = RunCli("simulate --out " + dir + "/ds" + run);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "stereorig simulate: " + dir +
                       "/ds: holds score.json, which the simulator does not write; refusing to replace the dataset "
                       "and delete it (move it out, or choose another --out)\n");
  EXPECT_EQ(Slurp(dir + "/ds/score.json"), "{}");
}

// A bump names a camera or module that exists and moves it by a finite
// amount within +-10, or exits 2 before any work naming the flag. -1 (the
// library's "none") used to read as no bump at all ("every amount given is
// 0" although the amount was 1), and a NaN amount got through to the rig's
// own check ("rig: module 1 right_from_left: contains NaN or Inf").
TEST(SimulateCli, BumpIndexAndAmountAreRefusedByTheFlagsName) {
  const std::string dir = ::testing::TempDir() + "/sim_bump_refused";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = " --out " + dir + "/ds --calibration-captures 0 --no-scenes";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {out + " --bump-camera -1 --bump-rotation-deg 1", "--bump-camera: no camera -1"},
      {out + " --bump-camera -2 --bump-translation-mm 1", "--bump-camera: no camera -2"},
      {out + " --bump-module -1 --bump-rotation-deg 1", "--bump-module: no module -1"},
      {out + " --bump-module 1 --bump-rotation-deg nan", "--bump-rotation-deg: must be within +-10"},
      {out + " --bump-module 1 --bump-translation-mm nan", "--bump-translation-mm: must be within +-10"},
      {out + " --bump-camera 1 --bump-rotation-deg -nan", "--bump-rotation-deg: must be within +-10"},
      {out + " --bump-camera 1 --bump-rotation-deg 11", "--bump-rotation-deg: must be within +-10"},
      {out + " --bump-camera 1 --bump-translation-mm -inf", "--bump-translation-mm: must be within +-10"}};
  ExpectEachRefusedBeforeAnyWork(cases, dir);
}

// Every bump amount's limit is in --help, on its flag's line, as the checks
// refuse it (docs/simulator.md says the same): the rotation and shift limits
// used to be found only by tripping over them.
TEST(SimulateCli, TheHelpGivesEveryBumpAmountsLimit) {
  const Result r = RunCli("simulate --help");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const auto& [flag, limit] :
       {std::pair{"--bump-rotation-deg", "within +-10"}, std::pair{"--bump-translation-mm", "within +-10"},
        std::pair{"--bump-focal-percent", "within +-10"}, std::pair{"--bump-principal-point-px", "within +-50"}}) {
    const size_t at = r.out.find(std::string("\n  ") + flag + " ");
    ASSERT_NE(at, std::string::npos) << flag << ": " << r.out;
    const size_t next_flag = r.out.find("\n  --", at + 1);
    EXPECT_NE(r.out.substr(at, next_flag - at).find(limit), std::string::npos) << flag << ": " << r.out;
  }
}

// A lens drift (--bump-focal-percent, --bump-principal-point-px) belongs to
// one camera and has a plausible size: anything else exits 2 before any
// work, one line naming the flag. A good one renders, and truth/rig.yaml and
// truth/simulation.yaml record the drifted lens.
TEST(SimulateCli, LensDriftIsValidatedAndRecordedInTheTruth) {
  const std::string dir = ::testing::TempDir() + "/sim_lens_drift";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = " --out " + dir + "/ds";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {out + " --bump-focal-percent 0.1", "--bump-focal-percent: needs --bump-camera"},
      {out + " --bump-principal-point-px 1 0", "--bump-principal-point-px: needs --bump-camera"},
      {out + " --bump-module 1 --bump-focal-percent 0.1", "--bump-focal-percent: needs --bump-camera"},
      {out + " --bump-camera 1 --bump-focal-percent 12", "--bump-focal-percent: must be within +-10"},
      {out + " --bump-camera 1 --bump-focal-percent -12", "--bump-focal-percent: must be within +-10"},
      {out + " --bump-camera 1 --bump-focal-percent nan", "--bump-focal-percent"},
      {out + " --bump-camera 1 --bump-principal-point-px 60 0", "--bump-principal-point-px: each of DX and DY"},
      {out + " --bump-camera 1 --bump-principal-point-px 0 -51", "--bump-principal-point-px: each of DX and DY"},
      {out + " --bump-camera 1 --bump-principal-point-px nan 0", "--bump-principal-point-px: each of DX and DY"},
      {out + " --bump-camera 1 --bump-principal-point-px 1", "--bump-principal-point-px"},
      {out + " --bump-camera 1 --bump-focal-percent 0", "--bump-camera: every amount given is 0"},
      {out + " --bump-camera 1 --bump-principal-point-px 0 0", "--bump-camera: every amount given is 0"},
      {out + " --bump-module 1 --bump-rotation-deg 0", "--bump-module: every amount given is 0"},
      {out + " --bump-camera 9 --bump-focal-percent 0.1 --calibration-captures 0 --no-scenes",
       "--bump-camera: no camera 9"},
      {" --write-default-spec " + dir + "/s.yaml --bump-focal-percent 1", "--bump-focal-percent: does not apply with"}};
  ExpectEachRefusedBeforeAnyWork(cases, dir);

  const Result r = RunCli("simulate" + out +
                          " --bump-camera 1 --bump-focal-percent 0.5 --bump-principal-point-px 1.5 -2"
                          " --calibration-captures 1 --no-scenes");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string info = Slurp(dir + "/ds/truth/simulation.yaml");
  EXPECT_NE(info.find("focal_percent: 0.5\n"), std::string::npos) << info;
  EXPECT_NE(info.find("principal_point_px: [1.5, -2]\n"), std::string::npos) << info;
  // truth/rig.yaml's drifted intrinsics: Simulate.ALensDriftChangesOnlyThatCamerasIntrinsics.
}

// --write-default-spec is checked like every command's output
// (apps/output_paths.h): over the --spec file given with it (an edited spec
// replaced by the default), directly or through a symbolic link, at a
// folder, or in a folder that is not there: exit 2, one line naming the
// path, the spec byte-identical and nothing written.
TEST(SimulateCli, WriteDefaultSpecRefusesTheSpecItWasGivenAndAFolder) {
  const std::string dir = ::testing::TempDir() + "/sim_write_spec";
  fs::remove_all(dir);
  fs::create_directories(dir + "/a_folder");
  const std::string spec = dir + "/edited.yaml";
  ASSERT_EQ(RunCli("simulate --write-default-spec " + spec).code, 0);
  std::string edited = Slurp(spec);
  const size_t at = edited.find("captures: 50");
  ASSERT_NE(at, std::string::npos) << "the default spec changed: edit another key";
  edited.replace(at, 12, "captures: 12");
  std::ofstream(spec) << edited;
  fs::create_symlink(spec, dir + "/link.yaml");
  const std::pair<std::string, std::string> cases[] = {
      {"--spec " + spec + " --write-default-spec " + spec, spec + ": is the spec file (--spec)"},
      {"--spec " + spec + " --write-default-spec " + dir + "/link.yaml", dir + "/link.yaml: is the spec file (--spec)"},
      {"--write-default-spec " + dir + "/a_folder", dir + "/a_folder: is a folder"},
      {"--write-default-spec " + dir + "/missing/s.yaml", dir + "/missing/s.yaml: its folder does not exist"},
      // A --spec beside it that is missing or a folder: refused as when it is
      // read (it was passed over, the default written, exit 0).
      {"--spec " + dir + "/no_spec.yaml --write-default-spec " + dir + "/w.yaml", dir + "/no_spec.yaml: no such file"},
      {"--spec " + dir + "/a_folder --write-default-spec " + dir + "/w.yaml", dir + "/a_folder: is a folder"}};
  for (const auto& [args, says] : cases) {
    const Result r = RunCli("simulate " + args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(Lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
  }
  EXPECT_EQ(Slurp(spec), edited);
  EXPECT_TRUE(fs::is_empty(dir + "/a_folder"));
  EXPECT_FALSE(fs::exists(dir + "/missing"));
  EXPECT_FALSE(fs::exists(dir + "/w.yaml"));
}

// --- Robustness walkthrough 44 (fuzz-bounds): the spec's projector, a piped spec ---

// The default spec's text with its first `from` replaced by `to`, written
// to `path` by `simulate --write-default-spec` first.
std::string EditedDefaultSpec(const std::string& path, const std::string& from, const std::string& to) {
  EXPECT_EQ(RunCli("simulate --write-default-spec " + path).code, 0);
  std::string text = Slurp(path);
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "the default spec changed: " << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

// A projector of 1000000000 lines was read and the dataset written, exit 0:
// lines that close merge into even light (datasets/sim_spec.cc). Refused
// naming the key, nothing written.
TEST(SimulateCli, AProjectorWhoseLinesMergeIsRefused) {
  const std::string dir = ::testing::TempDir() + "/sim_cli_lines_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir + "/out");
  const std::string spec = dir + "/lines.yaml";
  const std::string text = EditedDefaultSpec(spec, "lines: 51", "lines: 1000000000");
  std::ofstream(spec) << text;
  ExpectEachRefusedBeforeAnyWork({{" --spec " + spec + " --out " + dir + "/out/ds --calibration-captures 0 --no-scenes",
                                   spec + ": modules[0].projector: lines: 1000000000 lines over the fan stand"}},
                                 dir + "/out");
  fs::remove_all(dir);
}

// A cup 75 mm across typed in micrometres (75000) rendered for minutes,
// then aborted in std::bad_alloc (exit 134) sampling its truth surface
// every 0.2 mm. Each scene's size is held to 300 mm, refused naming the
// key before any work (here with --no-scenes, which read the spec whole
// and wrote the dataset).
TEST(SimulateCli, ASceneObjectLargerThanTheBeltTakesIsRefused) {
  const std::string dir = ::testing::TempDir() + "/sim_cli_sizes_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir + "/out");
  std::vector<std::pair<std::string, std::string>> cases;
  for (const auto& [from, to, says] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"cup_diameter_mm: 75", "cup_diameter_mm: 75000",
            "cup_diameter_mm: the cup is 75000 mm across, over "
            "the 300 mm a scene on the belt may be"},
           {"plate_size_mm: [130, 120, 8]", "plate_size_mm: [130, 301, 8]", "plate_size_mm: the plate is 301 mm"},
           // The bar's length is its distance plus a ball (25.4 mm): 280 + 25.4.
           {"ballbar_distance_mm: 80", "ballbar_distance_mm: 280",
            "ballbar_distance_mm: the ball bar (its distance plus a ball) is 305.4 mm"},
           // A ball typed in micrometres is named as the ball, not as a
           // distance (80 mm) short of it.
           {"ballbar_sphere_diameter_mm: 25.4", "ballbar_sphere_diameter_mm: 25400",
            "ballbar_sphere_diameter_mm: the ball bar (its distance plus a ball) is 25480 mm"},
           // The longest axis with its bumps (0.05 by default): 2 x 143 x 1.05.
           {"tuber_semi_axes_mm: [42, 30, 27]", "tuber_semi_axes_mm: [143, 30, 27]",
            "tuber_semi_axes_mm: the tuber (its longest axis with its bumps) is 300.3 mm"}}) {
    const std::string spec = dir + "/" + std::to_string(cases.size()) + ".yaml";
    const std::string text = EditedDefaultSpec(spec, from, to);  // before the stream opens it
    std::ofstream(spec) << text;
    cases.push_back({" --spec " + spec + " --out " + dir + "/out/ds --calibration-captures 0 --no-scenes",
                     spec + ": scenes: " + says});
  }
  ExpectEachRefusedBeforeAnyWork(cases, dir + "/out");
  // At the bound itself each is read and the dataset written: a plate 300 mm
  // long, a bar of 274.6 + 25.4 mm, a tuber of 2 x 142 x 1.05 = 298.2 mm.
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"plate_size_mm: [130, 120, 8]", "plate_size_mm: [130, 300, 8]"},
           {"ballbar_distance_mm: 80", "ballbar_distance_mm: 274.6"},
           {"tuber_semi_axes_mm: [42, 30, 27]", "tuber_semi_axes_mm: [142, 30, 27]"}}) {
    const std::string spec = dir + "/at_bound.yaml";
    const std::string text = EditedDefaultSpec(spec, from, to);
    std::ofstream(spec) << text;
    fs::remove_all(dir + "/out/ds");
    const Result r =
        RunCli("simulate --spec " + spec + " --out " + dir + "/out/ds --calibration-captures 0 --no-scenes");
    EXPECT_EQ(r.code, 0) << to << ": " << r.err;
  }
  fs::remove_all(dir);
}

// --spec as a pipe (`--spec <(...)`, /dev/stdin) was refused ("not a
// regular file") though the spec is read once, start to end, as --options
// and a rig file given so are.
TEST(SimulateCli, ASpecFromAPipeIsRead) {
  const std::string dir = ::testing::TempDir() + "/sim_cli_pipe_" + std::to_string(getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string text = EditedDefaultSpec(dir + "/spec.yaml", "captures: 50", "captures: 1");
  const std::string fifo = dir + "/spec.fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::atomic<bool> written{false};
  std::thread writer([&] {  // blocks until a reader opens the pipe
    std::ofstream(fifo) << text;
    written = true;
  });
  const Result r = RunCli("simulate --spec " + fifo + " --out " + dir + "/ds --no-scenes");
  const int release = written ? -1 : open(fifo.c_str(), O_RDONLY | O_NONBLOCK);  // if simulate never opened it
  writer.join();
  if (release >= 0) close(release);
  ASSERT_EQ(r.code, 0) << r.err;
  // The spec read from the pipe is the one rendered: its one capture.
  EXPECT_TRUE(fs::exists(dir + "/ds/calibration/000/cam3.png"));
  EXPECT_FALSE(fs::exists(dir + "/ds/calibration/001"));
  fs::remove_all(dir);
}

}  // namespace
