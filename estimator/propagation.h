#pragma once
// One step of IMU propagation: the mean (trapezoidal integration between two readings) and
// the exact Jacobians of that discrete step, which the EKF uses and the UKF replaces by
// sigma points.
//
// Step from t to t + dt with readings (w0, a0) at t and (w1, a1) at t + dt:
//   r  = (w0' + w1') dt / 2 + (w0' x w1') dt^2 / 12,  w' = w - b_g,   R' = R Exp(r)
//   a  = (R (a0 - b_a) + R' (a1 - b_a)) / 2 + g_world
//   v' = v + a dt,                 p' = p + v dt + a dt^2 / 2,     biases constant.
// The rotation is third order for a rate varying linearly (the coning term), the rest second
// order; a constant-rate, constant-acceleration motion is integrated exactly.
// Phi = d(x' ⊟)/d(x ⊞) is exact for this map; the noise enters as the biases do (the noise
// of a reading acts like a bias error over one step), so V is built from Phi's bias columns.

#include <Eigen/Core>

#include "estimator/imu.h"
#include "estimator/nav_state.h"

namespace kestrel::estimator {

/// Readings at both ends of a step of dt seconds.
struct ImuInterval {
  double dt = 0.0;
  Eigen::Vector3d gyro0 = Eigen::Vector3d::Zero(), accel0 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro1 = Eigen::Vector3d::Zero(), accel1 = Eigen::Vector3d::Zero();
  bool gap = false;  ///< the readings are held across a gap in the stream (more noise)
};

/// The error-state transition of one step. Phi is the identity except for these blocks:
///   Phi_pv = dt I,  Phi_v* = v_*,  Phi_p* = dt/2 v_* (for * = theta, bg, ba),
///   Phi_theta,theta = theta_theta,  Phi_theta,bg = theta_bg.
struct Transition {
  double dt = 0.0;
  Eigen::Matrix3d v_theta = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d v_bg = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d v_ba = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d theta_theta = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d theta_bg = Eigen::Matrix3d::Zero();

  Matrix15d dense() const;
};

/// Mean after one step (no Jacobians): what the UKF pushes each sigma point through.
NavState propagate_mean(const NavState& x, const ImuInterval& u, double gravity);

/// Mean after one step and the transition of the error state.
struct ImuStep {
  NavState next;
  Transition phi;
};
ImuStep propagate(const NavState& x, const ImuInterval& u, double gravity);

/// Noise Jacobian V (15 x 12) of one step, noise w = [n_g; n_a; n_bg; n_ba] (reading noise,
/// bias increments).
using NoiseJacobian = Eigen::Matrix<double, 15, 12>;
NoiseJacobian noise_jacobian(const Transition& phi);
/// Variances of w over one step (the diagonal of W): density^2 / dt for the reading noise
/// (plus the gap sigmas^2 across a gap), density^2 / dt for the bias increments, whose
/// Jacobian is dt I.
Eigen::Matrix<double, 12, 1> noise_variances(const ImuNoise& noise, double dt, bool gap);

/// The discrete process noise R = V W V^T of one step (information.h's process_noise_diagonal
/// of the two functions above, written out block by block because it runs at IMU rate).
Matrix15d process_noise(const Transition& phi, const ImuNoise& noise, bool gap);

/// The reading at time fraction s in [0, 1] of an interval, interpolated linearly.
void interpolate_reading(const ImuInterval& u, double s, Eigen::Vector3d& gyro,
                         Eigen::Vector3d& accel);

}  // namespace kestrel::estimator
