// The folder a command creates: made late, undone on failure.
#pragma once

#include <exception>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "calib/core/pending_temporary.h"

namespace stereorig {

// The file or folder a path names, as the output checks compare paths
// (apps/output_paths.h, FolderToCreate): absolute, symbolic links followed
// as far as the path exists, the rest normalised. A part the file system
// cannot look up (a name longer than it allows) counts as not there, so
// such a path is a path to refuse by name, not a std::filesystem error.
std::filesystem::path NormalPath(const std::filesystem::path& path);

// The deepest part of `normal` (a NormalPath) that exists, or empty if none
// does; `missing` gets the parts below it, innermost first. A part that
// cannot be looked up (a name too long for the file system) is missing.
std::filesystem::path DeepestExistingPart(const std::filesystem::path& normal,
                                          std::vector<std::filesystem::path>* missing);

// Throws InputError(path, "cannot <doing>: File name too long (...)") if the
// name of a part of `missing` (the parts of `path` to create below
// `existing`, as DeepestExistingPart gives them) is longer than the file
// system there allows (pathconf NAME_MAX: 255 on ext4): found before a
// command's work, not by creating it after, nor as a std::filesystem error
// from looking it up. Nothing is checked if `existing` is empty.
void CheckNamesFit(const std::string& path, const std::string& doing, const std::filesystem::path& existing,
                   const std::vector<std::filesystem::path>& missing);

// A folder a command creates, and the folders above it that did not exist
// when this object was made (a command's output folder is made so by
// OutputPaths::ClaimFolder, apps/output_paths.h, after its checks): created
// only once every input has been checked (Create), and removed again,
// innermost first and only while empty, if the command fails after that (an
// exception leaving the scope of this object, or RemoveIfEmpty), Create
// failing part way included, or if a termination signal ends the process
// while this object lives (pending_temporary.h: after the temporary files
// and folders in them). So bad input found after the claim, or Ctrl-C,
// leaves no new folder behind, while a folder that existed before (another
// process's made meanwhile included), or one holding what the command wrote
// before a later failure, stays.
class FolderToCreate {
 public:
  FolderToCreate() = default;  // no folder: an optional one not asked for
  // `what` names the folder's use in messages ("the camera models
  // (--export-cameramodels)").
  FolderToCreate(const std::string& path, const std::string& what);
  FolderToCreate(FolderToCreate&& other) noexcept;
  FolderToCreate& operator=(FolderToCreate&& other) noexcept;
  FolderToCreate(const FolderToCreate&) = delete;
  FolderToCreate& operator=(const FolderToCreate&) = delete;
  ~FolderToCreate();
  // Whether `folder` is the claimed folder or one above it that Create will
  // make (a file claimed in it needs no folder test).
  bool WillCreate(const std::filesystem::path& folder) const;
  // Creates the folder (and the missing ones above it). Throws InputError
  // naming it if it cannot be made. Nothing happens for no folder.
  void Create();
  // For a command that fails by its exit code, not an exception (a batch
  // whose every capture failed): the folders Create made, while empty.
  void RemoveIfEmpty();

 private:
  std::string path_, what_;                     // as given; what it holds (for the message)
  std::vector<std::filesystem::path> missing_;  // normal absolute paths not there when claimed, outermost first
  std::vector<std::filesystem::path> made_;     // those Create made itself, outermost first
  std::vector<std::unique_ptr<PendingTemporary>> on_signal_;  // made_, for a termination signal to remove
  bool created_ = false;
  int exceptions_ = std::uncaught_exceptions();  // at construction: more in the destructor means failing
};

}  // namespace stereorig
