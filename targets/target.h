// PLACEHOLDER until the targets/ branch lands in main: the shared target API
// (as agreed in the brief), header-only, so calib/ compiles against it. On
// merge, the real targets/target.h replaces this file.
#pragma once

#include <Eigen/Core>

#include "calib/core/pose.h"

namespace stereorig {

enum class Face { kFront = 0, kBack = 1 };

class Target {
 public:
  Target(int corners_x, int corners_y, double square_size_mm, bool double_sided, const Pose& back_from_front,
         const Eigen::Matrix<double, 6, 1>& back_from_front_sigma)
      : corners_x_(corners_x),
        corners_y_(corners_y),
        square_size_mm_(square_size_mm),
        double_sided_(double_sided),
        back_from_front_(back_from_front),
        back_from_front_sigma_(back_from_front_sigma) {}
  int corners_x() const { return corners_x_; }
  int corners_y() const { return corners_y_; }
  double square_size_mm() const { return square_size_mm_; }
  int num_corners() const { return corners_x_ * corners_y_; }
  bool double_sided() const { return double_sided_; }
  Eigen::Vector3d CornerInFace(int id) const {
    return Eigen::Vector3d((id % corners_x_) * square_size_mm_, (id / corners_x_) * square_size_mm_, 0.0);
  }
  const Pose& back_from_front() const { return back_from_front_; }
  const Eigen::Matrix<double, 6, 1>& back_from_front_sigma() const { return back_from_front_sigma_; }

 private:
  int corners_x_, corners_y_;
  double square_size_mm_;
  bool double_sided_;
  Pose back_from_front_;
  Eigen::Matrix<double, 6, 1> back_from_front_sigma_;
};

}  // namespace stereorig
