// The plate's outline against the truth of a synthetic plate: its size is
// measured right, and one or a few stray points inside the capture band do
// not move it (before, the outline was the rectangle around every point).
#include "reconstruct/metrology/plate_outline.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

namespace stereorig {
namespace {

// A length x width plate's face in the plane through `c` with `normal`,
// sampled every `step_mm` from edge to edge, noise along the normal.
struct SyntheticPlate {
  Eigen::Vector3d c, normal, x, y;
  std::vector<Eigen::Vector3d> points;
  Eigen::Vector3d At(double u, double v) const { return c + u * x + v * y; }
};

SyntheticPlate MakePlate(double length_mm, double width_mm, double step_mm, double noise_mm, unsigned seed) {
  SyntheticPlate p;
  p.c = Eigen::Vector3d(3, -4, 200);
  p.normal = Eigen::Vector3d(0.1, -0.2, 1).normalized();
  // The plate's sides along a direction 20 deg off the plane's own
  // unitOrthogonal, so the outline's frame must be found, not given.
  const Eigen::Vector3d e = p.normal.unitOrthogonal();
  p.x = Eigen::AngleAxisd(20 * M_PI / 180, p.normal) * e;
  p.y = p.normal.cross(p.x);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, noise_mm);
  const int nu = static_cast<int>(std::lround(length_mm / step_mm)),
            nv = static_cast<int>(std::lround(width_mm / step_mm));
  for (int i = 0; i <= nu; ++i)
    for (int j = 0; j <= nv; ++j)
      p.points.push_back(p.At(i * step_mm - length_mm / 2, j * step_mm - width_mm / 2) + noise(rng) * p.normal);
  return p;
}

std::vector<int> All(const std::vector<Eigen::Vector3d>& pts) {
  std::vector<int> idx(pts.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<int>(i);
  return idx;
}

TEST(PlateOutline, MeasuresAPlatesSizeAndIgnoresStrayPoints) {
  // Truth: the samples span exactly 130 x 120 mm. The outline may lose the
  // edge cells less than a quarter covered: at most a quarter of a cell on
  // each side, 0.5 mm a side for the 2 mm cell that 0.5 mm sampling gets
  // (16 points a cell). Noise (0.05 mm along the normal) does not move
  // points in the plane.
  const SyntheticPlate plate = MakePlate(130, 120, 0.5, 0.05, 1);
  const PlaneOutline clean = OutlineOfDensePart(plate.points, All(plate.points), plate.normal);
  EXPECT_EQ(clean.cell_mm, 2.0);
  EXPECT_LE(clean.length_mm(), 130 + 1e-6);
  EXPECT_GE(clean.length_mm(), 130 - 2 * 0.25 * clean.cell_mm);
  EXPECT_LE(clean.width_mm(), 120 + 1e-6);
  EXPECT_GE(clean.width_mm(), 120 - 2 * 0.25 * clean.cell_mm);
  EXPECT_GT(std::abs(clean.u.dot(plate.x)), std::cos(0.1 * M_PI / 180));  // the long side found, within 0.1 deg

  // One stray point 20 mm beyond a long side, in the plane; then five more
  // scattered around the plate within 25 mm of it; then a clump of 4 points
  // within 1 mm, 15 mm off a corner. None may move the outline: it is the
  // same set of dense points, so the same rectangle to rounding.
  std::vector<std::vector<Eigen::Vector3d>> strays = {
      {plate.At(0, 80)},
      {plate.At(0, 80), plate.At(-85, 0), plate.At(80, -70), plate.At(70, 70), plate.At(-75, -65), plate.At(0, -78)},
      {plate.At(80, 75), plate.At(80.5, 75), plate.At(80, 75.7), plate.At(80.3, 75.4)},
  };
  for (const auto& extra : strays) {
    std::vector<Eigen::Vector3d> pts = plate.points;
    pts.insert(pts.end(), extra.begin(), extra.end());
    const PlaneOutline o = OutlineOfDensePart(pts, All(pts), plate.normal);
    SCOPED_TRACE(::testing::Message() << extra.size() << " stray point(s)");
    EXPECT_NEAR(o.length_mm(), clean.length_mm(), 1e-6);
    EXPECT_NEAR(o.width_mm(), clean.width_mm(), 1e-6);
    EXPECT_EQ(o.points_outside, clean.points_outside + static_cast<int>(extra.size()));
    // The eroded outline holds the same plate points.
    for (const Eigen::Vector3d& p : {plate.At(-59.9, 0), plate.At(59.9, 0), plate.At(0, 54.9), plate.At(0, -54.9),
                                     plate.At(0, 55.6), plate.At(60.6, 0)})
      EXPECT_EQ(o.InsideEroded(p, 5), clean.InsideEroded(p, 5));
  }
}

TEST(PlateOutline, SizesASparseOrDensePlateAlike) {
  // 1.5 mm sampling (0.4 points a 1 mm cell, 7 a 4 mm one: the outline takes
  // 4 mm cells, at most 1 mm lost a side) and 0.2 mm sampling (25 a 1 mm cell:
  // 0.25 mm a side). The points left out are those of the edge cells less
  // than a quarter covered: at most a strip a quarter of a cell wide along
  // the perimeter.
  for (const double step_mm : {1.5, 0.2}) {
    const SyntheticPlate plate = MakePlate(120, 90, step_mm, 0.05, 2);
    const PlaneOutline o = OutlineOfDensePart(plate.points, All(plate.points), plate.normal);
    SCOPED_TRACE(::testing::Message() << "step " << step_mm << " mm, cell " << o.cell_mm << " mm");
    EXPECT_EQ(o.cell_mm, step_mm > 1 ? 4.0 : 1.0);
    EXPECT_LE(o.length_mm(), 120 + 1e-6);
    EXPECT_GE(o.length_mm(), 120 - 0.5 * o.cell_mm);
    EXPECT_LE(o.width_mm(), 90 + 1e-6);
    EXPECT_GE(o.width_mm(), 90 - 0.5 * o.cell_mm);
    const double strip_points = 2 * (120 + 90) * 0.25 * o.cell_mm / (step_mm * step_mm);
    EXPECT_LE(o.points_outside, strip_points);
  }
}

// A face seen as rows: a plate at a grazing angle, or a line scanner's
// profiles, rows 2 mm apart across the plate, points 0.15 mm apart along
// them. 1 mm cells hold ~6.7 points where a row crosses them and every other
// row of cells is empty: each row was a group of its own, 1/56 of the dense
// points, under the 2% a group must hold, and all were dropped (outline 0 x
// 0: verify refused the plate as "the plane found spans 0.0 x 0.0 mm").
// Truth: the rows span 129.9 x 110 mm; a 2 mm cell joins them and may lose
// a quarter of a cell a side: within 1 mm; the points left out, those of
// edge cells less than a quarter covered, under 2%.
TEST(PlateOutline, AFaceSeenAsRowsFurtherApartThanACellIsJoinedNotDropped) {
  // The rows along the cells (the plane's own frame, through the origin's
  // foot, so that the cells are whole millimetres along the rows' spacing):
  // rows at an angle to the cells touch diagonally and held together.
  const Eigen::Vector3d normal = Eigen::Vector3d(0.1, -0.2, 1).normalized();
  const Eigen::Vector3d x = normal.unitOrthogonal(), y = normal.cross(x), c = 200 * normal;
  std::vector<Eigen::Vector3d> pts;
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0, 0.05);
  for (double v = -54.5; v <= 55.5; v += 2)
    for (int i = 0; i <= 866; ++i) pts.push_back(c + (-65 + 0.15 * i) * x + v * y + noise(rng) * normal);
  const PlaneOutline e = OutlineOfDensePart(pts, All(pts), normal);
  EXPECT_NEAR(e.length_mm(), 129.9, 1.0);
  EXPECT_NEAR(e.width_mm(), 110, 1.0);
  EXPECT_LT(e.points_outside, static_cast<int>(0.02 * pts.size()));
}

}  // namespace
}  // namespace stereorig
