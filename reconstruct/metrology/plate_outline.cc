#include "reconstruct/metrology/plate_outline.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <tuple>
#include <utility>

namespace stereorig {

namespace {

constexpr double kDenseFractionOfMedian = 0.25;
// A group of dense cells is the face's if it holds at least this share of
// the dense points: a gap across the face (a shadow, a glare streak, a seam
// the grid does not light) splits it into groups that are all the plate's,
// and the largest alone dropped the rest from the figures (a warped strip
// beyond a 4 mm gap: F 2.35 mm FAIL read 0.29 mm PASS). A clump of strays is
// a cell or two of a face's hundreds.
constexpr double kMinGroupShareOfDensePoints = 0.02;
constexpr int kMinMedianCellPoints = 6;
// A cell size at which the face's groups hold less of the dense points than
// this has split the face into pieces each too small to keep (rows of
// points further apart than a cell): the next size is tried.
constexpr double kMinFaceShareOfDensePoints = 0.5;
constexpr double kCellSizesMm[] = {1, 2, 3, 4, 6, 8, 12, 16};

using Cell = std::pair<long, long>;

double Cross2(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
}

// Andrew's monotone chain: the convex hull, counter-clockwise.
std::vector<Eigen::Vector2d> ConvexHull(std::vector<Eigen::Vector2d> q) {
  std::sort(q.begin(), q.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (q.size() < 3) return q;
  std::vector<Eigen::Vector2d> hull(2 * q.size());
  size_t k = 0;
  for (size_t i = 0; i < q.size(); ++i) {  // lower hull
    while (k >= 2 && Cross2(hull[k - 2], hull[k - 1], q[i]) <= 0) --k;
    hull[k++] = q[i];
  }
  for (size_t i = q.size() - 1, lower = k + 1; i-- > 0;) {  // upper hull
    while (k >= lower && Cross2(hull[k - 2], hull[k - 1], q[i]) <= 0) --k;
    hull[k++] = q[i];
  }
  hull.resize(k - 1);
  return hull;
}

Cell CellOf(const Eigen::Vector2d& q, double cell_mm) {
  return {static_cast<long>(std::floor(q.x() / cell_mm)), static_cast<long>(std::floor(q.y() / cell_mm))};
}

std::map<Cell, int> CountPerCell(const std::vector<Eigen::Vector2d>& q, double cell_mm) {
  std::map<Cell, int> counts;
  for (const Eigen::Vector2d& p : q) ++counts[CellOf(p, cell_mm)];
  return counts;
}

int MedianCount(const std::map<Cell, int>& counts) {
  std::vector<int> c;
  c.reserve(counts.size());
  for (const auto& [cell, n] : counts) c.push_back(n);
  std::nth_element(c.begin(), c.begin() + c.size() / 2, c.end());
  return c[c.size() / 2];
}

// The dense cells' 8-connected groups holding at least
// kMinGroupShareOfDensePoints of the dense points.
std::map<Cell, int> FaceGroups(const std::map<Cell, int>& counts) {
  const double dense = kDenseFractionOfMedian * MedianCount(counts);
  std::map<Cell, int> group_of;  // dense cell -> group id
  for (const auto& [cell, n] : counts)
    if (n >= dense) group_of[cell] = -1;
  std::vector<int> group_points;
  for (auto& [seed, id] : group_of) {
    if (id >= 0) continue;
    const int g = static_cast<int>(group_points.size());
    group_points.push_back(0);
    std::vector<Cell> stack = {seed};
    id = g;
    while (!stack.empty()) {
      const Cell c = stack.back();
      stack.pop_back();
      group_points[g] += counts.at(c);
      for (long du = -1; du <= 1; ++du)
        for (long dv = -1; dv <= 1; ++dv) {
          const auto it = group_of.find({c.first + du, c.second + dv});
          if (it == group_of.end() || it->second >= 0) continue;
          it->second = g;
          stack.push_back(it->first);
        }
    }
  }
  double dense_points = 0;
  for (const int n : group_points) dense_points += n;
  std::map<Cell, int> kept;
  for (const auto& [cell, id] : group_of)
    if (group_points[id] >= kMinGroupShareOfDensePoints * dense_points) kept[cell] = counts.at(cell);
  return kept;
}

// The share of the dense cells' points that FaceGroups kept.
double FaceShareOfDensePoints(const std::map<Cell, int>& counts, const std::map<Cell, int>& face) {
  const double dense = kDenseFractionOfMedian * MedianCount(counts);
  double dense_points = 0, face_points = 0;
  for (const auto& [cell, n] : counts)
    if (n >= dense) dense_points += n;
  for (const auto& [cell, n] : face) face_points += n;
  return dense_points > 0 ? face_points / dense_points : 0.0;
}

}  // namespace

bool PlaneOutline::InsideEroded(const Eigen::Vector3d& p, double margin_mm) const {
  const Eigen::Vector3d d = p - mean;
  return d.dot(u) > u0_mm + margin_mm && d.dot(u) < u1_mm - margin_mm && d.dot(v) > v0_mm + margin_mm &&
         d.dot(v) < v1_mm - margin_mm;
}

PlaneOutline OutlineOfDensePart(const std::vector<Eigen::Vector3d>& pts, const std::vector<int>& idx,
                                const Eigen::Vector3d& normal) {
  PlaneOutline e;
  if (idx.empty()) return e;
  // In-plane coordinates about the world's origin, not the points' mean: the
  // cells must not move when a stray point is added.
  const Eigen::Vector3d a = normal.unitOrthogonal(), b = normal.cross(a);
  std::vector<Eigen::Vector2d> q;
  q.reserve(idx.size());
  for (int i : idx) q.emplace_back(pts[i].dot(a), pts[i].dot(b));

  // The smallest cell whose median occupied cell holds enough points, and
  // in which the face holds together: its groups of at least 2% hold most
  // of the dense points. A face seen as rows (a plate at a grazing angle, a
  // line scanner's profiles) rows 2 mm apart and dense along them filled
  // every other 1 mm cell: each row its own group, under 2% once there were
  // over 50 of them, and every one dropped ("the plane found spans 0.0 x
  // 0.0 mm"); a larger cell joins the rows.
  std::map<Cell, int> counts, face;
  for (double cell_mm : kCellSizesMm) {
    e.cell_mm = cell_mm;
    counts = CountPerCell(q, cell_mm);
    if (MedianCount(counts) < kMinMedianCellPoints && cell_mm != kCellSizesMm[std::size(kCellSizesMm) - 1]) continue;
    face = FaceGroups(counts);
    if (FaceShareOfDensePoints(counts, face) >= kMinFaceShareOfDensePoints) break;
  }
  std::vector<Eigen::Vector2d> dense;
  dense.reserve(q.size());
  e.mean.setZero();
  for (size_t k = 0; k < q.size(); ++k) {
    if (!face.count(CellOf(q[k], e.cell_mm))) continue;
    dense.push_back(q[k]);
    e.mean += pts[idx[k]];
  }
  e.points_outside = static_cast<int>(q.size() - dense.size());
  if (dense.empty()) return e;  // nothing dense: no outline (0 x 0), not NaN
  e.mean /= static_cast<double>(dense.size());
  // The rectangle's sides are measured about the dense points' mean.
  const Eigen::Vector2d mean_ab(e.mean.dot(a), e.mean.dot(b));
  for (Eigen::Vector2d& p : dense) p -= mean_ab;

  // The smallest-area enclosing rectangle has a side along an edge of the
  // convex hull (Freeman and Shapira): try each. Not the principal axes: a
  // square plate's are arbitrary, and its diagonals would be taken for sides.
  const std::vector<Eigen::Vector2d> hull = ConvexHull(std::move(dense));
  double best_area_mm2 = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < hull.size(); ++k) {
    const Eigen::Vector2d side = hull[(k + 1) % hull.size()] - hull[k];
    if (side.norm() == 0) continue;
    const Eigen::Vector2d s = side.normalized(), t(-s.y(), s.x());
    double s0 = 1e300, s1 = -1e300, t0 = 1e300, t1 = -1e300;
    for (const Eigen::Vector2d& h : hull) {
      s0 = std::min(s0, h.dot(s)), s1 = std::max(s1, h.dot(s));
      t0 = std::min(t0, h.dot(t)), t1 = std::max(t1, h.dot(t));
    }
    if ((s1 - s0) * (t1 - t0) >= best_area_mm2) continue;
    best_area_mm2 = (s1 - s0) * (t1 - t0);
    const bool s_longer = s1 - s0 >= t1 - t0;
    const Eigen::Vector3d s3 = s.x() * a + s.y() * b, t3 = t.x() * a + t.y() * b;
    e.u = s_longer ? s3 : t3;
    e.v = s_longer ? t3 : s3;
    std::tie(e.u0_mm, e.u1_mm, e.v0_mm, e.v1_mm) =
        s_longer ? std::make_tuple(s0, s1, t0, t1) : std::make_tuple(t0, t1, s0, s1);
  }
  return e;
}

}  // namespace stereorig
