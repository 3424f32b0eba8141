#include "reconstruct/kd_tree.h"

#include <cmath>
#include <nanoflann.hpp>

namespace stereorig {

namespace {
struct Adaptor {
  const std::vector<Eigen::Vector3d>* pts;
  size_t kdtree_get_point_count() const { return pts->size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return (*pts)[i][dim]; }
  template <class Bbox>
  bool kdtree_get_bbox(Bbox&) const {
    return false;
  }
};
using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Adaptor>, Adaptor, 3, uint32_t>;
}  // namespace

struct KdTree3::Impl {
  Adaptor adaptor;
  Tree tree;
  explicit Impl(const std::vector<Eigen::Vector3d>* p)
      : adaptor{p}, tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {
    tree.buildIndex();
  }
};

KdTree3::KdTree3(std::vector<Eigen::Vector3d> points)
    : points_(std::move(points)), impl_(std::make_unique<Impl>(&points_)) {}
KdTree3::~KdTree3() = default;

void KdTree3::Knn(const Eigen::Vector3d& q, int k, std::vector<int>* indices, std::vector<double>* sq_dist) const {
  std::vector<uint32_t> idx(k);
  sq_dist->assign(k, 0.0);
  const size_t found = impl_->tree.knnSearch(q.data(), k, idx.data(), sq_dist->data());
  indices->assign(idx.begin(), idx.begin() + found);
  sq_dist->resize(found);
}

double KdTree3::NearestDistance(const Eigen::Vector3d& q) const {
  uint32_t idx = 0;
  double d2 = 0;
  if (impl_->tree.knnSearch(q.data(), 1, &idx, &d2) == 0) return INFINITY;
  return std::sqrt(d2);
}

}  // namespace stereorig
