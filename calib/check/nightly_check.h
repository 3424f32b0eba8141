// The nightly recalibration check: a few fresh captures of the target, the
// stored rig held fixed, only board poses re-estimated. It answers "has
// anything moved since calibration?", names what moved, and sets every
// threshold from the stored calibration's own residuals and uncertainties.
//
// Figures (docs/verify-and-check.md):
//   - per camera, the consistency RMS: the camera's corners reprojected
//     through a board pose estimated from the OTHER cameras (leave one out),
//     so a moved camera cannot hide by pulling the pose towards itself;
//   - per module, the rectified-row (epipolar) error of corners both its
//     cameras see, with the stored right_from_left;
//   - per module pair, the closure through the double-sided target: the board
//     pose from module i alone against the one from module j alone, mean over
//     captures, in mm (at the board centre) and degrees.
// A module whose cameras disagree names each camera that also disagrees with
// the other modules (those that agree with themselves, where any do), and
// says whether a new pose or a new lens (focal length, principal point)
// explains its corners, either does (the check cannot tell), or neither
// alone does.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "calib/check/board_scale.h"
#include "calib/check/camera_change.h"
#include "calib/check/shared_lens_change.h"
#include "calib/core/rig.h"
#include "calib/observations.h"
#include "targets/target.h"

namespace stereorig {

struct CheckOptions {
  // Coverage factor of every threshold: a figure fails when it exceeds its
  // H0 expectation by this many standard errors. 3.5 gives a per-figure false
  // alarm rate near 2e-4 for Gaussian noise.
  double k_sigma = 3.5;          // in (0, 10]
  int min_captures = 5;          // fewer: bad input
  int min_corners_per_view = 6;  // views with fewer are ignored
  void Check() const;
};

struct CheckFigure {
  std::string name;  // e.g. "cam2_consistency_rms_px", "pair_0_1_closure_mm"
  double value = 0;
  double threshold = 0;
  bool pass = true;
  int samples = 0;  // corners or captures behind the figure
};

// Why a view was set aside (RunNightlyCheck): its board is seen nearly
// edge-on (SeenEdgeOn, calib/capture_folder.h: its corners can share one
// error that its own noise does not show); its corners jump about their
// own board pose, beyond any smooth field a lens change leaves; or it
// disagrees with the rest of its capture, in that capture only (taken at
// another moment than the capture's other views?), or its capture's modules
// disagree in that capture only (a trigger slip: the whole capture goes).
enum class SetAsideWhy { kCornersJump, kOtherMoment, kEdgeOn };

// Why a view went with every other view of its capture (SetAsideView's
// whole_capture): the capture's modules disagree in it only (a module's
// images from another moment: which module, two modules cannot tell), or
// one view disagrees with views that are all of one other module (the
// capture's three views: the lone camera's image or that module's pair may
// be the one taken at another moment, and the two agreeing views are one
// module's, not independent witnesses).
enum class WholeCapture { kNo, kModulesDisagree, kViewOrModule };

// A view the check set aside whole.
struct SetAsideView {
  int capture = -1;
  int camera = -1;
  // kCornersJump (and kEdgeOn, where it is the reading the jump screen
  // would have judged): per axis, neighbour jumps of its residuals about its own pose
  double jump_rms_px = 0;
  double bound_px = 0;  // what jump_rms_px, or off_px, had to be within (kEdgeOn: the jump's bound)
  SetAsideWhy why = SetAsideWhy::kCornersJump;
  double off_px = 0;  // kOtherMoment: median corner error through the pose its capture's other views imply
  WholeCapture whole_capture = WholeCapture::kNo;  // kOtherMoment: set aside with its capture's every view, and why
  int lone_camera = -1;                            // kViewOrModule: the view that disagrees with one module's ...
  int other_module = -1;                           // ... views: that module
  // kOtherMoment: no later capture of the night kept a view of this camera,
  // so nothing tells a knock during this capture (which stays) from an
  // image of another moment (which does not): the night reads "recapture"
  // (CheckResult::Verdict). A camera whose later views agree with their
  // captures was not knocked there: a slip of that image, the night judged.
  bool left_open = false;
  std::string capture_name = {};  // as the night names it (RunNightlyCheck's capture_names), else its index
  // kEdgeOn: the board's tilt from face-on in this view (TiltDeg of its own
  // board pose), at least kEdgeOnTiltDeg as printed.
  double tilt_deg = 0;
  double FigurePx() const { return why == SetAsideWhy::kOtherMoment ? off_px : jump_rms_px; }
};

// Tonight's corner noise against the calibration's, per camera: each view's
// residuals about its own board pose (RunNightlyCheck), the thresholds'
// noise the larger of the two.
struct CameraNoise {
  int camera = -1;
  double tonight_px = 0;      // per axis, over every view of the camera kept
  double calibration_px = 0;  // provenance.residuals.camK_rms_px
};

// Tonight's corner noise this many times the calibration's, or more, on a
// camera: the thresholds rise with it until a change the check exists to see
// passes under them. Such a night is no evidence: it reads "recapture". On
// the demo's rig (docs/verify-and-check.md) unmoved nights read 0.9-1.4
// times; at 4 times the closure's threshold rose 2.4-fold (0.0064 to 0.015
// mm) and module 1 shifted 0.05 mm was still named; at 20 times 13-fold
// (0.082 mm), and that shift read ok.
constexpr double kNoisyNightFactor = 5;

// Why a capture went whole (`v` any of its views, whole_capture not kNo),
// once for the capture: "its modules disagree by ... in this capture only:
// ...", "cam2 is off module 0's views by ...".
std::string WholeCaptureText(const SetAsideView& v);

struct CheckResult {
  std::vector<CheckFigure> figures;
  std::vector<SetAsideView> views_set_aside;
  // One per camera named by elimination (its module's cameras disagree and
  // it also disagrees with the other modules), in the order named: what
  // explains its corners, a new pose, a new lens, either (the check cannot
  // tell), neither alone, or too few corners to tell
  // (calib/check/camera_change.h).
  std::vector<CameraChange> camera_changes;
  // Modules named by failing closures alone (each module agrees with
  // itself): a closure shows that two modules' board poses disagree, which a
  // module's motion and a small change of one of their lenses (a focal
  // length scales a module's pose) both do. NameClosureModules (below) says
  // which: one module, or several of which the check cannot tell which
  // changed (closure_which_unknown).
  std::vector<int> closure_modules;
  bool closure_which_unknown = false;
  // Modules whose cameras both disagree with the modules that agree with
  // themselves, explained by one shift of the module and its lenses where
  // the lenses alone do not (module_shift.h): the module is in closure_modules
  // (with each module it was read against, as a failing closure), the shift
  // here (its cameras' centres, in the reference frame), and only the
  // cameras whose lens the shift leaves off are in camera_changes. Camera 0's
  // principal point +1 px with module 1 0.5 mm off read cameras 0 and 1
  // "moved" 0.5 mm, the module pair not named. The shift is relative: the
  // module is the one whose cameras disagree with each other (its lens),
  // read against `relative_to`, and those may be what moved, by the
  // opposite shift. Only where the closures name the module alone (three or
  // more modules, those it is read against agreeing) is it the one that
  // moved; otherwise `which_unknown` (always so with two modules: module 1
  // moved reads as module 0's shift).
  struct ModuleShiftNamed {
    int module = -1;
    Eigen::Vector3d shift_mm = Eigen::Vector3d::Zero();
    std::vector<int> relative_to = {};
    bool which_unknown = true;
  };
  std::vector<ModuleShiftNamed> module_shifts;
  // Modules whose own two cameras disagree while neither disagrees with the
  // other modules (or there are none): something in the module changed, a
  // camera's pose or lens, not the module as a whole.
  std::vector<int> split_modules;
  // The board's size as each module measures it over the target file's
  // (board_scale.h), and, when every module (at least two) reads it off the
  // same way by more than kMaxBoardScaleOff, what that says: the end of the
  // explanation (a wrong --target, or every module's cameras changed alike).
  std::vector<ModuleBoardScale> board_scales;
  std::string board_size_note;
  // What the board measured with says (check_target.h: the rig file records
  // no board, or the target file was re-measured), set by the caller: the
  // end of a failing night's explanation (a file off its plate fails the
  // cameras' consistency and the closures alike).
  std::string target_note;
  // Every camera's figure fails, every module (at least two) disagrees with
  // itself, and no named camera's change is explained by a new pose or a new
  // lens alone: no camera is left unchanged to read the others against, so
  // the cameras named (the worse of each module) are not all that changed.
  // Said after them: all four focal lengths +0.1 % named cameras 0 and 3,
  // "neither", and another rig's captures camera 1 alone.
  bool every_camera_fails = false;
  // Where every camera's figure fails (two modules or more), one lens change
  // shared by every camera is fitted (shared_lens_change.h); where with it
  // every camera's and module's consistency and every closure are within
  // their thresholds, it is what the night says, and no camera or module is
  // named alone: all four focal lengths +0.1 % named the worse camera of
  // each module, "neither a new pose nor a new lens alone explains".
  bool shared_lens_explains = false;
  SharedLensChange shared_lens_change;  // as fitted, where shared_lens_explains
  // Where a shared change explains every camera but a few (fewer than
  // half), each of which changed besides: those cameras, each in
  // camera_changes, read against the others with the shared change
  // applied (shared_lens_change, fitted without them). All four focal
  // lengths +0.1 % with camera 2's +0.13 % named camera 1 and camera 2
  // "neither", camera 1 unchanged but for the shared change.
  std::vector<int> shared_lens_besides;
  // Otherwise, where with the board at the size every module measures it
  // (their mean, board_scales) all those figures hold: the rig's scale
  // against the board's changed (every baseline and S alike, or a board of
  // another size: the board is the check's one length), said so, and no
  // camera or module named alone.
  bool shared_scale_explains = false;
  double shared_scale = 1;  // the board's size over its file's, where shared_scale_explains
  // Where shared_scale_explains: the board as a solid (the plate's
  // thickness scaled too) missed the night by far (twice a threshold), its
  // faces' prints scaled alone, on the plate as it was, explained it. No
  // change of the rig's scale reads so (a rig scaled sees the solid): the
  // board's print is not its file's size. A print on a plate scaled in its
  // plane differs from the solid by the thickness scaled alone (15 um at
  // 0.3 %), within the closures' noise: said as the rig's scale, which
  // cannot be told from the board's.
  bool shared_scale_print_only = false;
  // Every camera's corner noise tonight and at calibration (the figures'
  // noise is the larger): the report's corner_noise.
  std::vector<CameraNoise> corner_noise;
  // Every figure within its threshold (the figures alone: see Verdict).
  bool ok() const;
  // A view set aside left open (SetAsideView::left_open), or tonight's
  // noise kNoisyNightFactor times the calibration's on some camera: the
  // night cannot say ok, whatever its figures.
  bool Inconclusive() const { return !OpenViews().empty() || !NoiseWarning().empty(); }
  // "recalibrate" where a figure fails; else "recapture" where the night is
  // inconclusive (capture again before production: exit 1 as recalibrate);
  // else "ok".
  std::string Verdict() const { return !ok() ? "recalibrate" : Inconclusive() ? "recapture" : "ok"; }
  std::string Explanation() const;              // one line: what changed, in no more words than the figures support
  std::vector<SetAsideView> OpenViews() const;  // views_set_aside left open, one per capture
  // "" or why tonight's noise hides a change: the cameras many times noisier
  // than at calibration, and what the thresholds can still see (the
  // closures' in mm and deg); said on standard error and in the report.
  std::string NoiseWarning() const;
  // Every camera named (camera_changes' cameras; every camera where
  // shared_lens_explains): the report's
  // flagged_cameras (and moved_cameras, its old name; each change's kind
  // says what explains it).
  std::vector<int> FlaggedCameras() const;
  // Every module named (split_modules and closure_modules, sorted; every
  // module where shared_scale_explains, none where shared_scale_print_only:
  // recalibrated against the file, every module would take the print's
  // error): the report's flagged_modules. No
  // figure tells a module's motion from a lens change, so none is said to
  // have moved as a whole.
  std::vector<int> FlaggedModules() const;
  int num_cameras = 0;  // the rig's, set by RunNightlyCheck (FlaggedCameras where shared_lens_explains)
  int num_modules = 0;  // the rig's, set by RunNightlyCheck (FlaggedModules where shared_scale_explains)
};

// The modules failing closures name, from each module's count of failing
// pairs (module -> count, modules in no failing pair absent): the module in
// the most pairs, alone, when it is in at least two (it disagrees with
// modules that agree among themselves); otherwise every module tied at the
// top, and which_unknown: a single failing pair (always so with two modules:
// module 0 only defines the reference frame), or a tie (a ring whose every
// pair fails) tells that they disagree, not which one changed.
//
// `judged_pairs` holds each pair's (i < j) closure where it was judged,
// neither module's cameras disagreeing; a pair absent was not judged (too
// few captures where both saw the board). A single failing pair (a, b)
// names b alone where a third module c agrees with a, b's pair with c was
// not judged, and the failing closure is past twice (a, c)'s threshold (had
// a made that change, (a, c) would have failed): a agrees with the rest, b
// is the odd one. A ring whose side modules rarely see the board together
// under 70 deg: module 1 shifted fails (0, 1), passes (0, 2), and (1, 2) is
// not judged. So read where one module changed and its change moves its
// board pose alike in every capture: a motion does; a lens change does only
// roughly (its error moves with where the board is in the image), and one
// that shows in (a, b)'s captures past twice what (a, c)'s let pass would
// name b (docs/verify-and-check.md). Not where c agrees with both, or
// thirds point at a and at b: which_unknown as before.
struct JudgedClosure {
  double mm = 0, threshold_mm = 0;    // the board centre's mean offset between the two modules' poses
  double deg = 0, threshold_deg = 0;  // and the poses' mean turn
  bool Holds() const { return mm <= threshold_mm && deg <= threshold_deg; }
};
struct ClosureNaming {
  std::vector<int> modules;  // ascending
  bool which_unknown = false;
};
ClosureNaming NameClosureModules(const std::map<int, int>& failed_pairs_of,
                                 const std::map<std::pair<int, int>, JudgedClosure>& judged_pairs = {});

// Throws InputError(`where`, ...) when the rig file lacks a calibration
// residual the thresholds need (provenance.residuals.camK_rms_px for every
// camera: a rig stereorig calibrate did not write), or holds one of 0 (the
// check weights corners by 1 / rms^2). Commands call it with the rig file's
// path before the target is detected.
void RequireCalibrationResiduals(const Rig& rig, const std::string& where);

// Throws InputError(`where`, ...) when the rig file lacks the calibration
// residuals the thresholds need (RequireCalibrationResiduals), when there
// are too few captures (given, or left once views are set aside, corners
// trimmed and poses fitted: the message names each capture lost and why, by
// capture_names where given, else by index), when a view names a camera the
// rig does not have, or when the captures do not fit the rig at all (another
// rig's captures), or two cameras' images look exchanged (the night fits
// with their views swapped). `target` is measured with as given: pass
// TargetForCheck(rig, file's board, path).target (check_target.h), the
// board with the back_from_front S was calibrated with; the target file's
// own reads its error as the modules disagreeing.
CheckResult RunNightlyCheck(const Rig& rig, const Target& target, const std::vector<BoardObservation>& views,
                            const CheckOptions& options, const std::string& where,
                            const std::map<int, std::string>& capture_names = {});

}  // namespace stereorig
