// The error-state EKF: structured covariance propagation and the Kalman update.

#include <Eigen/Cholesky>

#include "estimator/filter.h"

namespace kestrel::estimator {

void transform_covariance(const Transition& phi, Covariance& P) {
  const int n = static_cast<int>(P.rows());
  const double half_dt = 0.5 * phi.dt;
  using Rows = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, kMaxDim>;
  using Cols = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::ColMajor, kMaxDim, 3>;
  {  // Rows: P <- Phi P.
    const auto th = P.middleRows<3>(idx::kTheta);
    const auto bg = P.middleRows<3>(idx::kBg);
    const auto ba = P.middleRows<3>(idx::kBa);
    Rows t(3, n);
    t.noalias() = phi.v_theta * th;
    t.noalias() += phi.v_bg * bg;
    t.noalias() += phi.v_ba * ba;
    Rows new_th(3, n);
    new_th.noalias() = phi.theta_theta * th;
    new_th.noalias() += phi.theta_bg * bg;
    P.middleRows<3>(idx::kP) += phi.dt * P.middleRows<3>(idx::kV) + half_dt * t;
    P.middleRows<3>(idx::kV) += t;
    P.middleRows<3>(idx::kTheta) = new_th;
  }
  {  // Columns: P <- P Phi^T.
    const auto th = P.middleCols<3>(idx::kTheta);
    const auto bg = P.middleCols<3>(idx::kBg);
    const auto ba = P.middleCols<3>(idx::kBa);
    Cols t(n, 3);
    t.noalias() = th * phi.v_theta.transpose();
    t.noalias() += bg * phi.v_bg.transpose();
    t.noalias() += ba * phi.v_ba.transpose();
    Cols new_th(n, 3);
    new_th.noalias() = th * phi.theta_theta.transpose();
    new_th.noalias() += bg * phi.theta_bg.transpose();
    P.middleCols<3>(idx::kP) += phi.dt * P.middleCols<3>(idx::kV) + half_dt * t;
    P.middleCols<3>(idx::kV) += t;
    P.middleCols<3>(idx::kTheta) = new_th;
  }
}

void Ekf::predict(FilterState& s, const ImuInterval& u) const {
  const ImuStep step = propagate(s.mean.nav, u, gravity_);
  s.mean.nav = step.next;
  transform_covariance(step.phi, s.P);
  s.P.topLeftCorner<idx::kNav, idx::kNav>() += process_noise(step.phi, noise_, u.gap);
}

UpdateResult Ekf::update(FilterState& s, const Measurement& m, double gate_chi2) const {
  using Gain = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxDim,
                             kMaxMeasurementDim>;
  const Residual g = m.residual(s.mean);
  const MeasurementJacobian H = m.jacobian(s.mean);
  const MeasurementJacobian HP = H * s.P;
  const MeasurementNoise S = HP * H.transpose() + m.noise();
  const Eigen::LLT<MeasurementNoise> llt(S);
  UpdateResult result;
  if (llt.info() != Eigen::Success || !g.allFinite()) return result;
  const Residual y = -g;
  result.mahalanobis2 = y.dot(llt.solve(y));
  if (gate_chi2 > 0.0 && result.mahalanobis2 > gate_chi2) return result;
  const Gain K = llt.solve(HP).transpose();  // P H^T S^-1
  const ErrorVector dx = K * y;
  s.P.noalias() -= K * HP;
  inject(s, dx);
  result.applied = true;
  return result;
}

std::unique_ptr<Filter> make_filter(FilterKind kind, const ImuNoise& noise, double gravity,
                                    const UnscentedParams& params) {
  if (kind == FilterKind::kUkf) return std::make_unique<Ukf>(noise, gravity, params);
  return std::make_unique<Ekf>(noise, gravity);
}

}  // namespace kestrel::estimator
