#include "calib/core/atomic_file.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "calib/core/input_error_testing.h"

namespace stereorig {
namespace {

std::string Contents(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The names in `dir`, temporary files (".tmp-...") included.
std::vector<std::string> Names(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(AtomicOutputSet, CommitWritesEveryOutput) {
  const std::string dir = testing::ScratchFolder("atomic_set_commit");
  AtomicOutputSet outputs;
  outputs.Add(dir + "/a.ply", "cloud");
  outputs.Add(dir + "/b.json", "report");
  EXPECT_TRUE(Contents(dir + "/a.ply").empty()) << "nothing at the output paths before Commit";
  outputs.Commit();
  EXPECT_EQ(Contents(dir + "/a.ply"), "cloud");
  EXPECT_EQ(Contents(dir + "/b.json"), "report");
  EXPECT_EQ(Names(dir), (std::vector<std::string>{"a.ply", "b.json"}));  // no temporary file left
}

// A later output that cannot be written leaves the earlier run's files as
// they were and no temporary file: not the first output new and the others
// old. The later output's folder is one where no file can be created, not
// even by root (as a full disk fails a write, after the earlier output's
// temporary file is written): /sys (/proc is refused before, as a place of
// streams: RequireReplaceableOutput).
TEST(AtomicOutputSet, AFailingOutputLeavesEveryEarlierFileAsItWas) {
  const std::string dir = testing::ScratchFolder("atomic_set_fail");
  WriteFileAtomically(dir + "/a.ply", "old cloud");
  const std::string unwritable = "/sys/stereorig-atomic-set-test.json";
  {
    AtomicOutputSet outputs;
    outputs.Add(dir + "/a.ply", "new cloud");
    EXPECT_NE(
        testing::InputErrorMessage([&] { outputs.Add(unwritable, "report"); }).find(unwritable + ": cannot write"),
        std::string::npos);
  }  // not committed
  EXPECT_EQ(Contents(dir + "/a.ply"), "old cloud");
  EXPECT_EQ(Names(dir), std::vector<std::string>{"a.ply"});
}

// A rename that fails within Commit (here onto a folder that holds a file;
// in use: an immutable or busy file) puts back what the renames before it
// replaced and removes what they added: the earlier run's files as they were,
// and nothing else left (no temporary file, no kept copy).
TEST(AtomicOutputSet, ARenameThatFailsPutsTheEarlierFilesBack) {
  const std::string dir = testing::ScratchFolder("atomic_set_rename_fails");
  WriteFileAtomically(dir + "/a.ply", "old cloud");
  std::filesystem::create_directory(dir + "/busy");
  WriteFileAtomically(dir + "/busy/inside", "x");
  AtomicOutputSet outputs;
  outputs.Add(dir + "/a.ply", "new cloud");
  outputs.Add(dir + "/b.json", "new report");
  outputs.Add(dir + "/busy", "cannot replace a folder");
  EXPECT_NE(testing::InputErrorMessage([&] { outputs.Commit(); }).find(dir + "/busy: cannot write"), std::string::npos);
  EXPECT_EQ(Contents(dir + "/a.ply"), "old cloud");
  EXPECT_EQ(Names(dir), (std::vector<std::string>{"a.ply", "busy"}));
  EXPECT_EQ(Names(dir + "/busy"), std::vector<std::string>{"inside"});
}

TEST(WriteFileAtomically, ReplacesTheFileAndLeavesNoTemporaryFile) {
  const std::string dir = testing::ScratchFolder("atomic_write");
  WriteFileAtomically(dir + "/r.json", "first");
  WriteFileAtomically(dir + "/r.json", "second");
  EXPECT_EQ(Contents(dir + "/r.json"), "second");
  EXPECT_EQ(Names(dir), std::vector<std::string>{"r.json"});
  EXPECT_NE(testing::InputErrorMessage([&] {
              WriteFileAtomically(dir + "/no_such_folder/r.json", "x");
            }).find("does not exist"),
            std::string::npos);
}

// Any name the file system takes is written, up to its 255 bytes. (Before,
// the temporary file's name, ".tmp-<pid>-<n>-" before the output's, passed
// 255 for a name of about 235 bytes, and the write failed with "File name
// too long".) The temporary file keeps the extension: writers that pick the
// format by it (cv::imwrite) still work.
TEST(WriteFileAtomically, ANameOfUpTo255BytesIsWritten) {
  const std::string dir = testing::ScratchFolder("atomic_long_name");
  for (const size_t name_bytes : {236u, 250u, 255u}) {
    const std::string name = std::string(name_bytes - 5, 'r') + ".json";
    WriteFileAtomically(dir + "/" + name, "report " + std::to_string(name_bytes));
    EXPECT_EQ(Contents(dir + "/" + name), "report " + std::to_string(name_bytes));
    AtomicOutputSet outputs;
    outputs.Add(dir + "/" + name, "again");
    outputs.Add(dir + "/a.ply", "cloud");
    outputs.Commit();
    EXPECT_EQ(Contents(dir + "/" + name), "again");
    EXPECT_EQ(Names(dir), (std::vector<std::string>{"a.ply", name}));  // no temporary file, no kept copy
    std::filesystem::remove(dir + "/" + name);
  }
  const AtomicOutput image(dir + "/" + std::string(251, 'i') + ".png");
  EXPECT_EQ(std::filesystem::path(image.temp_path()).extension(), ".png");
  EXPECT_LE(std::filesystem::path(image.temp_path()).filename().string().size(), 255u);
}

// A name longer than the file system takes is still refused by it, in the
// same words, and leaves nothing.
TEST(WriteFileAtomically, ANameLongerThan255BytesIsRefused) {
  const std::string dir = testing::ScratchFolder("atomic_too_long_name");
  const std::string path = dir + "/" + std::string(251, 'r') + ".json";
  EXPECT_NE(testing::InputErrorMessage([&] {
              WriteFileAtomically(path, "x");
            }).find(path + ": cannot write: File name too long"),
            std::string::npos);
  EXPECT_TRUE(Names(dir).empty());
}

// A FIFO (or a device: /dev/null as an output) at an output path is refused,
// and left a FIFO: the temporary file renamed over it would have replaced the
// node with a regular file (as root, a system device). "-" is refused too
// (a file of that name, where standard output is meant).
TEST(WriteFileAtomically, ADevicePipeOrDashIsRefusedAndLeftAsItWas) {
  const std::string dir = testing::ScratchFolder("atomic_fifo");
  const std::string fifo = dir + "/report.json";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string message = testing::InputErrorMessage([&] { WriteFileAtomically(fifo, "{}"); });
  EXPECT_NE(message.find(fifo + ": is a pipe (FIFO), not a file"), std::string::npos) << message;
  EXPECT_TRUE(std::filesystem::is_fifo(fifo));
  EXPECT_EQ(Names(dir), (std::vector<std::string>{"report.json"}));  // no temporary file left
  EXPECT_NE(testing::InputErrorMessage([&] { RequireReplaceableOutput("/dev/null"); }).find("/dev/null: is a device"),
            std::string::npos);
  EXPECT_NE(testing::InputErrorMessage([&] { RequireReplaceableOutput("-"); }).find("-: outputs are files"),
            std::string::npos);
  EXPECT_EQ(testing::InputErrorMessage([&] { RequireReplaceableOutput(dir + "/new.json"); }), "");
  // A link to the FIFO means that stream (as /dev/stdout does): the rename
  // would replace the link. A link to nothing is a file to write.
  std::filesystem::create_symlink(fifo, dir + "/stdout");
  EXPECT_NE(testing::InputErrorMessage([&] {
              WriteFileAtomically(dir + "/stdout", "{}");
            }).find("/stdout: is a link to a pipe (FIFO), not a file"),
            std::string::npos);
  EXPECT_TRUE(std::filesystem::is_symlink(dir + "/stdout"));
  std::filesystem::create_symlink(dir + "/nothing.json", dir + "/dangling");
  EXPECT_EQ(testing::InputErrorMessage([&] { RequireReplaceableOutput(dir + "/dangling"); }), "");
}

// A symbolic link at an output path is replaced by the file (the rename's
// way); the file it pointed to is left as it was.
TEST(WriteFileAtomically, ALinkIsReplacedAndItsTargetLeftAsItWas) {
  const std::string dir = testing::ScratchFolder("atomic_link");
  { std::ofstream(dir + "/target.json") << "old"; }
  std::filesystem::create_symlink("target.json", dir + "/link.json");
  WriteFileAtomically(dir + "/link.json", "new");
  EXPECT_FALSE(std::filesystem::is_symlink(dir + "/link.json"));
  EXPECT_EQ(Contents(dir + "/link.json"), "new");
  EXPECT_EQ(Contents(dir + "/target.json"), "old");
}

// A link into /proc or /dev at an output path is refused whatever it points
// to now, and left a link: /dev/stdout, /dev/fd/1 and /proc/self/fd/1 are
// links to a stream's file too, when it is redirected to one (cron's
// "--report /dev/stdout >> log"), and the rename replaced the link with the
// report, as root /dev/stdout itself. Tried here on links in a scratch
// folder to a file this test holds open (never on the real /dev/stdout);
// a path in /dev or /proc is only checked (RequireReplaceableOutput writes
// nothing). /dev/shm, a folder for files, is not refused.
TEST(WriteFileAtomically, ALinkIntoProcOrDevIsRefusedWhateverItPointsTo) {
  const std::string dir = testing::ScratchFolder("atomic_stream_link");
  const std::string log = dir + "/log.txt";
  WriteFileAtomically(log, "log\n");
  const int fd = open(log.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  const std::string n = std::to_string(fd);
  std::filesystem::create_symlink("/proc/self/fd/" + n, dir + "/stdout");  // a stdout redirected to log.txt
  std::filesystem::create_symlink("/dev/fd/" + n, dir + "/fd");
  std::filesystem::create_symlink("stdout", dir + "/chain");       // a link to such a link
  std::filesystem::create_symlink("/proc/self/fd", dir + "/fds");  // a folder link: fds/N
  const std::pair<std::string, std::string> refused[] = {
      {dir + "/stdout", "leads to /proc/self/fd/" + n + " through a symbolic link, in /dev or /proc"},
      {dir + "/fd", "leads to /dev/fd/" + n + " through a symbolic link, in /dev or /proc"},
      {dir + "/chain", "leads to /proc/self/fd/" + n + " through a symbolic link, in /dev or /proc"},
      {dir + "/fds/" + n, "leads to /proc/" + std::to_string(getpid()) + "/fd/" + n + " through a symbolic link"}};
  for (const auto& [path, says] : refused) {
    const std::string message = testing::InputErrorMessage([&] { WriteFileAtomically(path, "{}"); });
    EXPECT_NE(message.find(path + ": " + says), std::string::npos) << message;
    EXPECT_NE(message.find("name a regular file"), std::string::npos) << message;
  }
  // The links themselves, a new name in /dev too.
  for (const std::string& path : {"/proc/self/fd/" + n, "/dev/fd/" + n, std::string("/dev/stereorig-new-output.json")})
    EXPECT_NE(testing::InputErrorMessage([&] { RequireReplaceableOutput(path); }).find(path + ": is in /dev or /proc"),
              std::string::npos)
        << path;
  close(fd);
  EXPECT_TRUE(std::filesystem::is_symlink(dir + "/stdout"));
  EXPECT_TRUE(std::filesystem::is_symlink(dir + "/fd"));
  EXPECT_TRUE(std::filesystem::is_symlink(dir + "/chain"));
  EXPECT_EQ(Contents(log), "log\n");
  EXPECT_EQ(Names(dir), (std::vector<std::string>{"chain", "fd", "fds", "log.txt", "stdout"}));  // no temporary file
  if (std::filesystem::is_directory("/dev/shm") && !std::filesystem::is_symlink("/dev/shm")) {
    EXPECT_EQ(testing::InputErrorMessage([&] { RequireReplaceableOutput("/dev/shm/stereorig-output.json"); }), "");
  }
}

// A ".." after a link is the link target's parent, as the kernel takes it:
// not collapsed with the link before the link is resolved. With a link to
// /proc/self (or /dev/fd, /dev/shm), "link/../name" is in /proc (or /dev),
// where "name" beside the link is not; it was checked as the latter and
// written, the rename replacing what was there. Only the check is called
// here: nothing in /proc or /dev is written.
TEST(RequireReplaceableOutput, AParentStepAfterALinkIsTakenWhereTheLinkLeads) {
  const std::string dir = testing::ScratchFolder("atomic_link_parent_step");
  std::filesystem::create_symlink("/proc/self", dir + "/self");
  std::filesystem::create_symlink("/dev/fd", dir + "/fd");  // -> /proc/self/fd: its parent is /proc/<pid>
  const std::string pid = std::to_string(getpid());
  const std::pair<std::string, std::string> refused[] = {
      {dir + "/self/../stereorig-new-output.json", "leads to /proc/stereorig-new-output.json through a symbolic link"},
      {dir + "/fd/../stdout", "leads to /proc/" + pid + "/stdout through a symbolic link"}};
  for (const auto& [path, says] : refused) {
    const std::string message = testing::InputErrorMessage([&] { RequireReplaceableOutput(path); });
    EXPECT_NE(message.find(path + ": " + says), std::string::npos) << message;
  }
  if (std::filesystem::is_directory("/dev/shm") && !std::filesystem::is_symlink("/dev/shm")) {
    std::filesystem::create_symlink("/dev/shm", dir + "/shm");
    const std::string path = dir + "/shm/../stereorig-new-output.json";
    EXPECT_NE(testing::InputErrorMessage([&] {
                RequireReplaceableOutput(path);
              }).find(path + ": leads to /dev/stereorig-new-output.json through a symbolic link"),
              std::string::npos);
  }
  // A scratch folder standing in: "link/../x.json" is written in the link
  // target's parent, where the check looked; a ".." written in /dev that
  // leaves it is no refusal.
  std::filesystem::create_directories(dir + "/real/deeper");
  std::filesystem::create_symlink("real/deeper", dir + "/link");
  WriteFileAtomically(dir + "/link/../x.json", "{}");
  EXPECT_EQ(Contents(dir + "/real/x.json"), "{}");
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.json"));
  EXPECT_EQ(testing::InputErrorMessage([&] { RequireReplaceableOutput("/dev/.." + dir + "/y.json"); }), "");
}

// Stand-ins for a file system with neither renameat2's flags nor hard links
// (some FUSE mounts: sshfs, SMB, WSL's drvfs): a call failing with `kErrno`.
template <int kErrno>
int FailsWith(const char*, const char*) {
  errno = kErrno;
  return -1;
}
constexpr PathCall NoFlags = FailsWith<EINVAL>;
constexpr PathCall NoHardLinks = FailsWith<EPERM>;
constexpr PathCall NoLinksAcrossFuse = FailsWith<EXDEV>;
constexpr PathCall NotSupported = FailsWith<EOPNOTSUPP>;
constexpr PathCall NoAccess = FailsWith<EACCES>;

// There a commit that must not replace checks the name free, then renames:
// every capture of a stream on such a mount failed "cannot write:
// Operation not permitted" instead.
TEST(RenameWithoutReplacing, WithoutItsAtomicWaysAFreeNameIsStillWrittenATakenOneNot) {
  const std::string dir = testing::ScratchFolder("atomic_no_replace_fallback");
  const std::string from = dir + "/.tmp-new";
  for (PathCall no_link : {NoHardLinks, NoLinksAcrossFuse, NotSupported}) {
    WriteFileAtomically(from, "new");
    const std::string to = dir + "/free-" + std::to_string(Names(dir).size()) + ".json";
    EXPECT_EQ(RenameWithoutReplacing(from.c_str(), to.c_str(), NoFlags, no_link), 0);
    EXPECT_EQ(Contents(to), "new");
    EXPECT_FALSE(std::filesystem::exists(from));
  }
  for (PathCall no_rename : {NoFlags, NotSupported}) {  // and a dangling link is a name taken
    WriteFileAtomically(dir + "/taken.json", "theirs");
    std::filesystem::remove(dir + "/dangling.json");
    std::filesystem::create_symlink("nothing", dir + "/dangling.json");
    WriteFileAtomically(from, "new");
    for (const std::string& to : {dir + "/taken.json", dir + "/dangling.json"})
      EXPECT_EQ(RenameWithoutReplacing(from.c_str(), to.c_str(), no_rename, NoHardLinks), EEXIST) << to;
    EXPECT_EQ(Contents(dir + "/taken.json"), "theirs");
    EXPECT_TRUE(std::filesystem::is_symlink(dir + "/dangling.json"));
    EXPECT_EQ(Contents(from), "new");
  }
  // Any other error is this call's: returned, nothing renamed.
  EXPECT_EQ(RenameWithoutReplacing(from.c_str(), (dir + "/other.json").c_str(), NoFlags, NoAccess), EACCES);
  EXPECT_EQ(RenameWithoutReplacing(from.c_str(), (dir + "/other.json").c_str(), NoAccess, NoHardLinks), EACCES);
  EXPECT_FALSE(std::filesystem::exists(dir + "/other.json"));
  EXPECT_EQ(Contents(from), "new");
  // The system's own calls, here (tmpfs or ext4) atomic.
  EXPECT_EQ(RenameWithoutReplacing(from.c_str(), (dir + "/taken.json").c_str()), EEXIST);
  EXPECT_EQ(RenameWithoutReplacing(from.c_str(), (dir + "/other.json").c_str()), 0);
  EXPECT_EQ(Contents(dir + "/other.json"), "new");
}

// Committed without replacing (AtExisting::kRefuse, a reconstruct stream's
// outputs): a name another process made between this run's check that it
// is free and the commit is refused, "exists already", and left as it was;
// what the set committed before it is removed again, so it leaves no output
// of its own. (Two streams sharing an --out-dir each found a capture's
// names free, and the later rename silently replaced the other's.)
TEST(AtomicOutputSet, ACommitThatMustNotReplaceRefusesANameMadeMeanwhile) {
  const std::string dir = testing::ScratchFolder("atomic_set_no_replace");
  {
    AtomicOutputSet outputs;
    outputs.Add(dir + "/a.ply", "this run's cloud");
    outputs.Add(dir + "/a.json", "this run's report");
    WriteFileAtomically(dir + "/a.json", "the other run's report");  // after the check, before the commit
    const std::string message = testing::InputErrorMessage([&] { outputs.Commit(AtExisting::kRefuse); });
    EXPECT_NE(message.find(dir + "/a.json: exists already, not replaced"), std::string::npos) << message;
    EXPECT_EQ(Contents(dir + "/a.json"), "the other run's report");
    EXPECT_EQ(Names(dir), std::vector<std::string>{"a.json"});  // this run's cloud removed, no temporary file
  }
  {
    // The first output taken: the set writes nothing, the other's files as
    // they were; a link to nothing is a name taken too (not followed).
    WriteFileAtomically(dir + "/b.ply", "the other run's cloud");
    std::filesystem::create_symlink("nothing", dir + "/c.ply");
    for (const std::string stem : {"/b", "/c"}) {
      AtomicOutputSet outputs;
      outputs.Add(dir + stem + ".ply", "this run's cloud");
      outputs.Add(dir + stem + ".json", "this run's report");
      EXPECT_NE(testing::InputErrorMessage([&] {
                  outputs.Commit(AtExisting::kRefuse);
                }).find(dir + stem + ".ply: exists already, not replaced"),
                std::string::npos);
    }
    EXPECT_EQ(Contents(dir + "/b.ply"), "the other run's cloud");
    EXPECT_TRUE(std::filesystem::is_symlink(dir + "/c.ply"));
    EXPECT_EQ(Names(dir), (std::vector<std::string>{"a.json", "b.ply", "c.ply"}));
  }
  AtomicOutputSet outputs;  // names that are free: written
  outputs.Add(dir + "/d.ply", "cloud");
  outputs.Add(dir + "/d.json", "report");
  outputs.Commit(AtExisting::kRefuse);
  EXPECT_EQ(Contents(dir + "/d.ply"), "cloud");
  EXPECT_EQ(Contents(dir + "/d.json"), "report");
  EXPECT_EQ(Names(dir), (std::vector<std::string>{"a.json", "b.ply", "c.ply", "d.json", "d.ply"}));
}

}  // namespace
}  // namespace stereorig
