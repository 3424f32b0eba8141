#include "calib/check/check_target.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "calib/core/input_error.h"
#include "calib/core/number_text.h"

namespace stereorig {
namespace {

std::string Describe(int corners_x, int corners_y, double square_size_mm, bool double_sided) {
  return std::to_string(corners_x) + "x" + std::to_string(corners_y) + " inner corners of " +
         NumberText(square_size_mm, 12) + " mm, " + (double_sided ? "double-sided" : "one-sided");
}

// The same number as a file prints it: equal to 1e-12 of the size (a file
// written by another tool may print fewer digits than ours).
bool SameSize(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(std::abs(a), std::abs(b)); }

}  // namespace

CheckTarget TargetForCheck(const Rig& rig, const Target& file_target, const std::string& target_path) {
  CheckTarget out(file_target);
  const std::optional<CalibrationTarget>& rec = rig.provenance().target;
  if (!rec) {
    out.note =
        "the rig file records no calibration target (a rig file from an older stereorig, or a simulator's truth): "
        "the modules' closures "
        "use the target file's back_from_front, which the calibration may have refined (its report's "
        "back_from_front_change_mm); a calibration by this version records it";
    return out;
  }
  if (rec->corners_x != file_target.corners_x() || rec->corners_y != file_target.corners_y() ||
      !SameSize(rec->square_size_mm, file_target.square_size_mm()) || rec->double_sided != file_target.double_sided()) {
    throw InputError(target_path,
                     "a board of " +
                         Describe(file_target.corners_x(), file_target.corners_y(), file_target.square_size_mm(),
                                  file_target.double_sided()) +
                         ", but " + rig.Where() + " was calibrated with one of " +
                         Describe(rec->corners_x, rec->corners_y, rec->square_size_mm, rec->double_sided) +
                         " (its provenance.target, from " + (rec->file.empty() ? "no file" : rec->file) +
                         "): the rig's scale rests on that board's squares and its S on that board's faces; check "
                         "with its target file, or calibrate again with this board");
  }
  out.as_calibrated = true;
  out.calibrated_with = rec->file;
  if (!rec->double_sided) return out;  // one face: back_from_front plays no part
  Target::Layout layout = file_target.layout();
  layout.back_from_front = rec->back_from_front;
  out.target = Target(layout, target_path);
  const Pose moved = file_target.back_from_front().Inverse() * rec->back_from_front;
  out.calibrated_vs_file_deg = moved.AngleDeg();
  out.calibrated_vs_file_mm =
      (rec->back_from_front.translation_mm() - file_target.back_from_front().translation_mm()).norm();
  const Pose refiled = rec->back_from_front_file.Inverse() * file_target.back_from_front();
  const double refiled_mm =
      (file_target.back_from_front().translation_mm() - rec->back_from_front_file.translation_mm()).norm();
  // Printed to 17 digits on both sides, an unchanged file reads back exactly;
  // these bounds admit another tool's 12 digits.
  if (refiled_mm > 1e-9 || refiled.AngleDeg() > 1e-9) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%.4f mm and %.4f deg", refiled_mm, refiled.AngleDeg());
    out.note = std::string("the target file's back_from_front is ") + buf +
               " from the one the rig was calibrated with (a re-measured plate, or another board of the same "
               "print): the check uses the calibrated one; if this is another board, calibrate again with it";
  }
  return out;
}

}  // namespace stereorig
