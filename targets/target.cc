#include "targets/target.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "calib/core/input_error.h"
#include "calib/core/number_text.h"

namespace stereorig {

namespace {

// The smallest square a target may have, mm. A target's squares span
// several pixels in its views (at 200 mm with a 1000 px focal length, 1 mm
// is 5 px), and a size under this is a value typed in metres (a 9 mm square
// as 0.009), which the tags' placement in mm would otherwise reject as "tag 0
// must lie in the margin".
constexpr double kMinSquareSizeMm = 1.0;

}  // namespace

const char* FaceName(Face face) { return face == Face::kFront ? "front" : "back"; }

std::string SmallSquareHint(double square_size_mm) {
  if (!(square_size_mm > 0 && square_size_mm < kMinSquareSizeMm)) return "";
  // The unit it most likely is in: in centimetres, 0.1 to 1 is a square of
  // 1 to 10 mm, a board's usual; in metres, one of 100 mm to 1 m. Under
  // 0.1, centimetres would be under 1 mm, and metres are the slip.
  const char* unit = square_size_mm >= 0.1 ? "centimetres" : "metres";
  return "squares of " + NumberText(1000 * square_size_mm) + " um, under the " + NumberText(kMinSquareSizeMm) +
         " mm a camera resolves; is it in " + unit + "? the unit is mm";
}

Target::Target(Layout layout, const std::string& where) : layout_(std::move(layout)) {
  const Layout& l = layout_;
  if (l.corners_x < 2 || l.corners_y < 2) throw InputError(where, "a chessboard needs at least 2x2 inner corners");
  // A square board is rotationally symmetric, so corner order is ambiguous
  // without tags; even x odd dimensions break the 180-degree symmetry too.
  if (l.square_size_mm <= 0) throw InputError(where, "square_size_mm must be positive");
  // Said before the tags' placement, which fails against squares of
  // micrometres.
  if (const std::string hint = SmallSquareHint(l.square_size_mm); !hint.empty())
    throw InputError(where, "square_size_mm " + NumberText(l.square_size_mm) + ": " + hint);
  if (l.margin_mm < 0) throw InputError(where, "margin_mm must not be negative");
  if (l.flatness_allowance_mm < 0) throw InputError(where, "flatness_allowance_mm must not be negative");
  std::string why;
  if (!IsRigid(l.back_from_front.ToMatrix4(), 1e-9, &why)) throw InputError(where, "back_from_front: " + why);
  // A back face faces away from the front: each face's z points into the
  // plate, so the two z axes are opposite (a turn of about 180 deg about y,
  // IdealBackFromFront), within a misaligned print's degrees. A rotation
  // left at the identity (z kept) was read, and calibrate refused only
  // after its whole solve ("stage 3 did not converge: rms 21 px").
  const double z_turn_deg = std::acos(std::clamp(l.back_from_front.rotation()(2, 2), -1.0, 1.0)) * 180 / M_PI;
  if (l.double_sided && !(z_turn_deg > 90))
    throw InputError(where, "back_from_front: its rotation turns the back face's z axis " + NumberText(z_turn_deg, 3) +
                                " deg from the front's: a back face faces away from the front (z into the plate on "
                                "each face), turned about 180 deg (about y: diag(-1, 1, -1))");
  const int faces = l.double_sided ? 2 : 1;
  if (!l.double_sided && (!l.faces[0].tags.empty() || !l.faces[1].tags.empty())) {
    throw InputError(where, "a plain (one-sided) board carries no tags");
  }
  std::set<int> seen;
  if (l.double_sided) {
    if (SupportedTagFamilies().end() ==
        std::find(SupportedTagFamilies().begin(), SupportedTagFamilies().end(), l.tag_family)) {
      throw InputError(where, "unknown tag family '" + l.tag_family + "'");
    }
    if (l.tag_size_mm <= 0 || l.tag_size_mm > l.margin_mm) {
      throw InputError(where, "tag_size_mm must be positive and fit in the margin (margin_mm)");
    }
    const int ncodes = TagFamilySize(l.tag_family);
    for (int f = 0; f < faces; ++f) {
      if (l.faces[f].tags.empty()) throw InputError(where, std::string(FaceName(Face(f))) + " face has no tags");
      for (const TagPlacement& t : l.faces[f].tags) {
        if (t.id < 0 || t.id >= ncodes) {
          throw InputError(where, "tag id " + std::to_string(t.id) + " is outside " + l.tag_family + " (0.." +
                                      std::to_string(ncodes - 1) + ")");
        }
        if (!seen.insert(t.id).second) {
          throw InputError(where,
                           "tag id " + std::to_string(t.id) + " is used twice (the faces' ID ranges must be disjoint)");
        }
        const double h = 0.5 * l.tag_size_mm;
        const double s = l.square_size_mm;
        const bool on_plate = t.center_x_mm - h >= min_x_mm() && t.center_x_mm + h <= max_x_mm() &&
                              t.center_y_mm - h >= min_y_mm() && t.center_y_mm + h <= max_y_mm();
        const bool off_squares = t.center_x_mm + h <= -s || t.center_x_mm - h >= l.corners_x * s ||
                                 t.center_y_mm + h <= -s || t.center_y_mm - h >= l.corners_y * s;
        if (!on_plate || !off_squares) {
          throw InputError(where, "tag " + std::to_string(t.id) + " must lie in the margin, off the squares");
        }
        tag_bits_[f].push_back(RenderTagBits(l.tag_family, t.id));
      }
      // Two tags of one face printed over each other are read as neither
      // (a small grid in the default's design spaces its four tags closer
      // than their size), and touching ones are missed too: a tag's black
      // border needs white around it. Measured on the simulator (`target
      // --corners 7 5 --square-mm 5.5`: 11 mm tags 11 mm apart): 9 of 48
      // views without a tag, none with a 1.4 mm gap. So the borders must be
      // at least an eighth of a tag apart (tag36h11's module).
      const std::vector<TagPlacement>& tags = l.faces[f].tags;
      const double min_gap_mm = l.tag_size_mm / 8, min_apart_mm = l.tag_size_mm + min_gap_mm;
      for (size_t a = 0; a < tags.size(); ++a)
        for (size_t b = a + 1; b < tags.size(); ++b)
          if (std::abs(tags[a].center_x_mm - tags[b].center_x_mm) < min_apart_mm &&
              std::abs(tags[a].center_y_mm - tags[b].center_y_mm) < min_apart_mm) {
            char apart[64];
            std::snprintf(apart, sizeof apart, "%.3g mm", min_apart_mm);
            throw InputError(where, "tags " + std::to_string(tags[a].id) + " and " + std::to_string(tags[b].id) +
                                        " are too close: their centres must be at least tag_size_mm + 1/8 of it (" +
                                        apart + ") apart along x or y, for the white between them");
          }
    }
  }
}

Eigen::Vector3d Target::CornerInFace(int id) const {
  STEREORIG_CHECK(id >= 0 && id < num_corners());
  return Eigen::Vector3d((id % layout_.corners_x) * layout_.square_size_mm,
                         (id / layout_.corners_x) * layout_.square_size_mm, 0.0);
}

bool Target::FaceOfTag(int tag_id, Face* face) const {
  for (int f = 0; f < 2; ++f) {
    if (FindTag(Face(f), tag_id)) {
      if (face) *face = Face(f);
      return true;
    }
  }
  return false;
}

const TagPlacement* Target::FindTag(Face face, int tag_id) const {
  for (const TagPlacement& t : layout_.faces[static_cast<int>(face)].tags)
    if (t.id == tag_id) return &t;
  return nullptr;
}

bool Target::IsBlack(Face face, double x_mm, double y_mm) const {
  const double s = layout_.square_size_mm;
  const int f = static_cast<int>(face);
  // Chessboard: squares from -s to corners*s; the square whose top-left
  // corner is inner corner (0,0) is white, so the outer-top-left one is black.
  if (x_mm >= -s && x_mm < layout_.corners_x * s && y_mm >= -s && y_mm < layout_.corners_y * s) {
    const int i = static_cast<int>(std::floor(x_mm / s));
    const int j = static_cast<int>(std::floor(y_mm / s));
    return ((i + j) & 1) != 0;
  }
  const auto& tags = layout_.faces[f].tags;
  for (size_t k = 0; k < tags.size(); ++k) {
    const TagBits& b = tag_bits_[f][k];
    const double cell = layout_.tag_size_mm / b.width_at_border;
    const double half = 0.5 * cell * b.total_width;
    const double u = x_mm - (tags[k].center_x_mm - half);
    const double v = y_mm - (tags[k].center_y_mm - half);
    if (u < 0 || v < 0 || u >= 2 * half || v >= 2 * half) continue;
    const int cx = std::min(b.total_width - 1, static_cast<int>(u / cell));
    const int cy = std::min(b.total_width - 1, static_cast<int>(v / cell));
    return b.black[cy * b.total_width + cx];
  }
  return false;
}

Pose IdealBackFromFront(int corners_x, double square_size_mm, double thickness_mm) {
  // front_from_back: x_f = (corners_x-1)*s - x_b, y_f = y_b, z_f = t - z_b
  // (z_b = 0 is the back surface, at depth t behind the front surface).
  const Eigen::Matrix3d r = Eigen::Vector3d(-1, 1, -1).asDiagonal();
  const Pose front_from_back(r, Eigen::Vector3d((corners_x - 1) * square_size_mm, 0, thickness_mm));
  return front_from_back.Inverse();
}

Target DefaultTarget() { return DoubleSidedTarget(11, 9, 9.0); }

Target DoubleSidedTarget(int corners_x, int corners_y, double square_size_mm) {
  Target::Layout l;
  l.corners_x = corners_x;
  l.corners_y = corners_y;
  l.square_size_mm = square_size_mm;
  l.back_from_front = IdealBackFromFront(l.corners_x, l.square_size_mm, 5.0);
  // As measured on a coordinate measuring machine: 0.01 deg, 0.01 mm (1 sigma).
  l.back_from_front_sigma << 0.01, 0.01, 0.01, 0.01, 0.01, 0.01;
  l.flatness_allowance_mm = 0.02;
  // Four tags in the top margin and four in the bottom one, per face. Their
  // layout is the same on both faces; only the IDs differ.
  const double s = l.square_size_mm;
  const double top_y = -s - 0.5 * l.margin_mm, bottom_y = l.corners_y * s + 0.5 * l.margin_mm;
  const double x0 = -s, x1 = l.corners_x * s;
  for (int f = 0; f < 2; ++f) {
    int id = f == 0 ? 0 : 100;
    for (double y : {top_y, bottom_y}) {
      for (int k = 0; k < 4; ++k) {
        const double x = x0 + (x1 - x0) * (k + 0.5) / 4.0;
        l.faces[f].tags.push_back({id++, x, y});
      }
    }
  }
  return Target(l, "double-sided target");
}

Target PlainTarget(int corners_x, int corners_y, double square_size_mm) {
  Target::Layout l;
  l.corners_x = corners_x;
  l.corners_y = corners_y;
  l.square_size_mm = square_size_mm;
  l.double_sided = false;
  l.margin_mm = square_size_mm;
  return Target(l, "plain target");
}

}  // namespace stereorig
