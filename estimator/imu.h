#pragma once
// Inertial samples and the IMU noise model the filters assume.
//
// A reading is true value + bias + white noise: gyro = omega_body + b_g + n_g, accel =
// R_world_body^T (a_world - g_world) + b_a + n_a (specific force, +g up at rest), body frame
// x forward, y left, z up; the biases follow random walks. Densities are continuous-time
// (per sqrt(Hz)); a sample at rate 1/dt has white-noise variance density^2 / dt.

#include <Eigen/Core>
#include <cstdint>
#include <optional>

namespace kestrel::estimator {

struct ImuSample {
  int64_t utime = 0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   ///< rad/s, body
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  ///< specific force, m/s^2, body
};

/// An IMU message as it comes: either part may be missing (a Kinect has no gyro).
struct ImuReading {
  int64_t utime = 0;
  std::optional<Eigen::Vector3d> gyro;   ///< rad/s, body
  std::optional<Eigen::Vector3d> accel;  ///< specific force, m/s^2, body

  bool complete() const { return gyro.has_value() && accel.has_value(); }
  /// The sample of a complete reading.
  ImuSample sample() const { return {utime, *gyro, *accel}; }
};

struct ImuNoise {
  double gyro_noise_density = 1.7e-4;      ///< rad/s/sqrt(Hz)
  double accel_noise_density = 2.0e-3;     ///< m/s^2/sqrt(Hz)
  double gyro_bias_random_walk = 2.0e-5;   ///< rad/s^2/sqrt(Hz)
  double accel_bias_random_walk = 3.0e-3;  ///< m/s^3/sqrt(Hz)
  /// Across a gap in the IMU stream (an interval longer than the options' max_imu_dt_s) the
  /// held reading may be far from the truth: this much white acceleration and rotation rate
  /// (standard deviation over the gap) is added, so the covariance grows with the gap.
  double gap_accel_sigma = 2.0;  ///< m/s^2
  double gap_gyro_sigma = 0.5;   ///< rad/s
};

/// Standard gravity; world z is up, so g_world = (0, 0, -gravity).
inline constexpr double kStandardGravity = 9.80665;

}  // namespace kestrel::estimator
