#include "test/estimator/scenario.h"

#include <cmath>

#include "common/numbers.h"

namespace kestrel::estimator::test {

ScenarioOptions gentle_run(double duration_s) {
  ScenarioOptions o;
  o.duration_s = duration_s;
  o.imu.gyro_bias = {0.002, -0.001, 0.001};
  return o;
}

Matrix15d initial_covariance(const InitOptions& init) {
  Matrix15d P = Matrix15d::Zero();
  P.diagonal() << Eigen::Vector3d::Constant(sq(init.sigma_position)),
      Eigen::Vector3d::Constant(sq(init.sigma_velocity)), sq(init.sigma_tilt), sq(init.sigma_tilt),
      sq(init.sigma_yaw), Eigen::Vector3d::Constant(sq(init.sigma_gyro_bias)),
      Eigen::Vector3d::Constant(sq(init.sigma_accel_bias));
  return P;
}

std::vector<ScenarioStep> run_scenario(Estimator& estimator, const AnalyticMotion& motion,
                                       const ScenarioOptions& o,
                                       const std::function<void(size_t)>& before_imu) {
  const ImuRecord imu = generate_imu(motion, o.imu_rate_hz, o.duration_s, o.imu, o.seed);
  SyntheticVo vo(o.vo, o.seed + 1000);
  struct Pending {
    int64_t deliver_utime;
    VoUpdate update;
  };
  std::vector<Pending> queue;
  const int64_t t0 = imu.samples.front().utime;
  const int64_t vo_period = static_cast<int64_t>(std::llround(1e6 / o.vo_rate_hz));
  const int64_t latency = static_cast<int64_t>(std::llround(o.vo_latency_s * 1e6));
  int64_t next_frame = t0 + vo_period / 2;  // frames fall between IMU samples

  std::vector<ScenarioStep> out;
  for (size_t i = 0; i < imu.samples.size(); ++i) {
    const ImuSample& s = imu.samples[i];
    while (next_frame <= s.utime) {
      queue.push_back({next_frame + latency,
                       vo.next(next_frame, motion.state(seconds(next_frame)).T_world_body())});
      next_frame += vo_period;
    }
    for (auto it = queue.begin(); it != queue.end();) {
      if (it->deliver_utime <= s.utime) {
        if (o.alter_vo) o.alter_vo(it->update);
        estimator.add_vo(it->update);
        it = queue.erase(it);
      } else {
        ++it;
      }
    }
    if (before_imu) before_imu(i);
    if (i == 0 && o.start_from_truth) {
      NavState start = motion.state(0.0);
      start.gyro_bias = imu.gyro_bias[0];
      start.accel_bias = imu.accel_bias[0];
      // A consistent start: the initial error is drawn from the initial covariance.
      std::mt19937_64 rng(o.seed + 7);
      std::normal_distribution<double> n(0.0, 1.0);
      const Matrix15d P0 = initial_covariance(estimator.options().init);
      Vector15d e;
      for (int k = 0; k < 15; ++k) e[k] = std::sqrt(P0(k, k)) * n(rng);
      estimator.initialize(boxplus(start, e), P0, s);
    } else if (!o.drop_imu || !o.drop_imu(s)) {
      estimator.add_imu(s);
    }
    if (const auto output = estimator.output()) {
      ScenarioStep step;
      step.output = *output;
      step.truth = motion.state(seconds(s.utime));
      step.truth.gyro_bias = imu.gyro_bias[i];
      step.truth.accel_bias = imu.accel_bias[i];
      out.push_back(step);
    }
  }
  return out;
}

}  // namespace kestrel::estimator::test
