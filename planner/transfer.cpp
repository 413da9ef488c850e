// Transfer functions: the symplectic product of the paper and the scattering (star-product)
// form that composes without loss of precision.
#include "planner/transfer.h"

#include <Eigen/LU>

#include "common/gaussian/information.h"

namespace kestrel::planner {
namespace {
Mat4 sym(const Mat4& A) { return 0.5 * (A + A.transpose()); }
}  // namespace

Mat4 propagate_ekf(const Mat4& Sigma, const std::vector<BeliefStep>& steps) {
  Mat4 S = Sigma;
  for (const BeliefStep& s : steps)
    S = gaussian::update_covariance(gaussian::predict_covariance(s.G, S, s.R), s.M);
  return S;
}

SymplecticTransfer SymplecticTransfer::identity() { return {}; }

SymplecticTransfer SymplecticTransfer::from_step(const BeliefStep& s) {
  const Mat4 I = Mat4::Identity();
  const Mat4 G_inv_T = s.G.inverse().transpose();
  Mat8 update, predict;  // the paper's two factors, as printed (eq. 2)
  update << Mat4::Zero(), I, I, s.M;
  predict << Mat4::Zero(), G_inv_T, s.G, s.R * G_inv_T;
  SymplecticTransfer t;
  t.zeta_ = update * predict;
  return t;
}

SymplecticTransfer SymplecticTransfer::from_steps(const std::vector<BeliefStep>& steps) {
  SymplecticTransfer t;
  for (const BeliefStep& s : steps) t = t.then(from_step(s));
  return t;
}

SymplecticTransfer SymplecticTransfer::then(const SymplecticTransfer& next) const {
  SymplecticTransfer t;
  t.zeta_.noalias() = next.zeta_ * zeta_;
  return t;
}

Mat4 SymplecticTransfer::apply(const Mat4& Sigma) const {
  // Psi = zeta [Sigma; I]; Sigma' = B C^-1 = (C^-T B^T)^T.
  const Mat4 B = zeta_.topLeftCorner<4, 4>() * Sigma + zeta_.topRightCorner<4, 4>();
  const Mat4 C = zeta_.bottomLeftCorner<4, 4>() * Sigma + zeta_.bottomRightCorner<4, 4>();
  return sym(C.transpose().partialPivLu().solve(B.transpose()).transpose());
}

ScatteringTransfer ScatteringTransfer::identity() { return {}; }

ScatteringTransfer ScatteringTransfer::from_step(const BeliefStep& s) {
  ScatteringTransfer predict, update;
  predict.A_ = s.G;
  predict.Q_ = sym(s.R);
  update.J_ = sym(s.M);
  return predict.then(update);
}

ScatteringTransfer ScatteringTransfer::from_steps(const std::vector<BeliefStep>& steps) {
  ScatteringTransfer t;
  for (const BeliefStep& s : steps) t = t.then(from_step(s));
  return t;
}

ScatteringTransfer ScatteringTransfer::then(const ScatteringTransfer& next) const {
  // Star product of (A1, Q1, J1) then (A2, Q2, J2), with D = (I + Q1 J2)^-1:
  //   A = A2 D A1,  Q = Q2 + A2 D Q1 A2^T,  J = J1 + A1^T J2 D A1.
  // Q1 and J2 are positive semi-definite, so I + Q1 J2 has eigenvalues >= 1: well conditioned.
  const Eigen::PartialPivLU<Mat4> lu(Mat4::Identity() + Q_ * next.J_);
  const Mat4 DA1 = lu.solve(A_);
  const Mat4 DQ1 = lu.solve(Q_);
  ScatteringTransfer t;
  t.A_ = next.A_ * DA1;
  t.Q_ = sym(next.Q_ + next.A_ * DQ1 * next.A_.transpose());
  t.J_ = sym(J_ + A_.transpose() * next.J_ * DA1);
  return t;
}

Mat4 ScatteringTransfer::apply(const Mat4& Sigma) const {
  const Mat4 X = (Mat4::Identity() + J_ * Sigma).partialPivLu().solve(A_.transpose());
  return sym(Q_ + A_ * Sigma * X);
}

}  // namespace kestrel::planner
