// The calibration target: a chessboard on each face of a rigid plate, with
// AprilTags in the margins that tell the faces apart (disjoint ID ranges) and
// fix the board's orientation; or a plain one-sided chessboard without tags.
//
// Face frame (docs/conventions.md): origin at inner corner 0, x along a row of
// corners, y down the columns, z into the board, i.e. away from whoever looks
// at that face. Corner `id` = row * corners_x + col sits at (col*s, row*s, 0).
// Each face is described in its own frame; `back_from_front` joins them.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "calib/core/pose.h"
#include "targets/tag_family.h"

namespace stereorig {

enum class Face { kFront = 0, kBack = 1 };
const char* FaceName(Face face);  // "front" / "back"

struct TagPlacement {
  int id = 0;
  double center_x_mm = 0;  // in the face frame
  double center_y_mm = 0;
};

struct TargetFace {
  std::vector<TagPlacement> tags;  // IDs of one face never appear on the other
};

class Target {
 public:
  struct Layout {
    int corners_x = 11;           // inner corners along x (a row)
    int corners_y = 9;            // inner corners along y (a column)
    double square_size_mm = 9.0;  // printed square edge
    bool double_sided = true;     // false: a plain board, one face, no tags
    double margin_mm = 15.0;      // white border around the squares; holds the tags
    std::string tag_family = "tag36h11";
    double tag_size_mm = 11.0;  // edge of a tag's black border square
    TargetFace faces[2];        // [front, back]; back unused when !double_sided
    // Maps front-face-frame points to back-face-frame points (mm).
    Pose back_from_front;
    // 1-sigma of back_from_front as measured: [rx, ry, rz] deg, [tx, ty, tz] mm.
    Eigen::Matrix<double, 6, 1> back_from_front_sigma = Eigen::Matrix<double, 6, 1>::Zero();
    double flatness_allowance_mm = 0.0;  // max deviation from a plane, each face
  };

  // Validates the layout; throws InputError(`where`, ...) naming the problem.
  explicit Target(Layout layout, const std::string& where = "target");

  int corners_x() const { return layout_.corners_x; }
  int corners_y() const { return layout_.corners_y; }
  int num_corners() const { return layout_.corners_x * layout_.corners_y; }
  double square_size_mm() const { return layout_.square_size_mm; }
  bool double_sided() const { return layout_.double_sided; }
  const Layout& layout() const { return layout_; }
  const Pose& back_from_front() const { return layout_.back_from_front; }
  const Eigen::Matrix<double, 6, 1>& back_from_front_sigma() const { return layout_.back_from_front_sigma; }

  Eigen::Vector3d CornerInFace(int id) const;
  // Which face a tag ID belongs to; false if it is on neither.
  bool FaceOfTag(int tag_id, Face* face) const;
  const TagPlacement* FindTag(Face face, int tag_id) const;

  // The printed plate's extent in each face frame: x in [min_x, max_x] etc.
  double min_x_mm() const { return -layout_.square_size_mm - layout_.margin_mm; }
  double min_y_mm() const { return -layout_.square_size_mm - layout_.margin_mm; }
  double max_x_mm() const { return layout_.corners_x * layout_.square_size_mm + layout_.margin_mm; }
  double max_y_mm() const { return layout_.corners_y * layout_.square_size_mm + layout_.margin_mm; }
  bool OnPlate(double x_mm, double y_mm) const {
    return x_mm >= min_x_mm() && x_mm <= max_x_mm() && y_mm >= min_y_mm() && y_mm <= max_y_mm();
  }
  // True where the face is printed black (chessboard square or tag cell) at
  // (x, y) mm in that face's frame. Point sampling; renderers supersample.
  bool IsBlack(Face face, double x_mm, double y_mm) const;

 private:
  Layout layout_;
  // Rendered tag cells, per face, parallel to layout_.faces[f].tags.
  std::vector<TagBits> tag_bits_[2];
};

// The embedded default: 11x9 inner corners of 9 mm, tag36h11 in the margins
// (front IDs 0-7, back IDs 100-107), 5 mm plate. docs/simulator.md says why.
Target DefaultTarget();

// Why squares of this edge make no target, naming the unit the size was
// likely typed in ("squares of 900 um, under the 1 mm a camera resolves; is
// it in centimetres? the unit is mm"); "" for a size of at least 1 mm or one
// not positive (refused as such). The target file's square_size_mm and
// `stereorig target --square-mm` say the same.
std::string SmallSquareHint(double square_size_mm);
// The default's design at another size: corners_x x corners_y inner corners
// of square_size_mm, the same tags, margins, plate and measured sigma.
Target DoubleSidedTarget(int corners_x, int corners_y, double square_size_mm);
// A plain one-sided chessboard (no tags), e.g. what most labs own.
Target PlainTarget(int corners_x, int corners_y, double square_size_mm);
// The ideal back_from_front of a plate of `thickness_mm`, both faces printed
// in register: the back face is the front face turned a half turn about the
// y axis (a column of corners) and moved through the plate.
Pose IdealBackFromFront(int corners_x, double square_size_mm, double thickness_mm);

}  // namespace stereorig
