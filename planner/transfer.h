#pragma once
// One-step transfer functions of the Belief Roadmap (the paper's §4, eq. 2; Prentice & Roy
// 2009): the covariance update along a whole edge, computed once and composed in O(1) per
// edge during search, for any start covariance.
//
// Every step is an EKF prediction (G, R) followed by an update with information M:
//   Sigma' = ((G Sigma G^T + R)^-1 + M)^-1.
// Two representations of the composed map:
//  * SymplecticTransfer — the paper's: Psi = [B; C], Sigma = B C^-1, one step
//    Psi' = [[0, I], [I, M]] [[0, G^-T], [G, R G^-T]] Psi; an edge is the product of the
//    2n x 2n step matrices. Its eigenvalues come in pairs (lambda, 1/lambda), so long or
//    well-observed edges make the product ill-conditioned and B C^-1 loses digits.
//  * ScatteringTransfer — the same map as a "scattering" triple (A, Q, J),
//    Sigma' = Q + A Sigma (I + J Sigma)^-1 A^T, composed with the Redheffer star product.
//    Q, J stay symmetric positive semi-definite and only (I + PSD * PSD) is ever inverted, so
//    no digits are lost however long the edge (the default).
// Both satisfy: from_step(s).apply(S) == ekf_step(S, s); a.then(b).apply(S) == b.apply(a.apply(S)).

#include <Eigen/Core>
#include <vector>

#include "planner/types.h"

namespace kestrel::planner {

/// One EKF step: prediction (G, R) then a measurement of information M.
struct BeliefStep {
  Mat4 G = Mat4::Identity();
  Mat4 R = Mat4::Zero();
  Mat4 M = Mat4::Zero();
};

/// Step-by-step EKF covariance propagation (common/gaussian/information.h): the reference.
Mat4 propagate_ekf(const Mat4& Sigma, const std::vector<BeliefStep>& steps);

class SymplecticTransfer {
 public:
  using Mat8 = Eigen::Matrix<double, 8, 8>;
  static SymplecticTransfer identity();
  static SymplecticTransfer from_step(const BeliefStep& step);
  static SymplecticTransfer from_steps(const std::vector<BeliefStep>& steps);
  /// This edge, then `next`.
  SymplecticTransfer then(const SymplecticTransfer& next) const;
  /// Sigma at the end of the edge for Sigma at its start (B0 = Sigma, C0 = I).
  Mat4 apply(const Mat4& Sigma) const;
  const Mat8& matrix() const { return zeta_; }

 private:
  Mat8 zeta_ = Mat8::Identity();
};

class ScatteringTransfer {
 public:
  static ScatteringTransfer identity();
  static ScatteringTransfer from_step(const BeliefStep& step);
  static ScatteringTransfer from_steps(const std::vector<BeliefStep>& steps);
  /// This edge, then `next` (Redheffer star product).
  ScatteringTransfer then(const ScatteringTransfer& next) const;
  Mat4 apply(const Mat4& Sigma) const;

  const Mat4& A() const { return A_; }
  const Mat4& Q() const { return Q_; }  ///< noise the edge adds, seen at its end
  const Mat4& J() const { return J_; }  ///< information the edge gathers, seen at its start

 private:
  Mat4 A_ = Mat4::Identity(), Q_ = Mat4::Zero(), J_ = Mat4::Zero();
};

}  // namespace kestrel::planner
