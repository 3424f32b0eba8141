// Removing a folder and everything in it from a signal handler
// (pending_temporary.h), where std::filesystem, opendir and malloc may not
// be used: only open(2), getdents64(2) into a buffer on the stack,
// unlinkat(2), lseek(2) and close(2), which are async-signal-safe
// (signal-safety(7); getdents64 is a bare system call).
//
// Symbolic links are removed, never followed: a link in the tree to a folder
// outside it leaves that folder whole. Folders nested deeper than
// kMaxRemovalDepth are left, with the folders that hold them: what a
// temporary output holds is shallow, and the bound keeps the stack used (a
// 2 KiB listing buffer a level) small.
#pragma once

namespace stereorig {

// Folder levels entered, the one removed counting as 1.
inline constexpr int kMaxRemovalDepth = 16;

// Removes `path`: a file or symbolic link, or a folder and all it holds.
// Returns whether it is gone (true if it was not there). Best effort where
// another thread keeps writing in the folder: it is listed again, a few
// times, while something new keeps it from being removed.
bool RemoveTreeSignalSafe(const char* path);

}  // namespace stereorig
