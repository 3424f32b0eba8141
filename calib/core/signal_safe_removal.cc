#include "calib/core/signal_safe_removal.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>

namespace stereorig {

namespace {

// How often a folder is listed and emptied before it is given up: another
// thread may add a file after a listing (simulate's renderers, while the
// signal is handled).
constexpr int kListings = 8;

bool IsDotOrDotDot(const char* name) { return name[0] == '.' && (name[1] == 0 || (name[1] == '.' && name[2] == 0)); }

bool RemoveAt(int folder_fd, const char* name, int depth);

// Removes what the open folder `fd` holds, as far as it can; `depth`: its
// own level. Returns whether it removed all it listed.
bool Empty(int fd, int depth) {
  // glibc's dirent64 is the kernel's linux_dirent64, record for record.
  alignas(struct dirent64) char listing[2048];
  bool all = true;
  for (;;) {
    const long bytes = syscall(SYS_getdents64, fd, listing, sizeof listing);
    if (bytes < 0) return false;
    if (bytes == 0) return all;
    for (long at = 0; at < bytes;) {
      const auto* entry = reinterpret_cast<const struct dirent64*>(listing + at);
      at += entry->d_reclen;
      if (!IsDotOrDotDot(entry->d_name)) all = RemoveAt(fd, entry->d_name, depth + 1) && all;
    }
  }
}

// Removes `name` in the folder `folder_fd` (AT_FDCWD: `name` is a path), at
// level `depth`: unlinked if it is not a folder (a symbolic link to one
// included), else emptied first.
bool RemoveAt(int folder_fd, const char* name, int depth) {
  if (unlinkat(folder_fd, name, 0) == 0 || errno == ENOENT) return true;
  if (errno != EISDIR && errno != EPERM) return false;  // Linux says EISDIR for a folder, POSIX EPERM
  if (depth > kMaxRemovalDepth) return false;
  const int fd = openat(folder_fd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  // Gone meanwhile (another remover got there first): removed. Else not a
  // folder after all (EPERM: an immutable file), or replaced by a link.
  if (fd < 0) return errno == ENOENT;
  // Listed again only if all it listed went, yet the folder is not empty:
  // something new came (what cannot be removed is not tried again, level
  // after level).
  bool removed = false;
  for (int listing = 0; listing < kListings && !removed; ++listing) {
    if (listing > 0 && lseek(fd, 0, SEEK_SET) != 0) break;
    const bool emptied = Empty(fd, depth);
    removed = unlinkat(folder_fd, name, AT_REMOVEDIR) == 0;
    if (!removed && (!emptied || (errno != ENOTEMPTY && errno != EEXIST))) break;
  }
  close(fd);
  return removed;
}

}  // namespace

bool RemoveTreeSignalSafe(const char* path) { return RemoveAt(AT_FDCWD, path, 1); }

}  // namespace stereorig
