#pragma once
// Rigid transforms. A pose is an Eigen::Isometry3d named T_a_b: it maps points in frame b into
// frame a (p_a = T_a_b * p_b), so T_a_c = T_a_b * T_b_c.
//
// Two tangent parametrisations appear in kestrel, each with one purpose:
//  * se(3) exponential coordinates xi = [rho; phi] (exp/log below), for geometry;
//  * the pose error [dp; dtheta] used by every covariance in the messages and filters:
//    p = p_est + dp (parent frame), R = R_est * Exp(dtheta) (child frame) -> boxplus/boxminus.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace kestrel {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

namespace se3 {

/// T from a rotation and a translation.
Eigen::Isometry3d make(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);
/// T from a unit quaternion and a translation.
Eigen::Isometry3d make(const Eigen::Quaterniond& q, const Eigen::Vector3d& t);

/// exp of xi = [rho; phi]: R = Exp(phi), t = Jl(phi) rho.
Eigen::Isometry3d exp(const Vector6d& xi);
/// Inverse of exp().
Vector6d log(const Eigen::Isometry3d& T);

/// Adjoint of T acting on [rho; phi]: T * exp(xi) * T^-1 = exp(Ad(T) xi).
Matrix6d adjoint(const Eigen::Isometry3d& T);

/// Pose error retraction: p + dp, R * Exp(dtheta), with delta = [dp; dtheta].
Eigen::Isometry3d boxplus(const Eigen::Isometry3d& T, const Vector6d& delta);
/// The delta with boxplus(T_b, delta) = T_a.
Vector6d boxminus(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b);

/// Pose between two poses: translation linear, rotation by slerp; s in [0, 1].
Eigen::Isometry3d interpolate(const Eigen::Isometry3d& T0, const Eigen::Isometry3d& T1, double s);

/// Translation distance and rotation angle (radians) of T_a^-1 * T_b.
double translation_distance(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b);
double rotation_distance(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b);

/// True if every coefficient is finite and the rotation is orthonormal to `tolerance`.
bool is_valid(const Eigen::Isometry3d& T, double tolerance = 1e-6);

}  // namespace se3
}  // namespace kestrel
