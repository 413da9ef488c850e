#pragma once
// Conversions between message structs and the Eigen / kestrel types the libraries use.
// Quaternions are w, x, y, z in messages.

#include <Eigen/Geometry>

#include "common/camera.h"
#include "common/geometry/se3.h"
#include "kestrel/camera_info_t.hpp"
#include "kestrel/pose3_t.hpp"
#include "kestrel/state_t.hpp"

namespace kestrel::transport {

kestrel::pose3_t to_message(const Eigen::Isometry3d& T);
/// Throws InputError (naming `what`) for a non-finite value or a quaternion far from unit
/// length; a slightly non-unit quaternion is normalised.
Eigen::Isometry3d from_message(const kestrel::pose3_t& m, const char* what);

kestrel::camera_info_t to_message(const PinholeCamera& camera, const Eigen::Isometry3d& T_body_camera);
/// Throws InputError (naming `what`) for an unusable camera.
PinholeCamera from_message(const kestrel::camera_info_t& m, const char* what);

/// Row-major 6x6 from/to a message's double[36].
Matrix6d covariance_from(const double (&c)[36]);
void covariance_to(const Matrix6d& m, double (&c)[36]);

/// The pose block of STATE's error-state covariance in pose_t's convention, [dp (world);
/// dtheta (body)]: rows and columns 0-2 and 6-8 of state_t's. Zero where the state carries
/// fewer (cov_dim < 9, or rows shorter than cov_dim says).
Matrix6d pose_covariance_from(const kestrel::state_t& m);

}  // namespace kestrel::transport
