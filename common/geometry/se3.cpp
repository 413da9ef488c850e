#include "common/geometry/se3.h"

#include <cmath>

#include "common/geometry/so3.h"

namespace kestrel::se3 {
namespace {

// Left Jacobian of SO(3): Jl(phi) = Jr(-phi).
Eigen::Matrix3d left_jacobian(const Eigen::Vector3d& phi) { return so3::right_jacobian(-phi); }
Eigen::Matrix3d left_jacobian_inverse(const Eigen::Vector3d& phi) {
  return so3::right_jacobian_inverse(-phi);
}

}  // namespace

Eigen::Isometry3d make(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

Eigen::Isometry3d make(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) {
  return make(q.normalized().toRotationMatrix(), t);
}

Eigen::Isometry3d exp(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d phi = xi.tail<3>();
  return make(so3::exp(phi), left_jacobian(phi) * rho);
}

Vector6d log(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d phi = so3::log(T.linear());
  Vector6d xi;
  xi << left_jacobian_inverse(phi) * T.translation(), phi;
  return xi;
}

Matrix6d adjoint(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d R = T.linear();
  Matrix6d A = Matrix6d::Zero();
  A.topLeftCorner<3, 3>() = R;
  A.topRightCorner<3, 3>() = so3::hat(T.translation()) * R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

Eigen::Isometry3d boxplus(const Eigen::Isometry3d& T, const Vector6d& delta) {
  return make(T.linear() * so3::exp(delta.tail<3>()), T.translation() + delta.head<3>());
}

Vector6d boxminus(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b) {
  Vector6d d;
  d << T_a.translation() - T_b.translation(), so3::log(T_b.linear().transpose() * T_a.linear());
  return d;
}

Eigen::Isometry3d interpolate(const Eigen::Isometry3d& T0, const Eigen::Isometry3d& T1, double s) {
  const Eigen::Quaterniond q0(T0.linear());
  const Eigen::Quaterniond q1(T1.linear());
  return make(q0.slerp(s, q1), (1.0 - s) * T0.translation() + s * T1.translation());
}

double translation_distance(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b) {
  return (T_a.inverse() * T_b).translation().norm();
}

double rotation_distance(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b) {
  return so3::angle(T_a.linear().transpose() * T_b.linear());
}

bool is_valid(const Eigen::Isometry3d& T, double tolerance) {
  return T.matrix().allFinite() && so3::is_valid(T.linear(), tolerance);
}

}  // namespace kestrel::se3
