#pragma once
// The Kalman filter in information form (the paper's §2, eqs. 10-12 and 27): the quantities
// the Belief Roadmap composes along its edges. They live here, beside the filters, so that
// the planner predicts covariances with the same models the filter flies on.
//
// All functions are generic over the state dimension n and the measurement dimension m
// (fixed-size or Eigen::Dynamic), e.g. n = 4 for the planner's (x, y, z, yaw) belief and
// n = 15 for the state filter. Notation as in the paper:
//   predict   Sigma_bar = G Sigma G^T + R,  R = V W V^T                (process noise)
//   update    Omega = Sigma_bar^-1 + M,     M = H^T Q^-1 H             (EKF)
//             M = (Sigma_bar - K S K^T)^-1 - Sigma_bar^-1              (UKF, eq. 27)
// Matrices that must be symmetric positive definite (Q, Sigma) are checked; a violation
// throws std::invalid_argument, since it is a caller's bug, never a property of the data.

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/Core>
#include <stdexcept>
#include <string>

#include "common/gaussian/unscented.h"

namespace kestrel::gaussian {

template <int Rows, int Cols = Rows>
using Mat = Eigen::Matrix<double, Rows, Cols>;

namespace detail {
template <class Derived>
auto spd_factor(const Eigen::MatrixBase<Derived>& A, const char* what) {
  Eigen::LLT<typename Derived::PlainObject> llt(A.derived());
  if (llt.info() != Eigen::Success || !A.allFinite())
    throw std::invalid_argument(std::string(what) + " is not symmetric positive definite");
  return llt;
}
template <class Derived>
typename Derived::PlainObject symmetric(const Eigen::MatrixBase<Derived>& A) {
  return 0.5 * (A + A.transpose());
}
}  // namespace detail

/// Process noise R = V W V^T of a discrete step x' = g(x, u + w), w ~ N(0, W), V = dg/du.
template <class DV, class DW>
Mat<DV::RowsAtCompileTime> process_noise(const Eigen::MatrixBase<DV>& V,
                                         const Eigen::MatrixBase<DW>& W) {
  if (V.cols() != W.rows() || W.rows() != W.cols())
    throw std::invalid_argument("process_noise: V is n x k and W must be k x k");
  return detail::symmetric((V * W * V.transpose()).eval());
}

/// The same for a diagonal W given as the vector of its variances (cheaper).
template <class DV, class DW>
Mat<DV::RowsAtCompileTime> process_noise_diagonal(const Eigen::MatrixBase<DV>& V,
                                                  const Eigen::MatrixBase<DW>& variances) {
  if (V.cols() != variances.size())
    throw std::invalid_argument("process_noise_diagonal: V is n x k and W must have k entries");
  return (V * variances.asDiagonal() * V.transpose()).eval();
}

/// Measurement information M = H^T Q^-1 H of z = h(x) + q, q ~ N(0, Q), H = dh/dx.
template <class DH, class DQ>
Mat<DH::ColsAtCompileTime> measurement_information(const Eigen::MatrixBase<DH>& H,
                                                   const Eigen::MatrixBase<DQ>& Q) {
  if (Q.rows() != H.rows() || Q.cols() != H.rows())
    throw std::invalid_argument("measurement_information: H is m x n and Q must be m x m");
  const auto llt = detail::spd_factor(Q, "measurement noise Q");
  return detail::symmetric((H.transpose() * llt.solve(H)).eval());
}

/// EKF prediction of the covariance: G Sigma G^T + R.
template <class DG, class DS, class DR>
Mat<DS::RowsAtCompileTime> predict_covariance(const Eigen::MatrixBase<DG>& G,
                                              const Eigen::MatrixBase<DS>& Sigma,
                                              const Eigen::MatrixBase<DR>& R) {
  return detail::symmetric((G * Sigma * G.transpose() + R).eval());
}

/// Posterior covariance from a prior and a measurement's information: (Sigma^-1 + M)^-1,
/// computed as (I + Sigma M)^-1 Sigma so that a singular M (a measurement of part of the state)
/// is fine. Sigma must be positive definite.
template <class DS, class DM>
Mat<DS::RowsAtCompileTime> update_covariance(const Eigen::MatrixBase<DS>& Sigma,
                                             const Eigen::MatrixBase<DM>& M) {
  detail::spd_factor(Sigma, "prior covariance");
  using Plain = Mat<DS::RowsAtCompileTime>;
  const Plain I = Plain::Identity(Sigma.rows(), Sigma.cols());
  // (Sigma^-1 + M)^-1 = (I + Sigma M)^-1 Sigma: one LU of a well-conditioned matrix.
  const Plain A = (I + Sigma * M).eval();
  return detail::symmetric(A.partialPivLu().solve(Sigma.derived()).eval());
}

/// The measurement information a UKF update extracts (the paper's eq. 27):
/// M = (Sigma_bar - K S K^T)^-1 - Sigma_bar^-1, with the sigma points of (mean, Sigma_bar)
/// passed through `h` (a callable x -> predicted measurement, continuous over the points:
/// wrap angles relative to h(mean) if the measurement has any) and additive noise Q.
template <class DX, class DS, class H, class DQ>
Mat<DS::RowsAtCompileTime> ukf_measurement_information(const Eigen::MatrixBase<DX>& mean,
                                                       const Eigen::MatrixBase<DS>& Sigma_bar,
                                                       const H& h,
                                                       const Eigen::MatrixBase<DQ>& Q,
                                                       const UnscentedParams& params = {}) {
  using StateMat = Mat<DS::RowsAtCompileTime>;
  constexpr int M = DQ::RowsAtCompileTime;
  using MeasVec = Eigen::Matrix<double, M, 1>;
  const int n = static_cast<int>(Sigma_bar.rows());
  const int m = static_cast<int>(Q.rows());
  const auto prior = detail::spd_factor(Sigma_bar, "prior covariance");
  detail::spd_factor(Q, "measurement noise Q");

  const UnscentedWeights w = unscented_weights(n, params);
  const auto X = sigma_offsets(Sigma_bar, w);
  Eigen::Matrix<double, M, Eigen::Dynamic> Z(m, 2 * n + 1);
  for (int i = 0; i <= 2 * n; ++i) {
    const MeasVec z = h((mean + X.col(i)).eval());
    if (z.size() != m) throw std::invalid_argument("ukf_measurement_information: h and Q disagree on m");
    Z.col(i) = z;
  }
  MeasVec z_bar = w.mean0 * Z.col(0);
  for (int i = 1; i <= 2 * n; ++i) z_bar += w.other * Z.col(i);
  Mat<M> S = Q;
  Eigen::Matrix<double, DS::RowsAtCompileTime, M> C =
      Eigen::Matrix<double, DS::RowsAtCompileTime, M>::Zero(n, m);
  for (int i = 0; i <= 2 * n; ++i) {
    const double wc = i == 0 ? w.cov0 : w.other;
    const MeasVec dz = Z.col(i) - z_bar;
    S.noalias() += wc * dz * dz.transpose();
    C.noalias() += wc * X.col(i) * dz.transpose();
  }
  const auto S_llt = detail::spd_factor(S, "innovation covariance S");
  // K S K^T = C S^-1 C^T.
  const StateMat posterior = detail::symmetric((Sigma_bar - C * S_llt.solve(C.transpose())).eval());
  const auto post_llt = detail::spd_factor(posterior, "UKF posterior covariance");
  const StateMat I = StateMat::Identity(n, n);
  return detail::symmetric((post_llt.solve(I) - prior.solve(I)).eval());
}

}  // namespace kestrel::gaussian
