#pragma once
// Rotations: the exponential and logarithm maps of SO(3) and their Jacobians.
//
// Conventions used across kestrel: a rotation perturbation is applied on the right,
// R = R_est * Exp(dtheta), so dtheta lives in the rotated (body/child) frame. The right
// Jacobian Jr satisfies Exp(phi + dphi) ~= Exp(phi) * Exp(Jr(phi) * dphi).

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace kestrel::so3 {

/// Skew-symmetric matrix [v]x so that hat(a) * b = a.cross(b).
Eigen::Matrix3d hat(const Eigen::Vector3d& v);
/// Inverse of hat() for a skew-symmetric matrix.
Eigen::Vector3d vee(const Eigen::Matrix3d& m);

/// Rotation by angle |phi| about phi / |phi| (Rodrigues), accurate near phi = 0.
Eigen::Matrix3d exp(const Eigen::Vector3d& phi);
/// Rotation vector of R with angle in [0, pi], accurate near 0 and pi.
Eigen::Vector3d log(const Eigen::Matrix3d& R);

/// Right Jacobian of SO(3) and its inverse.
Eigen::Matrix3d right_jacobian(const Eigen::Vector3d& phi);
Eigen::Matrix3d right_jacobian_inverse(const Eigen::Vector3d& phi);

/// Angle of a rotation, radians in [0, pi].
double angle(const Eigen::Matrix3d& R);

/// Nearest rotation matrix (SVD projection); removes drift from repeated products.
Eigen::Matrix3d orthonormalize(const Eigen::Matrix3d& M);

/// Whether R is a rotation: every entry finite, |R^T R - I| and |det R - 1| below `tolerance`.
bool is_valid(const Eigen::Matrix3d& R, double tolerance = 1e-6);

}  // namespace kestrel::so3
