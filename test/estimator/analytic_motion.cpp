#include "test/estimator/analytic_motion.h"

#include <cmath>

namespace kestrel::estimator::test {

double Signal::value(double t) const {
  double v = constant;
  for (const auto& s : terms) v += s.amplitude * std::sin(s.omega * t + s.phase);
  return v;
}
double Signal::rate(double t) const {
  double v = 0.0;
  for (const auto& s : terms) v += s.amplitude * s.omega * std::cos(s.omega * t + s.phase);
  return v;
}
double Signal::acceleration(double t) const {
  double v = 0.0;
  for (const auto& s : terms) v -= s.amplitude * s.omega * s.omega * std::sin(s.omega * t + s.phase);
  return v;
}

NavState AnalyticMotion::state(double t) const {
  NavState s;
  s.p_world_body = {x.value(t), y.value(t), z.value(t)};
  s.v_world_body = {x.rate(t), y.rate(t), z.rate(t)};
  s.R_world_body = (Eigen::AngleAxisd(yaw.value(t), Eigen::Vector3d::UnitZ()) *
                    Eigen::AngleAxisd(pitch.value(t), Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(roll.value(t), Eigen::Vector3d::UnitX()))
                       .toRotationMatrix();
  return s;
}

Eigen::Vector3d AnalyticMotion::angular_velocity_body(double t) const {
  const double ph = roll.value(t), th = pitch.value(t);
  const double dph = roll.rate(t), dth = pitch.rate(t), dps = yaw.rate(t);
  return {dph - dps * std::sin(th),  //
          dth * std::cos(ph) + dps * std::cos(th) * std::sin(ph),
          -dth * std::sin(ph) + dps * std::cos(th) * std::cos(ph)};
}

Eigen::Vector3d AnalyticMotion::specific_force_body(double t) const {
  const Eigen::Vector3d a(x.acceleration(t), y.acceleration(t), z.acceleration(t) + gravity);
  return state(t).R_world_body.transpose() * a;
}

AnalyticMotion AnalyticMotion::gentle() {
  AnalyticMotion m;
  m.x = {0.0, {{0.03, 0.7, 0.1}, {0.01, 2.1, 1.0}}};
  m.y = {0.0, {{0.02, 0.9, 0.5}}};
  m.z = {1.0, {{0.02, 1.1, 0.3}}};
  m.roll = {0.0, {{0.02, 1.3, 0.2}}};
  m.pitch = {0.0, {{0.02, 1.7, 0.9}}};
  m.yaw = {0.3, {{0.05, 0.5, 0.0}}};
  return m;
}

AnalyticMotion AnalyticMotion::aggressive() {
  AnalyticMotion m;
  m.x = {0.0, {{1.2, 1.1, 0.0}, {0.2, 3.7, 0.4}}};
  m.y = {0.0, {{0.8, 1.6, 1.0}, {0.1, 4.3, 0.2}}};
  m.z = {1.2, {{0.3, 2.3, 0.7}}};
  m.roll = {0.0, {{0.25, 2.9, 0.1}}};
  m.pitch = {0.0, {{0.2, 3.3, 1.3}}};
  m.yaw = {0.0, {{0.6, 0.9, 0.0}, {0.2, 2.7, 0.6}}};
  return m;
}

AnalyticMotion AnalyticMotion::still(double yaw) {
  AnalyticMotion m;
  m.z.constant = 1.0;
  m.yaw.constant = yaw;
  return m;
}

ImuRecord generate_imu(const AnalyticMotion& motion, double rate_hz, double duration_s,
                       const ImuNoiseTruth& truth, uint64_t seed, int64_t t0_utime) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  const auto noise3 = [&](double sigma) { return Eigen::Vector3d(sigma * n(rng), sigma * n(rng), sigma * n(rng)); };
  ImuRecord rec;
  const double dt = 1.0 / rate_hz;
  Eigen::Vector3d bg = truth.gyro_bias, ba = truth.accel_bias;
  const int count = static_cast<int>(std::floor(duration_s * rate_hz + 1e-9)) + 1;
  for (int i = 0; i < count; ++i) {
    const double t = i * dt;
    ImuSample s;
    s.utime = t0_utime + static_cast<int64_t>(std::llround(t * 1e6));
    s.gyro = motion.angular_velocity_body(t) + bg;
    s.accel = motion.specific_force_body(t) + ba;
    if (truth.add_noise) {
      s.gyro += noise3(truth.noise.gyro_noise_density / std::sqrt(dt));
      s.accel += noise3(truth.noise.accel_noise_density / std::sqrt(dt));
    }
    rec.samples.push_back(s);
    rec.gyro_bias.push_back(bg);
    rec.accel_bias.push_back(ba);
    if (truth.add_noise) {
      bg += noise3(truth.noise.gyro_bias_random_walk * std::sqrt(dt));
      ba += noise3(truth.noise.accel_bias_random_walk * std::sqrt(dt));
    }
  }
  return rec;
}

}  // namespace kestrel::estimator::test
