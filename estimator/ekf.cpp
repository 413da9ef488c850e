// The error-state EKF: structured covariance propagation and the Kalman update.

#include <Eigen/Cholesky>

#include "estimator/filter.h"

namespace kestrel::estimator {

namespace {

// P <- Phi P Phi^T on any square matrix expression (a fixed-size map or the dynamic one).
template <typename Mat>
void transform_blocks(const Transition& phi, Mat& P) {
  constexpr int N = Mat::RowsAtCompileTime;
  const int n = static_cast<int>(P.rows());
  const double half_dt = 0.5 * phi.dt;
  using Rows = Eigen::Matrix<double, 3, N, Eigen::ColMajor, 3, N == Eigen::Dynamic ? kMaxDim : N>;
  using Cols = Eigen::Matrix<double, N, 3, Eigen::ColMajor, N == Eigen::Dynamic ? kMaxDim : N, 3>;
  {  // Rows: P <- Phi P.
    const auto th = P.template middleRows<3>(idx::kTheta);
    const auto bg = P.template middleRows<3>(idx::kBg);
    const auto ba = P.template middleRows<3>(idx::kBa);
    Rows t(3, n);
    t.noalias() = phi.v_theta * th;
    t.noalias() += phi.v_bg * bg;
    t.noalias() += phi.v_ba * ba;
    Rows new_th(3, n);
    new_th.noalias() = phi.theta_theta * th;
    new_th.noalias() += phi.theta_bg * bg;
    P.template middleRows<3>(idx::kP) += phi.dt * P.template middleRows<3>(idx::kV) + half_dt * t;
    P.template middleRows<3>(idx::kV) += t;
    P.template middleRows<3>(idx::kTheta) = new_th;
  }
  {  // Columns: P <- P Phi^T.
    const auto th = P.template middleCols<3>(idx::kTheta);
    const auto bg = P.template middleCols<3>(idx::kBg);
    const auto ba = P.template middleCols<3>(idx::kBa);
    Cols t(n, 3);
    t.noalias() = th * phi.v_theta.transpose();
    t.noalias() += bg * phi.v_bg.transpose();
    t.noalias() += ba * phi.v_ba.transpose();
    Cols new_th(n, 3);
    new_th.noalias() = th * phi.theta_theta.transpose();
    new_th.noalias() += bg * phi.theta_bg.transpose();
    P.template middleCols<3>(idx::kP) += phi.dt * P.template middleCols<3>(idx::kV) + half_dt * t;
    P.template middleCols<3>(idx::kV) += t;
    P.template middleCols<3>(idx::kTheta) = new_th;
  }
}

// The state's dimension is one of four (0 to 3 clones): each gets a fixed-size view of the
// same storage, so the products above are unrolled and vectorised at IMU rate.
template <int N>
void transform_fixed(const Transition& phi, Covariance& P) {
  Eigen::Map<Eigen::Matrix<double, N, N>> fixed(P.data());
  transform_blocks(phi, fixed);
}

}  // namespace

void transform_covariance(const Transition& phi, Covariance& P) {
  static_assert(kMaxClones == 3, "one fixed size per clone count below");
  switch (P.rows()) {
    case idx::kNav: return transform_fixed<idx::kNav>(phi, P);
    case idx::kNav + 6: return transform_fixed<idx::kNav + 6>(phi, P);
    case idx::kNav + 12: return transform_fixed<idx::kNav + 12>(phi, P);
    case idx::kNav + 18: return transform_fixed<idx::kNav + 18>(phi, P);
    default: transform_blocks(phi, P);
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
  const Innovation in = innovation(m, s);
  UpdateResult result;
  if (!in.valid) return result;
  result.mahalanobis2 = in.mahalanobis2();
  if (gate_chi2 > 0.0 && result.mahalanobis2 > gate_chi2) return result;
  const Gain K = in.S.solve(in.HP).transpose();  // P H^T S^-1
  const ErrorVector dx = K * in.y;
  s.P.noalias() -= K * in.HP;
  inject(s, dx);
  result.applied = true;
  return result;
}

std::unique_ptr<Filter> make_filter(FilterKind kind, const ImuNoise& noise, double gravity,
                                    const gaussian::UnscentedParams& params) {
  if (kind == FilterKind::kUkf) return std::make_unique<Ukf>(noise, gravity, params);
  return std::make_unique<Ekf>(noise, gravity);
}

}  // namespace kestrel::estimator
