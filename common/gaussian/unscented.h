#pragma once
// Sigma points of the scaled unscented transform (Julier 2002; the paper's Appendix B),
// generic over the dimension: the state filter uses them on its error state, the planner on
// its (x, y, z, yaw) belief through information.h.
//
// Points: delta_0 = 0, delta_i = +/- sqrt(n + lambda) * column i of a square root of Sigma,
// lambda = alpha^2 (n + kappa) - n. The square root comes from a pivoted LDL^T, so a
// singular (positive semi-definite) Sigma, as right after a pose is cloned, is fine; it must
// not be indefinite beyond rounding.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>
#include <stdexcept>

namespace kestrel::gaussian {

struct UnscentedParams {
  double alpha = 1.0;  ///< spread; 1 puts the points at sqrt(n + kappa) sigma
  double beta = 0.0;   ///< prior knowledge of the distribution (2 is optimal for a Gaussian)
  double kappa = 0.0;  ///< secondary scaling
};

struct UnscentedWeights {
  double scale = 0.0;     ///< sqrt(n + lambda), multiplies the square-root columns
  double mean0 = 0.0;     ///< weight of point 0 for the mean
  double cov0 = 0.0;      ///< weight of point 0 for the covariance
  double other = 0.0;     ///< weight of every other point (mean and covariance)
};

/// Weights for dimension n; throws std::invalid_argument if n + lambda <= 0.
inline UnscentedWeights unscented_weights(int n, const UnscentedParams& p) {
  const double lambda = p.alpha * p.alpha * (n + p.kappa) - n;
  if (!(n + lambda > 0.0)) throw std::invalid_argument("unscented transform: n + lambda must be > 0");
  UnscentedWeights w;
  w.scale = std::sqrt(n + lambda);
  w.mean0 = lambda / (n + lambda);
  w.cov0 = w.mean0 + (1.0 - p.alpha * p.alpha + p.beta);
  w.other = 0.5 / (n + lambda);
  return w;
}

/// A square root L of a symmetric positive semi-definite Sigma (L L^T = Sigma), from a pivoted
/// LDL^T; negative pivots down to -1e-9 * max|Sigma| are rounding and count as 0. Throws
/// std::invalid_argument for an indefinite or non-finite Sigma.
template <class Derived>
Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime, Eigen::ColMajor,
              Derived::MaxRowsAtCompileTime, Derived::MaxColsAtCompileTime>
psd_square_root(const Eigen::MatrixBase<Derived>& Sigma) {
  using Matrix = Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime,
                               Eigen::ColMajor, Derived::MaxRowsAtCompileTime,
                               Derived::MaxColsAtCompileTime>;
  if (!Sigma.allFinite()) throw std::invalid_argument("square root of a non-finite matrix");
  const Eigen::LDLT<Matrix> ldlt(Sigma.eval());
  auto d = ldlt.vectorD().eval();
  const double tolerance = 1e-9 * std::max(1e-300, Sigma.cwiseAbs().maxCoeff());
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    if (d[i] < -tolerance) throw std::invalid_argument("square root of an indefinite matrix");
    d[i] = std::sqrt(std::max(0.0, d[i]));
  }
  Matrix L = ldlt.matrixL();
  L = L * d.asDiagonal();
  return ldlt.transpositionsP().transpose() * L;
}

/// The 2n+1 sigma offsets (columns) around a mean, for covariance Sigma: column 0 is zero,
/// columns 1..n are +scale * L_i, columns n+1..2n are -scale * L_i.
template <class Derived>
Eigen::Matrix<double, Derived::RowsAtCompileTime, Eigen::Dynamic> sigma_offsets(
    const Eigen::MatrixBase<Derived>& Sigma, const UnscentedWeights& w) {
  const auto L = psd_square_root(Sigma);
  const Eigen::Index n = Sigma.rows();
  Eigen::Matrix<double, Derived::RowsAtCompileTime, Eigen::Dynamic> X(n, 2 * n + 1);
  X.col(0).setZero();
  X.middleCols(1, n) = w.scale * L;
  X.middleCols(n + 1, n) = -w.scale * L;
  return X;
}

}  // namespace kestrel::gaussian
