#include "reconstruct/metrology/least_squares.h"

#include <cmath>
#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

namespace stereorig {

namespace {

// The functor shape Eigen's NumericalDiff and LevenbergMarquardt expect.
struct Functor {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;

  Functor() = default;
  Functor(int n, int m, const ResidualFunction* f) : n_(n), m_(m), f_(f) {}
  int inputs() const { return n_; }
  int values() const { return m_; }
  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& r) const {
    (*f_)(x, &r);
    return 0;
  }

  int n_ = 0, m_ = 0;
  const ResidualFunction* f_ = nullptr;
};

}  // namespace

LeastSquaresSummary MinimiseSumOfSquares(int num_residuals, const ResidualFunction& residuals, Eigen::VectorXd* x) {
  LeastSquaresSummary summary;
  const int n = static_cast<int>(x->size());
  if (num_residuals < n) return summary;
  Eigen::NumericalDiff<Functor> diff(Functor(n, num_residuals, &residuals));
  Eigen::LevenbergMarquardt<Eigen::NumericalDiff<Functor>, double> lm(diff);
  lm.parameters.xtol = 1e-12;
  lm.parameters.ftol = 1e-12;
  lm.parameters.maxfev = 100 * (n + 1);
  const auto status = lm.minimize(*x);
  namespace S = Eigen::LevenbergMarquardtSpace;
  summary.converged = status != S::ImproperInputParameters && status != S::TooManyFunctionEvaluation &&
                      status != S::UserAsked && x->allFinite();
  summary.evaluations = static_cast<int>(lm.nfev);
  Eigen::VectorXd r(num_residuals);
  residuals(*x, &r);
  summary.rms = std::sqrt(r.squaredNorm() / num_residuals);
  return summary;
}

}  // namespace stereorig
