// Small dense nonlinear least squares for the geometric shape fits
// (cylinder, ellipsoid): min_x sum_i r_i(x)^2 by Levenberg-Marquardt, with
// Eigen's MINPACK port (unsupported/Eigen/NonLinearOptimization) and a
// forward-difference Jacobian. Header-only Eigen: the runtime keeps its
// dependencies (no Ceres in reconstruct/).
#pragma once

#include <Eigen/Core>
#include <functional>

namespace stereorig {

// residuals(x, r): fill r (num_residuals) at parameters x.
using ResidualFunction = std::function<void(const Eigen::VectorXd& x, Eigen::VectorXd* r)>;

struct LeastSquaresSummary {
  bool converged = false;  // a tolerance was met (not: out of evaluations, bad input)
  int evaluations = 0;     // residual evaluations, Jacobian columns included
  double rms = 0;          // of the residuals at the solution
};

// x: (n) start on entry, solution on return.
LeastSquaresSummary MinimiseSumOfSquares(int num_residuals, const ResidualFunction& residuals, Eigen::VectorXd* x);

}  // namespace stereorig
