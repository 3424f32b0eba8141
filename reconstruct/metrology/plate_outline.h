// The outline of a plate's face from its measured points: the smallest-area
// rectangle, in the plane, holding the *dense part* of the points. verify
// uses it to check that the plane found is the plate (coverage) and to erode
// the face by the edge margin. Taken from every point, one stray point inside
// the capture band (a speck of the table, a mismatched pixel) widened the
// outline: the coverage check could accept a plate seen too little, and the
// edge margin moved off the real edge on that side.
//
// The dense part: the points are binned in square cells in the plane; a cell
// is dense if it holds at least a quarter of the median occupied cell's
// points, and the dense cells' 8-connected groups that hold at least 2 % of
// the dense points are the face (a gap across it, a shadow or a seam, splits
// it into groups that are all the plate's; a clump of strays is not 2 %). The cell is the smallest of 1, 2, 3, 4, 6, 8,
// 12, 16 mm whose median occupied cell holds at least 6 points, so one or two stray points in a cell are under the
// quarter however dense or sparse the cloud, and a clump of strays dense enough is still not connected to the face;
// and whose kept groups hold at least half of the dense points, so a face seen as rows further apart than a cell
// (a grazing view, a line scanner's profiles) is joined by a larger cell, not dropped row by row. A
// real edge loses at most the cells less than a quarter covered: at most a quarter of a cell on each side (0.25 mm for
// the demo plate's 1 mm cells). The cells are fixed in the plane (about the world origin), so added points cannot shift
// them.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace stereorig {

// A rectangle in a plane: u along its longer side and v across it, both
// unit and in the plane; its sides at u0..u1 along u and v0..v1 along v,
// measured from `mean` (the dense points' mean).
struct PlaneOutline {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero(), u = Eigen::Vector3d::UnitX(), v = Eigen::Vector3d::UnitY();
  double u0_mm = 0, u1_mm = 0, v0_mm = 0, v1_mm = 0;
  double cell_mm = 0;      // the density cell used
  int points_outside = 0;  // of the given points, those not in the dense part
  double length_mm() const { return u1_mm - u0_mm; }
  double width_mm() const { return v1_mm - v0_mm; }
  // Inside the outline eroded by `margin_mm` on every side.
  bool InsideEroded(const Eigen::Vector3d& p, double margin_mm) const;
};

// points: (N) mm; indices: those of the plane's points (at least 3);
// normal: the plane's unit normal.
PlaneOutline OutlineOfDensePart(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& indices,
                                const Eigen::Vector3d& normal);

}  // namespace stereorig
