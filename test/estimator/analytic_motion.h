#pragma once
// Smooth test motions with exact derivatives, and the IMU readings they produce.
//
// Position: each axis a constant plus a sum of sinusoids; attitude: roll, pitch and yaw
// (R = Rz(yaw) Ry(pitch) Rx(roll)) each a constant plus sinusoids. Velocity, acceleration,
// body rates and specific force follow in closed form, so a noiseless IMU generated here is
// exact and any error after integration belongs to the integrator.

#include <Eigen/Geometry>
#include <cstdint>
#include <random>
#include <vector>

#include "estimator/imu.h"
#include "estimator/nav_state.h"

namespace kestrel::estimator::test {

struct Sinusoid {
  double amplitude = 0.0;
  double omega = 0.0;  ///< rad/s
  double phase = 0.0;
};

/// c + sum a sin(w t + phi), with derivatives.
struct Signal {
  double constant = 0.0;
  std::vector<Sinusoid> terms;
  double value(double t) const;
  double rate(double t) const;
  double acceleration(double t) const;
};

class AnalyticMotion {
 public:
  Signal x, y, z, roll, pitch, yaw;
  double gravity = kStandardGravity;

  /// The true state at t (biases zero).
  NavState state(double t) const;
  Eigen::Vector3d angular_velocity_body(double t) const;
  Eigen::Vector3d specific_force_body(double t) const;

  /// A hovering-vehicle-like motion: a few centimetres and degrees of smooth wander.
  static AnalyticMotion gentle();
  /// Metres and tens of degrees at up to ~1 Hz, about 1.5 m/s and 3 m/s^2 at its peaks.
  static AnalyticMotion aggressive();
  /// Standing still, level, with the given yaw.
  static AnalyticMotion still(double yaw = 0.0);
};

struct ImuNoiseTruth {
  ImuNoise noise;                        ///< densities used to draw the noise
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   ///< initial true biases
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();
  bool add_noise = true;
};

/// IMU samples at `rate_hz` over [0, duration], utime = t * 1e6 + t0_utime. With noise, the
/// biases random-walk; true_biases (if given) receives them per sample.
struct ImuRecord {
  std::vector<ImuSample> samples;
  std::vector<Eigen::Vector3d> gyro_bias;
  std::vector<Eigen::Vector3d> accel_bias;
};
ImuRecord generate_imu(const AnalyticMotion& motion, double rate_hz, double duration_s,
                       const ImuNoiseTruth& truth, uint64_t seed, int64_t t0_utime = 1000000);

inline double seconds(int64_t utime, int64_t t0_utime = 1000000) {
  return 1e-6 * static_cast<double>(utime - t0_utime);
}

}  // namespace kestrel::estimator::test
