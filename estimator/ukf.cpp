// The error-state UKF: sigma points drawn in the error state around the mean, pushed through
// the same nonlinear process and measurement models as the EKF, and mapped back with ⊟.

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <stdexcept>

#include "estimator/filter.h"

namespace kestrel::estimator {
namespace {

using SigmaMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxDim,
                                  2 * kMaxDim + 1>;

// A square root of P. The pivoted LDL^T fails when rounding (P -= K S K^T on a covariance made
// singular by its clones) has pushed a pivot below its tolerance; then P is replaced by its
// nearest positive semi-definite matrix (negative eigenvalues set to zero), which moves it by
// no more than that rounding, and the square root is taken from the eigen-decomposition.
// A P negative beyond rounding (|lambda_min| > 1e-6 max|P|) is an error, not repaired.
Covariance square_root(Covariance& P) {
  try {
    return gaussian::psd_square_root(P);
  } catch (const std::invalid_argument&) {
    if (!P.allFinite()) throw;
    const Eigen::SelfAdjointEigenSolver<Covariance> eig(P);
    Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxDim, 1> d = eig.eigenvalues();
    if (d.minCoeff() < -1e-6 * P.cwiseAbs().maxCoeff()) throw;
    d = d.cwiseMax(0.0);
    P = eig.eigenvectors() * d.asDiagonal() * eig.eigenvectors().transpose();
    symmetrize(P);
    return eig.eigenvectors() * d.cwiseSqrt().asDiagonal();
  }
}

SigmaMatrix offsets(Covariance& P, const gaussian::UnscentedWeights& w) {
  const Covariance L = square_root(P);
  const int n = static_cast<int>(P.rows());
  SigmaMatrix X(n, 2 * n + 1);
  X.col(0).setZero();
  X.middleCols(1, n) = w.scale * L;
  X.middleCols(n + 1, n) = -w.scale * L;
  return X;
}

double weight_mean(const gaussian::UnscentedWeights& w, int i) { return i == 0 ? w.mean0 : w.other; }
double weight_cov(const gaussian::UnscentedWeights& w, int i) { return i == 0 ? w.cov0 : w.other; }

}  // namespace

void Ukf::predict(FilterState& s, const ImuInterval& u) const {
  const int n = s.mean.dim();
  const int count = 2 * n + 1;
  const gaussian::UnscentedWeights w = gaussian::unscented_weights(n, params_);
  const SigmaMatrix X = offsets(s.P, w);

  // The centre is propagated with its Jacobians only for the additive process noise.
  const ImuStep centre = propagate(s.mean.nav, u, gravity_);
  SigmaMatrix Y(n, count);
  for (int i = 0; i < count; ++i) {
    const auto dx = X.col(i);
    if (dx.head<idx::kNav>().isZero(0.0)) {
      Y.col(i).head<idx::kNav>().setZero();
    } else {
      const NavState moved = propagate_mean(boxplus(s.mean.nav, dx.head<idx::kNav>()), u, gravity_);
      Y.col(i).head<idx::kNav>() = boxminus(moved, centre.next);
    }
    Y.col(i).tail(n - idx::kNav) = dx.tail(n - idx::kNav);  // clones do not move
  }
  ErrorVector y_mean = ErrorVector::Zero(n);
  for (int i = 0; i < count; ++i) y_mean += weight_mean(w, i) * Y.col(i);

  Covariance P = Covariance::Zero(n, n);
  for (int i = 0; i < count; ++i) {
    const ErrorVector d = Y.col(i) - y_mean;
    P.noalias() += weight_cov(w, i) * d * d.transpose();
  }
  P.topLeftCorner<idx::kNav, idx::kNav>() += process_noise(centre.phi, noise_, u.gap);
  s.mean.nav = boxplus(centre.next, y_mean.head<idx::kNav>());
  s.P = P;
  symmetrize(s.P);
}

UpdateResult Ukf::update(FilterState& s, const Measurement& m, double gate_chi2) const {
  const int n = s.mean.dim();
  const int count = 2 * n + 1;
  const gaussian::UnscentedWeights w = gaussian::unscented_weights(n, params_);
  UpdateResult result;
  SigmaMatrix X;
  try {
    X = offsets(s.P, w);
  } catch (const std::invalid_argument&) {
    return result;  // P lost positive semi-definiteness: refuse rather than corrupt it
  }

  const Residual g0 = m.residual(boxplus(s.mean, X.col(0)));
  const int k = static_cast<int>(g0.size());
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxMeasurementDim,
                2 * kMaxDim + 1>
      G(k, count);
  G.col(0) = g0;
  for (int i = 1; i < count; ++i) G.col(i) = m.residual(boxplus(s.mean, X.col(i)));
  Residual g_mean = Residual::Zero(k);
  for (int i = 0; i < count; ++i) g_mean += weight_mean(w, i) * G.col(i);

  MeasurementNoise S = m.noise();
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxDim,
                kMaxMeasurementDim>
      C = Eigen::MatrixXd::Zero(n, k);
  for (int i = 0; i < count; ++i) {
    const Residual dg = G.col(i) - g_mean;
    S.noalias() += weight_cov(w, i) * dg * dg.transpose();
    C.noalias() += weight_cov(w, i) * X.col(i) * dg.transpose();
  }
  const Eigen::LLT<MeasurementNoise> llt(S);
  if (llt.info() != Eigen::Success || !g_mean.allFinite()) return result;
  const Residual y = -g_mean;
  result.mahalanobis2 = y.dot(llt.solve(y));
  if (gate_chi2 > 0.0 && result.mahalanobis2 > gate_chi2) return result;
  const decltype(C) K = llt.solve(C.transpose()).transpose();  // C S^-1
  const ErrorVector dx = K * y;
  s.P.noalias() -= K * C.transpose();  // K S K^T
  inject(s, dx);
  result.applied = true;
  return result;
}

}  // namespace kestrel::estimator
