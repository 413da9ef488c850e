#pragma once
// The simulated IMU: gyro and accelerometer samples of a flight's true motion.
//
// gyro  = omega_body + b_g + n_g,   accel = R^T (a + g e_z) + b_a + n_a,
// with white noise n of continuous density sigma (discrete sigma * sqrt(rate)) and biases
// that random-walk (b_{k+1} = b_k + sigma_rw sqrt(dt) w_k) from a random initial value. The
// biases of every sample are returned with it (ground truth). Defaults are MEMS grade
// (ADIS16448-like, as on many small quadrotors). With `noise` off the samples are exact.
// Draws come from a stream keyed by (seed, "imu"), so a seed gives the same samples always.

#include <Eigen/Core>
#include <cstdint>

#include "drivers/sim/flight.h"
#include "drivers/sim/random.h"

namespace kestrel::sim {

struct ImuOptions {
  double rate_hz = 200.0;
  bool noise = true;                       ///< white noise and biases (off: exact samples)
  double gyro_noise_density = 1.7e-4;      ///< rad/s/sqrt(Hz)
  double accel_noise_density = 2.0e-3;     ///< m/s^2/sqrt(Hz)
  double gyro_bias_walk = 2.0e-5;          ///< rad/s^2/sqrt(Hz)
  double accel_bias_walk = 3.0e-3;         ///< m/s^3/sqrt(Hz)
  double gyro_bias_initial = 5.0e-3;       ///< sigma of each initial gyro bias, rad/s
  double accel_bias_initial = 5.0e-2;      ///< sigma of each initial accelerometer bias, m/s^2
};

struct ImuSample {
  int64_t seq = 0;
  double t = 0.0;                                     ///< flight time, seconds (seq / rate)
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();     ///< rad/s, body axes
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();    ///< specific force, m/s^2, body axes
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();
};

class ImuSimulator {
 public:
  /// `flight` must outlive the simulator.
  ImuSimulator(const Flight& flight, const ImuOptions& options, uint64_t seed);

  /// The next sample (seq 0, 1, 2, ... at t = seq / rate_hz).
  ImuSample next();
  /// Starts again from sample 0 with the same draws.
  void reset();

  const ImuOptions& options() const { return options_; }

 private:
  Eigen::Vector3d normal3();

  const Flight& flight_;
  ImuOptions options_;
  uint64_t seed_;
  Rng rng_;
  int64_t seq_ = 0;
  Eigen::Vector3d gyro_bias_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias_ = Eigen::Vector3d::Zero();
};

}  // namespace kestrel::sim
