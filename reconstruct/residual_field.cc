#include "reconstruct/residual_field.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace stereorig {
namespace {

double Median(std::vector<double> v) {
  const size_t k = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// Every k-th column so that at most `max_count` remain (deterministic).
Eigen::Matrix3Xd StrideColumns(const Eigen::Matrix3Xd& m, int max_count, Eigen::VectorXd* values) {
  const Eigen::Index step = std::max<Eigen::Index>(1, (m.cols() + max_count - 1) / max_count);
  const Eigen::Index n = (m.cols() + step - 1) / step;
  Eigen::Matrix3Xd out(3, n);
  Eigen::VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    out.col(i) = m.col(i * step);
    v(i) = (*values)(i * step);
  }
  *values = std::move(v);
  return out;
}

// The unit-variance kernel matrix C(i, j) = exp(-|xi - xj|^2 / (2 l^2)).
Eigen::MatrixXd KernelMatrix(const Eigen::Matrix3Xd& x, double length_mm) {
  const Eigen::Index n = x.cols();
  const double c = -0.5 / (length_mm * length_mm);
  Eigen::MatrixXd k(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    k(j, j) = 1.0;
    for (Eigen::Index i = j + 1; i < n; ++i) k(i, j) = k(j, i) = std::exp(c * (x.col(i) - x.col(j)).squaredNorm());
  }
  return k;
}

// Log marginal likelihood of y under N(0, s^2 (C + ratio I)) with s^2 at its
// maximum, up to a constant; -inf if the matrix is not positive definite.
double ProfiledLogLikelihood(const Eigen::MatrixXd& c, double ratio, const Eigen::VectorXd& y, double* signal_var) {
  Eigen::MatrixXd a = c;
  a.diagonal().array() += ratio;
  const Eigen::LLT<Eigen::MatrixXd> llt(a);
  if (llt.info() != Eigen::Success) return -std::numeric_limits<double>::infinity();
  const double n = double(y.size());
  *signal_var = y.dot(llt.solve(y)) / n;
  const double log_det = 2 * llt.matrixLLT().diagonal().array().log().sum();
  return -0.5 * n * std::log(*signal_var) - 0.5 * log_det;
}

}  // namespace

ResidualField ResidualField::Fit(const std::vector<Eigen::Vector3d>& points_mm, const std::vector<double>& residuals_mm,
                                 const ResidualFieldOptions& o) {
  ResidualField f;
  char buf[300];
  if (points_mm.size() != residuals_mm.size() || residuals_mm.size() < 20) {
    f.description_ = "residual field off: too few points";
    return f;
  }
  // Gross outliers out (a MAD is robust to up to half of them).
  const double median = Median(residuals_mm);
  std::vector<double> dev(residuals_mm.size());
  for (size_t i = 0; i < dev.size(); ++i) dev[i] = std::abs(residuals_mm[i] - median);
  const double cut = o.outlier_mads * 1.4826 * Median(dev);
  std::vector<size_t> keep;
  double sum2 = 0;
  for (size_t i = 0; i < residuals_mm.size(); ++i)
    if (dev[i] <= cut) {
      keep.push_back(i);
      sum2 += residuals_mm[i] * residuals_mm[i];
    }
  f.residual_rms_mm_ = std::sqrt(sum2 / std::max<size_t>(1, keep.size()));
  if (f.residual_rms_mm_ < o.min_rms_mm || keep.size() < 20) {
    std::snprintf(buf, sizeof buf, "residual field off: residual rms %.3f mm < %.3f mm (the model is exact)",
                  f.residual_rms_mm_, o.min_rms_mm);
    f.description_ = buf;
    return f;
  }
  Eigen::Matrix3Xd all(3, keep.size());
  Eigen::VectorXd y_all(keep.size());
  for (size_t i = 0; i < keep.size(); ++i) {
    all.col(i) = points_mm[keep[i]];
    y_all(i) = residuals_mm[keep[i]];
  }
  Eigen::VectorXd y = y_all;
  const Eigen::Matrix3Xd x = StrideColumns(all, o.max_points, &y);

  // Hyperparameters by marginal likelihood on a coarser subsample.
  Eigen::VectorXd y_ml = y;
  const Eigen::Matrix3Xd x_ml = StrideColumns(x, o.max_likelihood_points, &y_ml);
  const std::vector<double> lengths =
      o.length_mm > 0 ? std::vector<double>{o.length_mm} : o.candidate_lengths_mm;
  double best = -std::numeric_limits<double>::infinity(), best_length = lengths.front(),
         best_ratio = o.candidate_noise_ratios.back(), best_signal_var = 0;
  for (double l : lengths) {
    const Eigen::MatrixXd c = KernelMatrix(x_ml, l);
    for (double ratio : o.candidate_noise_ratios) {
      double signal_var = 0;
      const double ll = ProfiledLogLikelihood(c, ratio, y_ml, &signal_var);
      if (ll > best) best = ll, best_length = l, best_ratio = ratio, best_signal_var = signal_var;
    }
  }
  if (!std::isfinite(best)) {
    f.description_ = "residual field off: no kernel matrix was positive definite";
    return f;
  }

  // The field on the full subsample. The posterior mean c*' (C + ratio I)^-1 y
  // does not depend on s^2.
  Eigen::MatrixXd a = KernelMatrix(x, best_length);
  a.diagonal().array() += best_ratio;
  const Eigen::LLT<Eigen::MatrixXd> llt(a);
  if (llt.info() != Eigen::Success) {
    f.description_ = "residual field off: the kernel matrix is not positive definite";
    return f;
  }
  f.alpha_ = llt.solve(y);
  f.points_mm_ = x;
  f.length_mm_ = best_length;
  f.signal_sd_mm_ = std::sqrt(best_signal_var);
  f.noise_sd_mm_ = std::sqrt(best_ratio * best_signal_var);
  std::snprintf(buf, sizeof buf,
                "residual field: rms %.3f mm over %zu points, fitted on %d; length %.1f mm%s, signal sd %.3f mm, "
                "noise sd %.3f mm",
                f.residual_rms_mm_, keep.size(), int(x.cols()), best_length, o.length_mm > 0 ? " (given)" : "",
                f.signal_sd_mm_, f.noise_sd_mm_);
  f.description_ = buf;
  return f;
}

double ResidualField::Predict(const Eigen::Vector3d& p_mm) const {
  if (!active()) return 0;
  const double c = -0.5 / (length_mm_ * length_mm_);
  return (((points_mm_.colwise() - p_mm).colwise().squaredNorm().array() * c).exp().matrix() * alpha_).value();
}

}  // namespace stereorig
