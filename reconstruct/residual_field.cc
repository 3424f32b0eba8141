#include "reconstruct/residual_field.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <unordered_map>

namespace stereorig {
namespace {

double Median(std::vector<double> v) {
  const size_t k = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// The mean point and mean value of each occupied cube of a grid, the cube's
// edge grown until at most ~max_count cubes remain: a subsample spread
// evenly over the surface (a stride through the cloud's rows is not: it
// thins the seen region's edges, which carry the extrapolation), with the
// noise averaged down. Deterministic: cubes in order of first occupancy.
// *weights: each cell's point count over the median count; a cell mean's
// noise variance goes as 1 / weight.
Eigen::Matrix3Xd CellMeans(const Eigen::Matrix3Xd& x, const Eigen::VectorXd& y, int max_count, Eigen::VectorXd* means,
                           Eigen::VectorXd* weights) {
  const Eigen::Vector3d lo = x.rowwise().minCoeff(), extent = x.rowwise().maxCoeff() - lo;
  // Start from a cell for which a surface of the box's size would give
  // max_count cells, then grow by the excess.
  double cell = std::max(1e-3, std::sqrt((extent.x() * extent.y() + extent.y() * extent.z() + extent.z() * extent.x()) /
                                         std::max(1, max_count)));
  std::unordered_map<int64_t, int> index;
  std::vector<int> cell_of(x.cols());
  for (int attempt = 0; attempt < 20; ++attempt) {
    index.clear();
    const Eigen::Vector3i dims = (extent / cell).cast<int>() + Eigen::Vector3i::Ones();
    for (Eigen::Index i = 0; i < x.cols(); ++i) {
      const Eigen::Vector3i c = ((x.col(i) - lo) / cell).cast<int>().cwiseMin(dims - Eigen::Vector3i::Ones());
      const int64_t key = c.x() + int64_t(dims.x()) * (c.y() + int64_t(dims.y()) * c.z());
      cell_of[i] = index.emplace(key, int(index.size())).first->second;
    }
    if (int(index.size()) <= max_count) break;
    // A surface's cell count goes as 1 / cell^2.
    cell *= std::max(1.05, 1.02 * std::sqrt(double(index.size()) / max_count));
  }
  const Eigen::Index n = Eigen::Index(index.size());
  Eigen::Matrix3Xd sum = Eigen::Matrix3Xd::Zero(3, n);
  Eigen::VectorXd value = Eigen::VectorXd::Zero(n), count = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 0; i < x.cols(); ++i) {
    sum.col(cell_of[i]) += x.col(i);
    value(cell_of[i]) += y(i);
    count(cell_of[i]) += 1;
  }
  *means = value.cwiseQuotient(count);
  std::vector<double> counts(count.data(), count.data() + n);
  *weights = count / Median(counts);
  return sum.array().rowwise() / count.transpose().array();
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

// Log marginal likelihood of y under N(0, s^2 (C + ratio W^-1)), W the
// cells' weights, with s^2 at its maximum, up to a constant; -inf if the
// matrix is not positive definite.
double ProfiledLogLikelihood(const Eigen::MatrixXd& c, double ratio, const Eigen::VectorXd& weights,
                             const Eigen::VectorXd& y, double* signal_var) {
  Eigen::MatrixXd a = c;
  a.diagonal() += ratio * weights.cwiseInverse();
  const Eigen::LLT<Eigen::MatrixXd> llt(a);
  if (llt.info() != Eigen::Success) return -std::numeric_limits<double>::infinity();
  const double n = double(y.size());
  *signal_var = y.dot(llt.solve(y)) / n;
  const double log_det = 2 * llt.matrixLLT().diagonal().array().log().sum();
  return -0.5 * n * std::log(*signal_var) - 0.5 * log_det;
}

// The points' indices by cube of block_mm (a grid anchored at the origin),
// cubes in a fixed order: the same sums every run.
std::map<std::array<int, 3>, std::vector<Eigen::Index>> Blocks(const Eigen::Matrix3Xd& x, double block_mm) {
  std::map<std::array<int, 3>, std::vector<Eigen::Index>> blocks;
  for (Eigen::Index i = 0; i < x.cols(); ++i) {
    const Eigen::Vector3i b = (x.col(i) / block_mm).array().floor().cast<int>();
    blocks[{b.x(), b.y(), b.z()}].push_back(i);
  }
  return blocks;
}

}  // namespace

namespace internal {

double BlockCrossValidationError(const Eigen::MatrixXd& c, double ratio, const Eigen::VectorXd& weights,
                                 const Eigen::VectorXd& y, const Eigen::Matrix3Xd& x, double block_mm) {
  Eigen::MatrixXd a = c;
  a.diagonal() += ratio * weights.cwiseInverse();
  const Eigen::LLT<Eigen::MatrixXd> llt(a);
  if (llt.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
  const Eigen::MatrixXd inverse = llt.solve(Eigen::MatrixXd::Identity(a.rows(), a.cols()));
  const Eigen::VectorXd alpha = inverse * y;
  double error = 0;
  for (const auto& [key, idx] : Blocks(x, block_mm)) {
    const Eigen::Index m = Eigen::Index(idx.size());
    Eigen::MatrixXd inverse_bb(m, m);
    Eigen::VectorXd alpha_b(m), weights_b(m);
    for (Eigen::Index r = 0; r < m; ++r) {
      alpha_b(r) = alpha(idx[r]);
      weights_b(r) = weights(idx[r]);
      for (Eigen::Index q = 0; q < m; ++q) inverse_bb(r, q) = inverse(idx[r], idx[q]);
    }
    const Eigen::VectorXd held_out = inverse_bb.ldlt().solve(alpha_b);
    error += (held_out.array().square() * weights_b.array()).sum();
  }
  return error;
}

}  // namespace internal

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
  Eigen::VectorXd y, y_ml, w, w_ml;
  const Eigen::Matrix3Xd x = CellMeans(all, y_all, o.max_points, &y, &w);
  // Hyperparameters on a coarser subsample: the noise ratio by marginal
  // likelihood, the length by held-out blocks (or likelihood too; header).
  const Eigen::Matrix3Xd x_ml = CellMeans(all, y_all, o.max_likelihood_points, &y_ml, &w_ml);
  const std::vector<double> lengths = o.length_mm > 0 ? std::vector<double>{o.length_mm} : o.candidate_lengths_mm;
  // With the data in one block, leaving it out says nothing of the length:
  // the likelihood decides.
  const bool by_cross_validation = o.cv_block_mm > 0 && lengths.size() > 1 && Blocks(x_ml, o.cv_block_mm).size() >= 2;
  double best = -std::numeric_limits<double>::infinity(), best_length = lengths.front(),
         best_ratio = o.candidate_noise_ratios.back(), best_signal_var = 0;
  double best_held_out = std::numeric_limits<double>::infinity();
  for (double l : lengths) {
    const Eigen::MatrixXd c = KernelMatrix(x_ml, l);
    // The noise ratio for this length, by marginal likelihood.
    double l_best = -std::numeric_limits<double>::infinity(), l_ratio = 0, l_signal_var = 0;
    for (double ratio : o.candidate_noise_ratios) {
      double signal_var = 0;
      const double ll = ProfiledLogLikelihood(c, ratio, w_ml, y_ml, &signal_var);
      if (ll > l_best) l_best = ll, l_ratio = ratio, l_signal_var = signal_var;
    }
    if (!std::isfinite(l_best)) continue;
    if (by_cross_validation) {
      const double held_out = internal::BlockCrossValidationError(c, l_ratio, w_ml, y_ml, x_ml, o.cv_block_mm);
      if (!(held_out < best_held_out)) continue;
      best_held_out = held_out;
    } else if (!(l_best > best)) {
      continue;
    }
    best = l_best, best_length = l, best_ratio = l_ratio, best_signal_var = l_signal_var;
  }
  if (!std::isfinite(best)) {
    f.description_ = "residual field off: no kernel matrix was positive definite";
    return f;
  }

  // The field on the full set of cell means. The posterior mean
  // c*' (C + ratio W^-1)^-1 y
  // does not depend on s^2.
  Eigen::MatrixXd a = KernelMatrix(x, best_length);
  a.diagonal() += best_ratio * w.cwiseInverse();
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
                "residual field: rms %.3f mm over %zu points, fitted on %d cell means; length %.1f mm%s, signal sd "
                "%.3f mm, noise sd %.3f mm",
                f.residual_rms_mm_, keep.size(), int(x.cols()), best_length,
                o.length_mm > 0       ? " (given)"
                : by_cross_validation ? " (by held-out blocks)"
                                      : " (by likelihood)",
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
