// Target captures on disk -> corner observations for the engine.
//
// A captures folder holds one sub-folder per capture (sorted by name; a
// numeric name such as 007 is the capture's index), each with one 8-bit grey
// image per camera named camK.png (K = global camera index), as
// docs/formats.md fixes. A dataset folder written by `stereorig simulate`
// works too: its calibration/ sub-folder is used (one without is refused,
// saying so).
#pragma once

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "calib/observations.h"
#include "targets/detect.h"

namespace stereorig {

struct ImageDetectionLog {
  int capture = -1;
  int camera = -1;
  std::string path;
  bool accepted = false;
  Face face = Face::kFront;
  int num_corners = 0;
  int num_outside = 0;                        // corners the detector placed outside the image, dropped here
  std::string reason;                         // why it was rejected (empty if accepted)
  RejectReason reject = RejectReason::kNone;  // its kind (kNone if accepted)
};

struct DetectedCaptures {
  std::vector<CameraImager> cameras;  // (num_cameras,) names camK and the images' size
  std::vector<BoardObservation> observations;
  std::vector<ImageDetectionLog> log;  // one entry per image
  int num_captures = 0;
  std::map<int, std::string> capture_names;  // capture index -> its sub-folder's name (CalibrationInput's)
  // Sub-folders taken for no capture, sorted: hidden ones (.thumbs), and
  // those holding no image at all (camera models written beside the
  // captures). The command says which it skipped (SkippedFoldersNote). One
  // holding images but no camK.png (Cam0.png, left.png, images a folder
  // deeper) is refused instead: skipped, a misnamed capture was lost
  // without a word.
  std::vector<std::string> skipped_folders{};
  // With incomplete_set_aside (CaptureFolderOptions): the camK.png files
  // missing (or empty: 0 bytes) from captures that were set aside whole for
  // it, sorted by capture; those captures are in neither num_captures nor
  // capture_names.
  std::vector<std::string> missing_images{};
};

// The images a captures folder holds: every file named camK.png (any K) in
// each capture sub-folder, as DetectCaptureFolder finds them (a dataset's
// calibration/ sub-folder for a dataset). For a command to protect from its
// outputs (apps/output_paths.h) before any work; empty if `dir` is not a
// folder (the detector names it then).
std::vector<std::string> CaptureFolderImages(const std::string& dir);

// Throws InputError naming `dir` unless it is a folder: "no such captures
// folder", or "is a file, not a captures folder". DetectCaptureFolder calls
// it first; a command calls it before announcing the detection.
void RequireCapturesFolder(const std::string& dir);

// "" if `skipped_folders` (DetectedCaptures') is empty, else "skipped: A, B
// (not captures: ...)": for a refusal or a report to name them.
std::string SkippedFoldersNote(const std::vector<std::string>& skipped_folders);

// How DetectCaptureFolder reads a captures folder: calibrate's way (no rig
// yet) and check's (held to the rig) differ in every field but `detect`.
struct CaptureFolderOptions {
  DetectOptions detect{};
  bool progress = false;  // one line per capture on stderr
  // (num_cameras,) the sizes a rig file gives each camera's images (check),
  // every image held to them; empty (calibrate: no rig yet): each camera's
  // images are held to one size, and each module of `modules` to one size
  // for its two cameras, both read from the PNG headers and refused before
  // any detection.
  std::vector<CameraImager> rig_cameras{};
  std::vector<ModuleLayout> modules{};
  // A capture missing a camera's image, or holding it empty (0 bytes), is
  // set aside whole (missing_images), not refused: the nightly check, whose
  // 8 to 10 captures leave room for one lost (calibrate refuses it).
  bool incomplete_set_aside = false;
};

// Detects the target in every image. Throws InputError (naming the file) on
// a missing folder or image, a capture sub-folder holding images none of
// which is named camK.png (naming it and them), an unreadable image, an
// image of the wrong size (CaptureFolderOptions), or a dataset folder
// without calibration/ captures.
DetectedCaptures DetectCaptureFolder(const std::string& dir, const Target& target, int num_cameras,
                                     const CaptureFolderOptions& per_folder);

// "" unless most images were rejected (more than half) and at least one in
// ten as not fitting the target's layout (ambiguous: no single orientation
// of the grid fits; grid_mismatch): then one line counting the rejections
// by reason and asking whether `target_path` describes this board, its
// corners_x and corners_y named. A board of 11 x 9 inner corners read with a
// file of 9 x 11 (the corners swapped) left 29 of 200 images, 59 of them
// rejected as ambiguous, and the calibration ended on "too few views"; a
// right file rejects 13 of the same 200, none as ambiguous.
std::string RejectedViewsNote(const DetectedCaptures& detected, const Target& target, const std::string& target_path);

// For a calibration refused for too few views, where RejectedViewsNote
// said nothing: "" unless most images (more than half) were rejected as
// showing no board the target file describes (no_chessboard: none of its
// grid; no_tags: none of a double-sided target's tags). Then the board was
// out of view or too dark, or the file gives another grid or tags: a plain 9 x 6 file against
// the 11 x 9 board read "too few views: 1 usable" and nothing more. Not a
// warning on its own: the same rejections come of a board that most
// cameras see in few captures, and such a calibration can succeed.
std::string NoBoardFoundNote(const DetectedCaptures& detected, const Target& target, const std::string& target_path);

// "" unless a row or a column of the target file's grid was never detected
// in any accepted view (`observations`, at least one): then one line naming
// `target_path`, its corners_x and corners_y and the rows or columns
// (1-based) never seen. A double-sided target is found by its tags, and a
// view keeps the corners it finds: a file hand-edited to corners_x 12 for
// the 11 x 9 board calibrated, its 12th column never seen, and the rig
// recorded a board of 12 x 9. A plain target's detector finds the whole
// grid or nothing, so it never says so. A warning, not a refusal: a board
// held every time with one edge out of view gives the same.
std::string NeverSeenCornersNote(const std::vector<BoardObservation>& observations, const Target& target,
                                 const std::string& target_path);

// "" unless the captures of `dir` hold camK.png for cameras the layout
// names in no module (K >= num_cameras): then one line naming them, in how
// many captures each is, and that they are not calibrated. calibrate read
// only the layout's cameras and wrote a rig without the others, saying
// nothing; a one-module rig calibrated on purpose from captures of a larger
// one is legitimate, so a warning (stderr and the report's "warnings"),
// not a refusal. (check and reconstruct, which read a rig, refuse such
// images: captures of another rig.)
std::string CamerasLeftOutNote(const std::string& dir, int num_cameras);

// A board stage 1 solved tilted at least this far from facing the camera
// (TiltDeg, rounded to the degree the note prints) is seen nearly edge-on:
// 1 / cos 70 deg = 2.9x foreshortened.
inline constexpr double kEdgeOnTiltDeg = 70.0;
// Whether a board tilted `tilt_deg` (TiltDeg) is seen nearly edge-on, judged
// as printed (to the degree): 69.6 deg reads "70 deg", and is. The
// calibration's notes and the nightly check's screen of such views
// (calib/check/nightly_check.cc) both judge by it.
inline bool SeenEdgeOn(double tilt_deg) { return std::round(tilt_deg) >= kEdgeOnTiltDeg; }

// One warning per module whose joint solve left views out
// (StereoReport::views_left_out), naming them by folder and camera, with
// the board's tilt in each as stage 1 solved it, and the likely cause: a
// board seen nearly edge-on (normal in a ring, whose modules see the board
// from the side), or an image of another camera or capture (a module's left
// and right swapped: each such image is an ordinary view of the other
// camera, at an ordinary tilt). The notes used to blame a swap alone.
std::vector<std::string> StereoViewsLeftOutNotes(const CalibrationReport& report);

// Whether a refusal's problem is one of too few views (stages 1 and 2:
// "never sees the board", "too few views ..."; calib/intrinsics.cc,
// calib/stereo.cc), which NoBoardFoundNote may explain; not one that shows
// the board was seen (a face seen by the wrong module, a corner outside
// the imager), where the note would send the user after the wrong cause.
bool IsTooFewViewsProblem(const std::string& problem);

// The whole of `stereorig calibrate`: reads the target file, detects the
// target in every capture and runs the three stages on the modules of
// `modules` (the layout file, ReadLayoutFile in calib/layout_file.h, read
// by the caller, which needs its cameras before: the files it will write).
// A refusal after most images were rejected (RejectedViewsNote) carries the
// note: the likely cause is the target file, not the stage that failed.
struct FolderCalibration {
  CalibrationResult result;
  int num_captures = 0;
  std::vector<std::string> skipped_folders{};
  int num_views = 0;  // images with an accepted detection
};
FolderCalibration CalibrateCaptureFolder(const std::string& captures_dir, const std::string& target_path,
                                         const std::vector<ModuleLayout>& modules, const CalibrationOptions& options);

}  // namespace stereorig
