#include "drivers/sim/imu.h"

#include <cmath>
#include <stdexcept>

namespace kestrel::sim {

ImuSimulator::ImuSimulator(const Flight& flight, const ImuOptions& options, uint64_t seed)
    : flight_(flight), options_(options), seed_(seed), rng_(0) {
  if (!(options_.rate_hz > 0)) throw std::invalid_argument("IMU rate must be > 0");
  reset();
}

Eigen::Vector3d ImuSimulator::normal3() {
  const double x = rng_.normal(), y = rng_.normal(), z = rng_.normal();
  return {x, y, z};
}

void ImuSimulator::reset() {
  rng_ = Rng(derive(seed_, tag("imu")));
  seq_ = 0;
  gyro_bias_.setZero();
  accel_bias_.setZero();
  if (options_.noise) {
    gyro_bias_ = options_.gyro_bias_initial * normal3();
    accel_bias_ = options_.accel_bias_initial * normal3();
  }
}

ImuSample ImuSimulator::next() {
  ImuSample s;
  s.seq = seq_;
  s.t = static_cast<double>(seq_) / options_.rate_hz;
  const MotionState m = flight_.state(s.t);
  s.gyro = m.omega_body;
  s.accel = m.specific_force_body();
  if (options_.noise) {
    const double sqrt_rate = std::sqrt(options_.rate_hz), sqrt_dt = 1.0 / sqrt_rate;
    s.gyro_bias = gyro_bias_;
    s.accel_bias = accel_bias_;
    s.gyro += gyro_bias_ + options_.gyro_noise_density * sqrt_rate * normal3();
    s.accel += accel_bias_ + options_.accel_noise_density * sqrt_rate * normal3();
    gyro_bias_ += options_.gyro_bias_walk * sqrt_dt * normal3();
    accel_bias_ += options_.accel_bias_walk * sqrt_dt * normal3();
  }
  ++seq_;
  return s;
}

}  // namespace kestrel::sim
