#include "reconstruct/proximity_grid.h"

#include <algorithm>
#include <cmath>

#include "calib/core/input_error.h"

namespace stereorig {

ProximityGrid::ProximityGrid(const std::vector<Eigen::Vector3f>& points_mm, double cell_mm) : cell_mm_(cell_mm) {
  STEREORIG_CHECK(cell_mm > 0);
  if (points_mm.empty()) return;
  Eigen::Vector3d lo = points_mm[0].cast<double>(), hi = lo;
  for (const auto& p : points_mm) {
    lo = lo.cwiseMin(p.cast<double>());
    hi = hi.cwiseMax(p.cast<double>());
  }
  // Far-flung outliers must not make the table huge: enlarge the cells.
  constexpr double kMaxCells = 16e6;
  const Eigen::Vector3d extent = hi - lo;
  while ((extent / cell_mm_ + Eigen::Vector3d::Ones()).prod() > kMaxCells) cell_mm_ *= 2;
  origin_mm_ = lo;
  nx_ = int(extent.x() / cell_mm_) + 1;
  ny_ = int(extent.y() / cell_mm_) + 1;
  nz_ = int(extent.z() / cell_mm_) + 1;
  std::vector<int64_t> cell(points_mm.size());
  cell_start_.assign(size_t(nx_) * ny_ * nz_ + 1, 0);
  for (size_t i = 0; i < points_mm.size(); ++i) {
    const Eigen::Vector3d u = (points_mm[i].cast<double>() - origin_mm_) / cell_mm_;
    cell[i] = CellIndex(std::min(nx_ - 1, int(u.x())), std::min(ny_ - 1, int(u.y())), std::min(nz_ - 1, int(u.z())));
    ++cell_start_[cell[i] + 1];
  }
  for (size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  std::vector<int> next(cell_start_.begin(), cell_start_.end() - 1);
  points_.resize(points_mm.size());
  for (size_t i = 0; i < points_mm.size(); ++i) points_[next[cell[i]]++] = points_mm[i];
}

bool ProximityGrid::AnyWithin(const Eigen::Vector3d& q, double radius_mm) const {
  if (points_.empty() || !q.allFinite()) return false;
  const Eigen::Vector3d lo = (q - origin_mm_ - Eigen::Vector3d::Constant(radius_mm)) / cell_mm_;
  const Eigen::Vector3d hi = (q - origin_mm_ + Eigen::Vector3d::Constant(radius_mm)) / cell_mm_;
  // Cells overlapping the ball's bounding box, clipped to the grid.
  const int x0 = std::max(0, int(std::floor(lo.x()))), x1 = std::min(nx_ - 1, int(std::floor(hi.x())));
  const int y0 = std::max(0, int(std::floor(lo.y()))), y1 = std::min(ny_ - 1, int(std::floor(hi.y())));
  const int z0 = std::max(0, int(std::floor(lo.z()))), z1 = std::min(nz_ - 1, int(std::floor(hi.z())));
  if (x0 > x1 || y0 > y1 || z0 > z1) return false;  // the ball misses the grid
  const Eigen::Vector3f qf = q.cast<float>();
  const float r2 = float(radius_mm * radius_mm);
  for (int z = z0; z <= z1; ++z)
    for (int y = y0; y <= y1; ++y) {
      const int64_t row = CellIndex(0, y, z);
      for (int i = cell_start_[row + x0]; i < cell_start_[row + x1 + 1]; ++i)
        if ((points_[i] - qf).squaredNorm() <= r2) return true;
    }
  return false;
}

}  // namespace stereorig
