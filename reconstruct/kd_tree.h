// Nearest-neighbour queries over a point set (nanoflann k-d tree), for hole
// filling and for scoring clouds against a truth surface.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

namespace stereorig {

class KdTree3 {
 public:
  // Keeps a copy of the points (N, 3), mm.
  explicit KdTree3(std::vector<Eigen::Vector3d> points);
  ~KdTree3();
  KdTree3(const KdTree3&) = delete;
  KdTree3& operator=(const KdTree3&) = delete;

  // Indices of the k nearest points to `q`, nearest first, and their squared
  // distances. Thread-safe (const).
  void Knn(const Eigen::Vector3d& q, int k, std::vector<int>* indices, std::vector<double>* sq_dist) const;
  // Distance to the nearest point.
  double NearestDistance(const Eigen::Vector3d& q) const;
  const std::vector<Eigen::Vector3d>& points() const { return points_; }

 private:
  struct Impl;
  std::vector<Eigen::Vector3d> points_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stereorig
