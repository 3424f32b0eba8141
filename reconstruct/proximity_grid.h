// "Is any point within r of q?" over a fixed point set, for hole filling:
// a uniform grid of cubic cells over the points' bounding box, the points
// sorted by cell (a counting sort, so building is O(N) and deterministic).
// A query visits only the cells the ball of radius r touches; with r close
// to the cell size that is 27 cells, and it stops at the first point found.
// For this one question it beats a k-d tree (no descent, no priority queue)
// and is simpler; nearest-neighbour and k-nearest queries stay with
// kd_tree.h.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace stereorig {

class ProximityGrid {
 public:
  // points: (N), mm. cell_mm > 0: the cell edge; choose about the query
  // radius. If the bounding box would need more than ~16M cells the edge is
  // enlarged (queries stay correct, only slower).
  ProximityGrid(const std::vector<Eigen::Vector3f>& points_mm, double cell_mm);

  // True if some point lies within radius_mm of q (distance <= radius_mm).
  // Thread-safe (const).
  bool AnyWithin(const Eigen::Vector3d& q, double radius_mm) const;

  double cell_mm() const { return cell_mm_; }
  size_t size() const { return points_.size(); }

 private:
  int64_t CellIndex(int ix, int iy, int iz) const { return ix + int64_t(nx_) * (iy + int64_t(ny_) * iz); }

  double cell_mm_ = 1;
  Eigen::Vector3d origin_mm_ = Eigen::Vector3d::Zero();  // the bounding box's minimum corner
  int nx_ = 0, ny_ = 0, nz_ = 0;
  std::vector<int> cell_start_;          // (nx*ny*nz + 1): cell c's points are [start[c], start[c+1])
  std::vector<Eigen::Vector3f> points_;  // sorted by cell
};

}  // namespace stereorig
