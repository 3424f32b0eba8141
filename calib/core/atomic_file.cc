#include "atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "input_error.h"
#include "temporary_name.h"

namespace stereorig {

namespace {

// ".tmp-<pid>-<n>-<name>" beside `path`: unique by the pid and counter,
// hidden, and of any length the file system takes (the name shortened).
std::string MakeTempPath(const std::string& path) {
  static std::atomic<int> counter{0};
  const std::filesystem::path p(path);
  const std::string tag = ".tmp-" + std::to_string(getpid()) + "-" + std::to_string(counter++) + "-";
  return (p.parent_path() / TemporaryName(tag, p.filename().string())).string();
}

}  // namespace

std::string CannotCreateBeside(const std::string& path) {
  const std::string probe = MakeTempPath(path);
  const PendingTemporary pending(probe);  // a signal now removes it too
  const int fd = open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) return std::strerror(errno);
  close(fd);
  std::remove(probe.c_str());
  return "";
}

namespace {

// /dev and /proc hold the system's devices and each process's streams, never
// an output. /dev/shm is the exception: a folder for files (tmpfs).
bool InSystemFolder(const std::filesystem::path& absolute) {
  auto part = absolute.begin();
  if (part == absolute.end() || *part != "/" || ++part == absolute.end()) return false;
  if (*part == "proc") return true;
  return *part == "dev" && !(++part != absolute.end() && *part == "shm");
}

// True if `p` has a ".." part: what it names is known only once the links
// before it are resolved (the kernel's order: "link/.." is the link
// target's parent, not the link's folder).
bool HasParentStep(const std::filesystem::path& p) {
  for (const auto& part : p)
    if (part == "..") return true;
  return false;
}

// The first place on the way from `path` to the file it names that lies in
// /dev or /proc (InSystemFolder), "" if none: the path itself, as written
// (where no ".." makes that differ from what it names) and with the folders
// above it resolved, then each symbolic link's target in turn. Whatever the
// last link points to now does not matter: /dev/stdout, /dev/fd/1 and
// /proc/self/fd/1 are links to what a stream is at the moment, a log file
// too when it is redirected (cron's ">> log"). Never collapsed lexically
// before its links are resolved: with a -> /dev/shm, "a/../stdout" is
// /dev/stdout, not "./stdout".
std::string SystemPlaceOnTheWay(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  for (int hops = 0; !ec && hops < 40; ++hops) {  // 40: the kernel's own limit (ELOOP)
    if (!HasParentStep(p) && InSystemFolder(p.lexically_normal())) return p.lexically_normal().string();
    if (p.filename() == ".." || p.filename() == ".") p = fs::weakly_canonical(p, ec);  // no link at its end
    if (ec) break;
    const fs::path folder = fs::weakly_canonical(p.parent_path(), ec);  // links resolved as the kernel does
    if (ec) break;
    p = folder / p.filename();
    if (InSystemFolder(p)) return p.string();
    struct stat st {};
    if (lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) break;
    p = folder / fs::read_symlink(p, ec);  // an absolute target replaces the folder
  }
  return "";
}

}  // namespace

void RequireReplaceableOutput(const std::string& path) {
  if (path == "-")
    throw InputError(path, "outputs are files, not standard output: name the file (./- for a file called '-')");
  const std::string replaced =
      ", not a file: an output is written beside its path and renamed over it, which would replace it; name a "
      "regular file";
  auto kind = [](const struct stat& st) -> const char* {
    return S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device"
           : S_ISFIFO(st.st_mode)                     ? "a pipe (FIFO)"
           : S_ISSOCK(st.st_mode)                     ? "a socket"
                                                      : nullptr;
  };
  struct stat st {};
  if (lstat(path.c_str(), &st) == 0) {
    const char* what = kind(st);
    // A link to one (/dev/stdout, /proc/self/fd/1) means that stream: the
    // rename would replace the link, a system one in /dev.
    struct stat target {};
    const bool link_to_stream =
        what == nullptr && S_ISLNK(st.st_mode) && stat(path.c_str(), &target) == 0 && kind(target) != nullptr;
    if (link_to_stream) what = kind(target);
    if (what != nullptr)
      throw InputError(path, std::string(link_to_stream ? "is a link to " : "is ") + what + replaced);
  }
  // Nothing there yet, or a file or a link to one: refused too if it is, or
  // leads through, a place in /dev or /proc. A stream redirected to a file
  // is a link to that file there (/dev/stdout in a cron job's "--report
  // /dev/stdout >> log"): the rename replaced /dev/stdout itself.
  const std::string system_place = SystemPlaceOnTheWay(path);
  if (!system_place.empty()) {
    std::error_code ec;
    const bool itself = std::filesystem::path(system_place) == std::filesystem::absolute(path, ec).lexically_normal();
    const std::string where =
        itself ? "is in /dev or /proc" : "leads to " + system_place + " through a symbolic link, in /dev or /proc";
    throw InputError(path, where +
                               ": they hold the system's devices and the processes' streams (/dev/stdout: whatever "
                               "standard output is now, a file it is redirected to too), never an output; the rename "
                               "that writes an output would replace " +
                               (itself ? "it" : "the link") + ": name a regular file");
  }
}

AtomicOutput::AtomicOutput(const std::string& path)
    : path_(path), temp_path_(MakeTempPath(path)), pending_(temp_path_) {
  RequireReplaceableOutput(path);
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    throw InputError(path, "output folder '" + parent.string() + "' does not exist");
  }
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) std::remove(temp_path_.c_str());
  pending_.Release();
}

namespace {

// The errors of a file system that has no such call (FUSE mounts: sshfs,
// SMB, WSL's drvfs), not of this call on these paths.
bool NotSupported(int err) { return err == ENOSYS || err == EOPNOTSUPP || err == ENOTSUP; }

int RenameNoReplace(const char* from, const char* to) {
  return renameat2(AT_FDCWD, from, AT_FDCWD, to, RENAME_NOREPLACE);
}

}  // namespace

int RenameWithoutReplacing(const char* from, const char* to, PathCall rename_noreplace, PathCall hard_link) {
  if (rename_noreplace == nullptr) rename_noreplace = RenameNoReplace;
  if (hard_link == nullptr) hard_link = link;
  if (rename_noreplace(from, to) == 0) return 0;
  if (errno != EINVAL && !NotSupported(errno)) return errno;  // EINVAL: the file system takes no flags
  if (hard_link(from, to) == 0) {
    unlink(from);
    return 0;
  }
  // EPERM: "the file system does not support hard links" (link(2)); EXDEV:
  // some FUSE file systems say so for any link.
  if (errno != EPERM && errno != EXDEV && !NotSupported(errno)) return errno;
  // Neither atomic way: the name checked free, then the rename. A file
  // another process makes in the moment between would be replaced; on such
  // a file system a line keeps measuring rather than every capture failing.
  struct stat st {};
  if (lstat(to, &st) == 0) return EEXIST;
  if (errno != ENOENT) return errno;
  return std::rename(from, to) == 0 ? 0 : errno;
}

void AtomicOutput::Commit(AtExisting existing) {
  const bool refuse = existing == AtExisting::kRefuse;
  const int err = refuse ? RenameWithoutReplacing(temp_path_.c_str(), path_.c_str())
                         : (std::rename(temp_path_.c_str(), path_.c_str()) == 0 ? 0 : errno);
  if (err != 0) {
    std::remove(temp_path_.c_str());
    throw InputError(path_, refuse && err == EEXIST
                                ? "exists already, not replaced: made after this run found the name free (by "
                                  "another run writing to the same folder?)"
                                : std::string("cannot write: ") + std::strerror(err));
  }
  pending_.Release();
  committed_ = true;
}

namespace {

// `bytes` into out's temporary file, synced; InputError naming `path`.
void WriteTemporary(const AtomicOutput& out, const std::string& path, const std::string& bytes) {
  FILE* f = std::fopen(out.temp_path().c_str(), "wb");
  if (!f) throw InputError(path, std::string("cannot write: ") + std::strerror(errno));
  const bool ok =
      std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size() && std::fflush(f) == 0 && fsync(fileno(f)) == 0;
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed) throw InputError(path, "write failed (disk full?)");
}

}  // namespace

void WriteFileAtomically(const std::string& path, const std::string& bytes) {
  AtomicOutput out(path);
  WriteTemporary(out, path, bytes);
  out.Commit();
}

void AtomicOutputSet::Add(const std::string& path, const std::string& bytes) {
  auto out = std::make_unique<AtomicOutput>(path);
  WriteTemporary(*out, path, bytes);  // on failure `out` removes its temporary file
  staged_.push_back(std::move(out));
}

void AtomicOutputSet::Commit(AtExisting existing) {
  if (existing == AtExisting::kRefuse)
    CommitNew();
  else
    CommitReplacing();
}

void AtomicOutputSet::CommitReplacing() {
  // What is at each output path now, kept under a second name until every
  // rename is done.
  struct Earlier {
    bool existed = false;
    std::string kept;  // the hard link's path; empty if none was made
    std::unique_ptr<PendingTemporary> pending;
  };
  std::vector<Earlier> earlier(staged_.size());
  for (size_t i = 0; i < staged_.size(); ++i) {
    const std::string& path = staged_[i]->path();
    struct stat st {};
    if (lstat(path.c_str(), &st) != 0) continue;
    earlier[i].existed = true;
    const std::string kept = MakeTempPath(path);
    if (link(path.c_str(), kept.c_str()) != 0) continue;
    earlier[i].kept = kept;
    earlier[i].pending = std::make_unique<PendingTemporary>(kept);
  }
  auto drop_kept = [&] {
    for (const Earlier& e : earlier)
      if (!e.kept.empty()) std::remove(e.kept.c_str());  // gone already where it was put back
  };
  size_t done = 0;
  try {
    for (; done < staged_.size(); ++done) staged_[done]->Commit();
  } catch (...) {
    for (size_t j = 0; j < done; ++j) {
      const std::string& path = staged_[j]->path();
      if (!earlier[j].kept.empty())
        std::rename(earlier[j].kept.c_str(), path.c_str());
      else if (!earlier[j].existed)
        std::remove(path.c_str());
    }
    drop_kept();
    throw;
  }
  drop_kept();
  staged_.clear();
}

void AtomicOutputSet::CommitNew() {
  // Each temporary file's identity: a failure removes what this set
  // committed, and only that (not a file another process put there since).
  std::vector<struct stat> ours(staged_.size());
  for (size_t i = 0; i < staged_.size(); ++i) lstat(staged_[i]->temp_path().c_str(), &ours[i]);
  size_t done = 0;
  try {
    for (; done < staged_.size(); ++done) staged_[done]->Commit(AtExisting::kRefuse);
  } catch (...) {
    for (size_t j = 0; j < done; ++j) {
      struct stat now {};
      const std::string& path = staged_[j]->path();
      if (lstat(path.c_str(), &now) == 0 && now.st_dev == ours[j].st_dev && now.st_ino == ours[j].st_ino)
        std::remove(path.c_str());
    }
    throw;
  }
  staged_.clear();
}

}  // namespace stereorig
