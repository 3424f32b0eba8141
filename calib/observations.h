// What the calibration engine consumes: corner observations of the target,
// the target's geometry, and the rig's layout (which cameras form a module).
//
// The engine works on detected corners, never on images, so detection
// (targets/) and the simulator (datasets/) plug in here.
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "calib/core/pose.h"
#include "targets/target.h"

namespace stereorig {

// One camera's view of one face of the target in one capture. Partial boards
// are allowed: corner_ids lists only the corners found.
struct BoardObservation {
  int capture = -1;                   // capture index (all cameras fire together)
  int camera = -1;                    // global camera index
  Face face = Face::kFront;           // which face of the target was seen
  std::vector<int> corner_ids;        // (N,) id = row * corners_x + col, in the face's own frame
  std::vector<Eigen::Vector2d> q_px;  // (N,) pixel; (0,0) is the centre of the top-left pixel
};

// The target as the engine needs it: a chessboard grid per face and the
// face-to-face transform with its measured uncertainty.
struct TargetGeometry {
  int corners_x = 0;            // inner corners along a row
  int corners_y = 0;            // inner corners along a column
  double square_size_mm = 0.0;  // chessboard pitch, mm
  bool double_sided = false;    // false: a plain board, front face only
  Pose back_from_front;         // front-face frame -> back-face frame, mm
  // 1-sigma of back_from_front as measured: [rx, ry, rz (deg), tx, ty, tz (mm)].
  // Stage 3 refines back_from_front under this prior axis by axis: an axis
  // whose sigma is 0 is held at the given value, the others refined (all 0:
  // held whole).
  Eigen::Matrix<double, 6, 1> back_from_front_sigma = Eigen::Matrix<double, 6, 1>::Constant(1e-3);

  int num_corners() const { return corners_x * corners_y; }
  // Corner `id` in its face's frame, mm: (col * s, row * s, 0).
  Eigen::Vector3d CornerInFace(int id) const {
    const int col = id % corners_x, row = id / corners_x;  // integer division: the row
    return Eigen::Vector3d(col * square_size_mm, row * square_size_mm, 0.0);
  }
  // face_from_front: identity for the front face, back_from_front for the back.
  Pose FaceFromFront(Face face) const { return face == Face::kFront ? Pose::Identity() : back_from_front; }
  // Throws InputError naming `where` if the geometry is unusable.
  void Check(const std::string& where) const;
};

TargetGeometry TargetGeometryFromTarget(const Target& target);

// One stereo module as the layout names it.
struct ModuleLayout {
  std::string name;       // e.g. "module0"
  int left_camera = -1;   // global camera index; the module's frame is this camera's frame
  int right_camera = -1;  // global camera index
  // If set, the only face this module can see (e.g. module 0 the front face
  // and module 1 the back face of the default rig). An observation of the
  // other face is refused as an input error.
  std::optional<Face> face;
};

struct CameraImager {
  std::string name;  // e.g. "cam0"
  int width_px = 0;  // imager size
  int height_px = 0;
};

struct CalibrationInput {
  TargetGeometry target;
  std::vector<CameraImager> cameras;  // indexed by global camera index
  std::vector<ModuleLayout> modules;  // module 0 is the reference
  std::vector<BoardObservation> observations;
  std::string source = "observations";  // for provenance and error messages
  // Capture index -> the name of its folder (calib/capture_folder.h), for
  // the report to name a capture as the detection lines do; empty for
  // observations from elsewhere (the synthetic rigs).
  std::map<int, std::string> capture_names;
};

// The captures in which a module's two cameras (global indices) saw different faces of the
// target (views with corners only), sorted. Physically possible: the board
// nearly edge-on to the module, its plane passing between the two cameras.
// Stage 1 uses such views as they are; stage 2 sets the module's views of
// these captures aside (a face misread by the detector looks the same), and
// stage 3 honours stage 2's list (SystemExclusions). Over every view,
// including those stage 1 drops: a dropped view (too few corners, no board
// pose determined) still says which face its camera saw, so a misread face
// in its partner's view is still caught. A rule counting only the views
// stage 1 kept would let such a misread view into stage 3, where the module
// poses no board to check it: measured with that rule, a module's 3D error
// 0.082 mm and the modules' agreement 0.059 mm, over the 0.05 mm bounds
// (CalibrateDifferentFaces.AViewStageOneDroppedStillSetsItsCaptureAside).
std::vector<int> CapturesWithDifferentFaces(const CalibrationInput& input, int left_camera, int right_camera);

}  // namespace stereorig
