#pragma once
// The two pose spaces of a pose graph, SE(2) and SE(3): composition, the error of a relative
// pose measurement and its exact Jacobians, and the update (retraction) the solver applies.
//
// Error convention (g2o's, so chi2 figures compare with g2o and the published baselines): for
// an edge i -> j with measurement Z, E = Z^-1 * (X_i^-1 * X_j) and
//   SE(2): e = [t_E; angle(E) wrapped to (-pi, pi]]
//   SE(3): e = [t_E; vec(q_E)] with the sign of q_E chosen so that q_E.w >= 0,
// so chi2 = sum over edges of e^T Omega e. The derivation of the Jacobians is in
// slam/README.md ("Pose-graph error and Jacobians").
//
// Updates: SE(2) poses (x, y, theta) are updated additively; an SE(3) pose X = (R, t) by
// d = [rho; phi] as X <- (R Exp(phi), t + R rho), a right-multiplicative step.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "common/geometry/so3.h"
#include "common/numbers.h"

namespace kestrel::slam {

/// The plane: a pose is (x, y, theta), T_a_b maps b into a as p_a = R(theta) p_b + (x, y).
struct Se2 {
  static constexpr int kDim = 3;
  static constexpr int kRotationDim = 1;
  static constexpr const char* kName = "SE2";
  using Pose = Eigen::Vector3d;
  using Vector = Eigen::Matrix<double, kDim, 1>;
  using Matrix = Eigen::Matrix<double, kDim, kDim>;

  static Pose identity() { return Pose::Zero(); }
  static Eigen::Matrix2d rotation(double theta) {
    const double c = std::cos(theta), s = std::sin(theta);
    Eigen::Matrix2d R;
    R << c, -s, s, c;
    return R;
  }
  static Pose compose(const Pose& a, const Pose& b) {
    Pose out;
    out.head<2>() = a.head<2>() + rotation(a.z()) * b.head<2>();
    out.z() = wrap_angle(a.z() + b.z());
    return out;
  }
  static Pose inverse(const Pose& a) {
    Pose out;
    out.head<2>() = -(rotation(a.z()).transpose() * a.head<2>());
    out.z() = wrap_angle(-a.z());
    return out;
  }
  static Pose retract(const Pose& X, const Vector& d) {
    return {X.x() + d.x(), X.y() + d.y(), wrap_angle(X.z() + d.z())};
  }
  /// e for an edge whose measurement inverse is Z_inv.
  static Vector error(const Pose& Xi, const Pose& Xj, const Pose& Z_inv) {
    return compose(Z_inv, compose(inverse(Xi), Xj));
  }
  /// e and de/dXi, de/dXj.
  static Vector linearize(const Pose& Xi, const Pose& Xj, const Pose& Z_inv, Matrix& Ji,
                          Matrix& Jj) {
    const Eigen::Matrix2d Rz = rotation(Z_inv.z());
    const double c = std::cos(Xi.z()), s = std::sin(Xi.z());
    Eigen::Matrix2d Ri_t;  // R(theta_i)^T
    Ri_t << c, s, -s, c;
    Eigen::Matrix2d dRi_t;  // d R(theta_i)^T / d theta_i
    dRi_t << -s, c, -c, -s;
    const Eigen::Vector2d dt = Xj.head<2>() - Xi.head<2>();
    const Eigen::Matrix2d A = Rz * Ri_t;
    Vector e;
    e.head<2>() = A * dt + Z_inv.head<2>();
    e.z() = wrap_angle(Z_inv.z() + Xj.z() - Xi.z());
    Ji.setZero();
    Jj.setZero();
    Ji.topLeftCorner<2, 2>() = -A;
    Ji.topRightCorner<2, 1>() = Rz * dRi_t * dt;
    Ji(2, 2) = -1.0;
    Jj.topLeftCorner<2, 2>() = A;
    Jj(2, 2) = 1.0;
    return e;
  }
};

/// Space: a pose is an Eigen::Isometry3d T_a_b.
struct Se3 {
  static constexpr int kDim = 6;
  static constexpr int kRotationDim = 3;
  static constexpr const char* kName = "SE3";
  using Pose = Eigen::Isometry3d;
  using Vector = Eigen::Matrix<double, kDim, 1>;
  using Matrix = Eigen::Matrix<double, kDim, kDim>;

  static Pose identity() { return Pose::Identity(); }
  static Pose compose(const Pose& a, const Pose& b) { return a * b; }
  static Pose inverse(const Pose& a) { return a.inverse(Eigen::Isometry); }
  static Pose retract(const Pose& X, const Vector& d) {
    Pose out;
    out.linear() = X.linear() * so3::exp(d.tail<3>());
    out.translation() = X.translation() + X.linear() * d.head<3>();
    out.makeAffine();
    return out;
  }
  /// Unit quaternion of R with w >= 0 (the sign g2o's error uses).
  static Eigen::Quaterniond positive_quaternion(const Eigen::Matrix3d& R) {
    Eigen::Quaterniond q(R);
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();
    return q;
  }
  static Vector error(const Pose& Xi, const Pose& Xj, const Pose& Z_inv) {
    const Pose E = Z_inv * (Xi.inverse(Eigen::Isometry) * Xj);
    Vector e;
    e.head<3>() = E.translation();
    e.tail<3>() = positive_quaternion(E.linear()).vec();
    return e;
  }
  static Vector linearize(const Pose& Xi, const Pose& Xj, const Pose& Z_inv, Matrix& Ji,
                          Matrix& Jj) {
    const Eigen::Matrix3d Ri_t = Xi.linear().transpose();
    const Eigen::Matrix3d R_delta = Ri_t * Xj.linear();
    const Eigen::Vector3d t_delta = Ri_t * (Xj.translation() - Xi.translation());
    const Eigen::Matrix3d& Rz = Z_inv.linear();
    const Eigen::Quaterniond q = positive_quaternion(Rz * R_delta);
    // d vec(q (x) [1, psi/2]) / d psi for a right perturbation psi of E's rotation.
    const Eigen::Matrix3d Q = 0.5 * (q.w() * Eigen::Matrix3d::Identity() + so3::hat(q.vec()));
    Vector e;
    e.head<3>() = Rz * t_delta + Z_inv.translation();
    e.tail<3>() = q.vec();
    Ji.topLeftCorner<3, 3>() = -Rz;
    Ji.topRightCorner<3, 3>() = Rz * so3::hat(t_delta);
    Ji.bottomLeftCorner<3, 3>().setZero();
    Ji.bottomRightCorner<3, 3>() = -Q * R_delta.transpose();
    Jj.topLeftCorner<3, 3>() = Rz * R_delta;
    Jj.topRightCorner<3, 3>().setZero();
    Jj.bottomLeftCorner<3, 3>().setZero();
    Jj.bottomRightCorner<3, 3>() = Q;
    return e;
  }
};

}  // namespace kestrel::slam
