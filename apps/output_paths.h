// The files one command will write, checked before it does any work: no file
// named twice (its cloud and its mesh at one path would leave only the last
// written), none of them one of the inputs the command protects (a report
// written over the rig file it was checking), and each one's folder there to
// write in. Paths are compared after following symbolic links. A failure is bad input
// (InputError) naming the path, so nothing is computed only to fail at the
// end with some outputs written and others not.
#pragma once

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "calib/core/folder_to_create.h"
#include "calib/core/rig.h"

namespace stereorig {

class OutputPaths {
 public:
  // `remedy`: appended to the message when a file is claimed twice.
  explicit OutputPaths(std::string remedy = "") : remedy_(std::move(remedy)) {}
  // Records `path`, written as `what` (for the message). Throws InputError if
  // another output already claimed the same file, if it is a folder a
  // ClaimFolder before will create or claimed (named as that folder), if a name in it that does not exist yet
  // (the file's, or a folder's the command creates) is longer than the file
  // system allows (NAME_MAX), or, with
  // check_folder, if its folder does not exist or this process may not
  // write in it (access W_OK|X_OK, then a file created and removed there:
  // root passes access() in /sys; off for files in a folder the command
  // creates itself, which ClaimFolder checks), or if it is "-", a device, a
  // pipe or a socket (RequireReplaceableOutput, calib/core/atomic_file.h).
  void Claim(const std::string& path, const std::string& what, bool check_folder = true);
  // Records an input the command reads, `what` naming it ("the rig file
  // (--rig)"): a Claim of the same file throws InputError. Call before the
  // Claims. An empty path is ignored (an optional input not given).
  void Protect(const std::string& path, const std::string& what);
  // Records a folder the command creates if needed and writes files into
  // (`what` names it). Throws InputError if it is an input or a claimed
  // file, if a missing folder above it is a claimed file, if it, or the
  // nearest part of its path that exists, is a file, or if the folders
  // missing cannot be made there: a name longer than the file system allows
  // (pathconf NAME_MAX of that nearest existing folder, 255 on ext4), or a
  // nearest existing folder this process may not write in and search
  // (access W_OK|X_OK; the folder itself if it exists).
  // The command creates it through the object returned, once every input
  // is checked (FolderToCreate::Create).
  [[nodiscard]] FolderToCreate ClaimFolder(const std::string& path, const std::string& what);

 private:
  std::string remedy_;
  std::map<std::filesystem::path, std::string> claimed_;  // normal absolute path -> what writes it
  std::map<std::filesystem::path, std::string> inputs_;   // normal absolute path -> the input it is
  std::map<std::filesystem::path, std::string> folders_;  // folders ClaimFolder will create -> what they hold
  std::set<std::filesystem::path> writable_folders_;      // folders a Claim found it can write in (as given)
};

// The --report of a command that reads a rig file and runtime options
// (bench, score, a reconstruct batch), and the inputs it may not replace.
// An empty path: not given. Call sites name the fields they set:
//   ClaimRuntimeReport({.path = report, .rig_path = rig, .options_path = options});
// (Every field has an initializer: GCC's -Wmissing-field-initializers then
// lets a designated initializer leave it out.)
struct RuntimeReportClaim {
  std::string path{};                             // --report
  std::string rig_path{};                         // the rig file the command reads
  std::string rig_what = "the rig file (--rig)";  // names it in the message (a dataset's truth rig without --rig)
  std::string options_path{};                     // --options
  bool check_folder = true;                       // as OutputPaths::Claim: off if the command creates the folder
  std::vector<std::pair<std::string, std::string>> more_inputs{};  // further (path, what) to protect (DatasetInputs)
};
// Protects the inputs and claims the report. Returns the OutputPaths that
// holds them, for the command's further outputs (score's --diagnose images,
// known once the rig is read): each is then checked against the report too.
OutputPaths ClaimRuntimeReport(const RuntimeReportClaim& report);

// The inputs of a command that reconstructs one capture (reconstruct,
// tune): its rig file, its options file (if given) and the capture's
// camK.png images (runtime.h CaptureImagePaths: the rig says which).
void ProtectCaptureInputs(const std::string& rig_path, const std::string& options_path, const std::string& capture_dir,
                          const Rig& rig, OutputPaths* outputs);

// The files `stereorig score` and `bench` read from a simulated dataset
// (docs/formats.md "Datasets"), as (path, what) for OutputPaths::Protect:
// truth/rig.yaml (the scorer reads it even when --rig is given), every
// other file under truth/ (surfaces, depth, id and lit maps, object poses),
// spec.yaml, and every camK.png of scenes/<scene>/{active,passive}/. Empty
// if `dataset` is empty or not a folder.
std::vector<std::pair<std::string, std::string>> DatasetInputs(const std::string& dataset);

}  // namespace stereorig
