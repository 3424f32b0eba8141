#include "calib/check/check_target.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>
#include <vector>

#include "calib/core/input_error.h"
#include "calib/core/number_text.h"

namespace stereorig {
namespace {

std::string Describe(int corners_x, int corners_y, double square_size_mm, bool double_sided) {
  return std::to_string(corners_x) + "x" + std::to_string(corners_y) + " inner corners of " +
         NumberText(square_size_mm, 12) + " mm, " + (double_sided ? "double-sided" : "one-sided");
}

}  // namespace

CheckTarget TargetForCheck(const Rig& rig, const Target& file_target, const std::string& target_path) {
  CheckTarget out(file_target);
  const std::optional<CalibrationTarget>& rec = rig.provenance().target;
  if (!rec) {
    out.note =
        "the rig file records no calibration target (it is from an older stereorig): the check uses the "
        "target file's back_from_front, which the calibration may have refined (its report's "
        "stage3_system.back_from_front_change_mm); a calibration by this version records it";
    return out;
  }
  const std::string recorded_file = rec->file.empty() ? "no file" : rec->file;
  const double square_off = file_target.square_size_mm() / rec->square_size_mm - 1;
  if (rec->corners_x != file_target.corners_x() || rec->corners_y != file_target.corners_y() ||
      std::abs(square_off) > kSameBoardSquareOff || rec->double_sided != file_target.double_sided()) {
    throw InputError(target_path,
                     "a board of " +
                         Describe(file_target.corners_x(), file_target.corners_y(), file_target.square_size_mm(),
                                  file_target.double_sided()) +
                         ", but " + rig.Where() + " was calibrated with one of " +
                         Describe(rec->corners_x, rec->corners_y, rec->square_size_mm, rec->double_sided) +
                         " (its provenance.target, from " + recorded_file +
                         "): the rig's scale rests on that board's squares and its S on that board's faces; check "
                         "with its target file, or calibrate again with this board");
  }
  out.as_calibrated = true;
  out.calibrated_with = rec->file;
  std::vector<std::string> notes;
  Target::Layout layout = file_target.layout();
  if (square_off != 0) {  // the same board, its squares re-measured (or printed with more digits)
    layout.square_size_mm = rec->square_size_mm;
    if (std::abs(square_off) >= 5e-7)  // a difference 6 printed digits show
      notes.push_back("the target file's squares are " + NumberText(file_target.square_size_mm(), 12) +
                      " mm, the rig was calibrated with " + NumberText(rec->square_size_mm, 12) +
                      " mm: measured with " + NumberText(rec->square_size_mm, 12) +
                      " mm, on which the rig's scale rests (the file's " + (square_off > 0 ? "+" : "") +
                      NumberText(100 * square_off, 3) + " %); calibrate again to take the new size");
  }
  if (rec->double_sided) {
    // Tonight's file against the one filed at calibration: two
    // measurements of one plate differ per axis with sigma^2 the sum of the
    // two files' (the rotation vector of R_file R_filed^T in deg, as stage 3
    // perturbs it, then the translation in mm). An axis whose sigma is 0 in
    // both is held: it must not move. Where the squares were re-measured,
    // the file's in-plane offset (tx, ty) is read both as written and at the
    // record's square size (it scales with the print, the plate's thickness
    // tz does not; a user may have updated it or not), the nearer taken.
    const Pose& file = file_target.back_from_front();
    const Eigen::Vector3d turn_deg = PlateTurnDeg(file, rec->back_from_front_file);
    Eigen::Matrix<double, 6, 1> variance;
    for (int k = 0; k < 6; ++k)
      variance(k) =
          std::pow(file_target.back_from_front_sigma()(k), 2) + std::pow(rec->back_from_front_sigma_file(k), 2);
    struct Reading {
      PlateDifference d;
      Eigen::Vector3d shift_mm = Eigen::Vector3d::Zero();
    };
    std::optional<Reading> nearer;  // of the two readings below
    for (const double scale : {1.0, rec->square_size_mm / file_target.square_size_mm()}) {
      Reading r;
      r.shift_mm = file.translation_mm() - rec->back_from_front_file.translation_mm();
      r.shift_mm.head<2>() =
          file.translation_mm().head<2>() * scale - rec->back_from_front_file.translation_mm().head<2>();
      Eigen::Matrix<double, 6, 1> off;
      off << turn_deg, r.shift_mm;
      r.d = ComparePlates(off, variance);
      if (!nearer || std::make_pair(r.d.held_moved >= 0, r.d.chi_square) <
                         std::make_pair(nearer->d.held_moved >= 0, nearer->d.chi_square))
        nearer = r;
    }
    const Reading& reading = *nearer;
    const PlateDifference& best = reading.d;
    out.file_vs_filed_mm = reading.shift_mm.norm();
    out.file_vs_filed_deg = turn_deg.norm();
    char moved[96];
    std::snprintf(moved, sizeof moved, "%.4f mm and %.4f deg", out.file_vs_filed_mm, out.file_vs_filed_deg);
    if (!best.SamePlate()) {
      char why[200];
      if (best.held_moved >= 0)
        std::snprintf(why, sizeof why, "its %s moved, which both files hold (sigma 0)", PlateAxisName(best.held_moved));
      else
        std::snprintf(why, sizeof why,
                      "chi-square %.1f over both files' sigmas, above %.2f, which two measurements of one plate "
                      "exceed 3 times in 1000 (most on %s: %+.4f %s against a sigma of %.4f)",
                      best.chi_square, best.Bound(), PlateAxisName(best.worst), best.worst_off,
                      PlateAxisUnit(best.worst), best.worst_sigma);
      throw InputError(target_path, std::string("its back_from_front is ") + moved + " from the one filed when " +
                                        rig.Where() + " was calibrated (from " + recorded_file + "): " + why +
                                        ": another plate, or not this plate's file; the check's figures rest on "
                                        "the plate calibrated with: check with that plate and its file, or "
                                        "calibrate again with this one");
    }
    layout.back_from_front = rec->back_from_front;
    out.back_from_front_as_calibrated = true;
    if (out.file_vs_filed_mm >= kPlateUnchangedInPrint || out.file_vs_filed_deg >= kPlateUnchangedInPrint)
      notes.push_back(std::string("the target file's back_from_front is ") + moved +
                      " from the one filed when the rig was calibrated, as two measurements of one plate may "
                      "differ: measured with the calibration's estimate");
    out.calibrated_vs_file_deg = AngleBetweenDeg(file, rec->back_from_front);
    out.calibrated_vs_file_mm = TranslationBetweenMm(file, rec->back_from_front);
  }
  out.target = Target(layout, target_path);
  for (size_t k = 0; k < notes.size(); ++k) out.note += (k ? "; " : "") + notes[k];
  return out;
}

}  // namespace stereorig
