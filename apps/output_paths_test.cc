#include "apps/output_paths.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <grp.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "calib/core/input_error.h"
#include "calib/core/input_error_testing.h"

namespace stereorig {
namespace {

namespace fs = std::filesystem;

using testing::InputErrorMessage;

std::string Scratch(const std::string& name) { return testing::ScratchFolder("output_paths_" + name); }

// A folder whose name is longer than the file system allows (255 on ext4)
// is refused by the claim itself, naming the path and the problem, before
// the command does any work: it used to be found only by Create, after it.
// Nothing is made. (A folder this process may not write in: below.)
TEST(OutputPaths, AFolderNameTooLongForTheFileSystemIsRefusedWhenClaimed) {
  const std::string dir = Scratch("long_folder");
  const long name_max = pathconf(dir.c_str(), _PC_NAME_MAX);
  ASSERT_GT(name_max, 0) << "a file system without a name limit: nothing to test";
  const std::string too_long(name_max + 1, 'x');
  for (const std::string& folder : {dir + "/" + too_long, dir + "/new/" + too_long + "/deeper"}) {
    const std::string says = InputErrorMessage([&] { (void)OutputPaths().ClaimFolder(folder, "the test folder"); });
    EXPECT_EQ(says.rfind(folder + ": cannot create this folder for the test folder: File name too long", 0), 0u)
        << says;
    EXPECT_NE(says.find(std::to_string(name_max + 1) + " characters"), std::string::npos) << says;
  }
  EXPECT_FALSE(fs::exists(dir + "/new"));
  // A name of the longest length allowed is claimed, and made.
  FolderToCreate longest = OutputPaths().ClaimFolder(dir + "/new/" + std::string(name_max, 'y'), "the test folder");
  longest.Create();
  EXPECT_TRUE(fs::is_directory(dir + "/new/" + std::string(name_max, 'y')));
}

// The same test for a file claimed: its own name, in an existing folder or
// in one the command creates (claimed without the folder test).
TEST(OutputPaths, AFileNameTooLongForTheFileSystemIsRefusedWhenClaimed) {
  const std::string dir = Scratch("long_file");
  const long name_max = pathconf(dir.c_str(), _PC_NAME_MAX);
  ASSERT_GT(name_max, 0) << "a file system without a name limit: nothing to test";
  const std::string too_long = std::string(name_max - 4, 'x') + ".json";
  const std::string file = dir + "/" + too_long;
  std::string says = InputErrorMessage([&] { OutputPaths().Claim(file, "the report (--report)"); });
  EXPECT_EQ(says.rfind(file + ": cannot write the report (--report): File name too long", 0), 0u) << says;
  OutputPaths outputs;
  (void)outputs.ClaimFolder(dir + "/out", "the output folder");
  says = InputErrorMessage([&] { outputs.Claim(dir + "/out/" + too_long, "a capture's report", false); });
  EXPECT_NE(says.find("cannot write a capture's report: File name too long"), std::string::npos) << says;
  EXPECT_EQ(InputErrorMessage([&] { outputs.Claim(dir + "/out/" + too_long.substr(1), "a capture's report", false); }),
            "");
}

// Returned by ClaimAsUnprivileged when root cannot become another user
// (a user namespace without uid 65534): nothing can be tested.
constexpr char kNoUnprivilegedUser[] = "could not become user 65534";

// The message of the InputError `claim` throws in a process that is not
// root, "" if it throws none. Root (as in CI) may write in any folder
// (access() grants it everything), so then the claim runs in a forked child
// that first becomes the unprivileged user 65534 (nobody, no supplementary
// groups) and sends the message back through a pipe.
std::string ClaimAsUnprivileged(const std::function<void()>& claim) {
  if (geteuid() != 0) return InputErrorMessage(claim);
  int fds[2];
  if (pipe(fds) != 0) return "pipe failed";
  const pid_t pid = fork();
  if (pid < 0) return "fork failed";
  if (pid == 0) {
    close(fds[0]);
    std::string message;
    if (setgroups(0, nullptr) != 0 || setgid(65534) != 0 || setuid(65534) != 0) {
      message = kNoUnprivilegedUser;
    } else {
      try {
        message = InputErrorMessage(claim);
      } catch (...) {
        message = "another exception";
      }
    }
    const ssize_t written = write(fds[1], message.data(), message.size());
    _exit(written == static_cast<ssize_t>(message.size()) ? 0 : 1);
  }
  close(fds[1]);
  std::string message;
  char buffer[512];
  for (;;) {
    const ssize_t n = read(fds[0], buffer, sizeof buffer);
    if (n > 0) {
      message.append(buffer, size_t(n));
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  close(fds[0]);
  int status = 0;
  pid_t waited;
  do waited = waitpid(pid, &status, 0);
  while (waited < 0 && errno == EINTR);
  EXPECT_EQ(waited, pid);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  return message;
}

// A file claimed in a folder this process may not write in, or a folder to
// create there, is refused when claimed, naming the path and the reason,
// not after the command's work when the file is written. The same claims
// in a folder anyone may write in pass (the control).
// "-" as an output folder (reconstruct --out-dir -, --rectified-out -) made
// a folder of that name, where standard output is the usual reading, as a
// file output's "-" is refused (RequireReplaceableOutput).
TEST(OutputPaths, ADashIsRefusedAsAFolderAsAsAFile) {
  EXPECT_NE(InputErrorMessage([] {
              (void)OutputPaths().ClaimFolder("-", "the output folder");
            }).find("-: outputs are folders and files, not standard output"),
            std::string::npos);
  EXPECT_NE(InputErrorMessage([] { OutputPaths().Claim("-", "the report"); }).find("-: outputs are files"),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists("-"));
}

TEST(OutputPaths, AFolderThisProcessMayNotWriteInIsRefusedWhenClaimed) {
  // In /tmp, not the build tree: user 65534 must be able to reach the
  // folders, and a checkout may lie below a folder only root may enter
  // (/root, mode 0700).
  char templ[] = "/tmp/stereorig_output_paths_XXXXXX";
  ASSERT_NE(mkdtemp(templ), nullptr) << std::strerror(errno);
  const std::string dir = templ;
  fs::permissions(dir, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec | fs::perms::others_read |
                           fs::perms::others_exec);
  struct Cleanup {
    std::string dir;
    ~Cleanup() {
      std::error_code ignored;
      fs::permissions(dir + "/locked", fs::perms::owner_all, ignored);
      fs::remove_all(dir, ignored);
    }
  } cleanup{dir};
  const std::string locked = dir + "/locked", open = dir + "/open";
  fs::create_directories(locked);
  fs::create_directories(open);
  std::ofstream(locked + "/target.ply") << "an earlier cloud\n";  // a link's target, below
  fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                              fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  fs::permissions(open, fs::perms::all);
  const std::string locked_normal = fs::path(locked).lexically_normal().string();  // as messages name it
  std::string says = ClaimAsUnprivileged([&] { OutputPaths().Claim(locked + "/cloud.ply", "the cloud (--out)"); });
  if (says == kNoUnprivilegedUser) GTEST_SKIP() << "root cannot become user 65534 here: nothing to test";
  EXPECT_EQ(says, locked + "/cloud.ply: cannot write the cloud (--out) in its folder " + locked_normal + ": " +
                      std::strerror(EACCES));
  says = ClaimAsUnprivileged([&] { (void)OutputPaths().ClaimFolder(locked + "/new", "the output folder"); });
  EXPECT_EQ(says.rfind(locked + "/new: cannot create this folder for the output folder: " + locked_normal + ": ", 0),
            0u)
      << says;
  EXPECT_EQ(ClaimAsUnprivileged([&] { OutputPaths().Claim(open + "/cloud.ply", "the cloud (--out)"); }), "");
  EXPECT_EQ(ClaimAsUnprivileged([&] { (void)OutputPaths().ClaimFolder(open + "/new", "the output folder"); }), "");
  EXPECT_FALSE(fs::exists(open + "/new"));  // a claim makes nothing
  // A path through a link to a file is written in the link's folder (a
  // temporary file renamed over the link): that folder is the one checked.
  fs::create_symlink(locked + "/target.ply", open + "/link.ply");
  EXPECT_EQ(ClaimAsUnprivileged([&] { OutputPaths().Claim(open + "/link.ply", "the cloud (--out)"); }), "");
}

// access(W_OK) says yes to root in /sys, where no file can be made: a
// calibration with --report /sys/r.json ran its whole solve and only then
// failed. The claim now creates (and removes) a file there, so the refusal
// comes first, as root too; and a claim that succeeds leaves nothing behind.
TEST(OutputPaths, AFolderNoFileCanBeMadeInIsRefusedWhenClaimedAsRootToo) {
  ASSERT_TRUE(fs::is_directory("/sys")) << "no /sys: nothing to test";
  const std::string says = InputErrorMessage([] { OutputPaths().Claim("/sys/report.json", "the report (--report)"); });
  EXPECT_EQ(says.rfind("/sys/report.json: cannot write the report (--report) in its folder /sys: ", 0), 0u) << says;
  const std::string dir = Scratch("probe_leaves_nothing");
  OutputPaths().Claim(dir + "/cloud.ply", "the cloud (--out)");
  EXPECT_TRUE(fs::is_empty(dir)) << "the claim's trial file was left in " << dir;
}

}  // namespace
}  // namespace stereorig
