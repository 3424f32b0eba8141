// One camera: an mrcal lens model, its intrinsics and its imager size.
//
// Projection and unprojection go through mrcal's C API, so every lens model
// mrcal knows (LENSMODEL_OPENCV8, LENSMODEL_SPLINED_STEREOGRAPHIC_..., ...)
// behaves exactly as it does in mrcal. Points are in the camera frame, in mm;
// pixels follow mrcal: (0,0) is the centre of the top-left pixel.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

namespace stereorig {

class Camera {
 public:
  // Validates the model name (as mrcal spells it, configuration included for
  // splined models) and the number of intrinsics. Throws InputError, whose
  // message starts with `where` (a file and key), on any problem.
  Camera(const std::string& lensmodel_name, std::vector<double> intrinsics, int imager_width_px, int imager_height_px,
         const std::string& where = "camera");
  Camera(const Camera&);
  Camera& operator=(const Camera&);
  Camera(Camera&&) noexcept;
  Camera& operator=(Camera&&) noexcept;
  ~Camera();

  // Number of intrinsics the named model takes, or -1 if mrcal does not know
  // the name (or its configuration is bad).
  static int NumIntrinsics(const std::string& lensmodel_name);

  const std::string& lensmodel_name() const { return lensmodel_name_; }
  const std::vector<double>& intrinsics() const { return intrinsics_; }
  int imager_width_px() const { return imager_width_px_; }
  int imager_height_px() const { return imager_height_px_; }
  // fx, fy, cx, cy: the first four intrinsics of every model used here.
  double fx() const { return intrinsics_[0]; }
  double fy() const { return intrinsics_[1]; }
  double cx() const { return intrinsics_[2]; }
  double cy() const { return intrinsics_[3]; }

  // p_cam (mm, camera frame) -> q (px). `dq_dp` (2x3) may be null.
  Eigen::Vector2d Project(const Eigen::Vector3d& p_cam, Eigen::Matrix<double, 2, 3>* dq_dp = nullptr) const;
  // Batch form. p_cam: (N,3); returns (N,2).
  Eigen::Matrix<double, Eigen::Dynamic, 2> ProjectMany(const Eigen::Matrix<double, Eigen::Dynamic, 3>& p_cam) const;
  // q (px) -> v, a unit direction in the camera frame (z > 0 for a
  // forward-looking lens). Returns false if mrcal's solver did not converge.
  bool Unproject(const Eigen::Vector2d& q, Eigen::Vector3d* v_unit) const;
  // Batch form; rows that fail are NaN.
  Eigen::Matrix<double, Eigen::Dynamic, 3> UnprojectMany(const Eigen::Matrix<double, Eigen::Dynamic, 2>& q) const;

  // mrcal's opaque lens model struct, for code that calls mrcal directly
  // (the intrinsics solver). Points to a mrcal_lensmodel_t.
  const void* mrcal_lensmodel() const;

 private:
  struct Impl;
  std::string lensmodel_name_;
  std::vector<double> intrinsics_;
  int imager_width_px_ = 0;
  int imager_height_px_ = 0;
  std::unique_ptr<Impl> impl_;
};

}  // namespace stereorig
