#include "test/estimator/synthetic_log.h"

#include <cmath>

#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "estimator/eval/synthetic_vo.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/slam_correction_t.hpp"
#include "test/estimator/analytic_motion.h"

namespace kestrel::estimator::test {

kestrel::imu_t imu_message(const ImuSample& s) {
  kestrel::imu_t m{};
  m.utime = s.utime;
  m.fields = kestrel::imu_t::HAS_GYRO | kestrel::imu_t::HAS_ACCEL;
  for (int i = 0; i < 3; ++i) {
    m.angular_velocity[i] = s.gyro[i];
    m.linear_acceleration[i] = s.accel[i];
  }
  return m;
}

kestrel::vo_update_t vo_message(const VoUpdate& u) {
  kestrel::vo_update_t m{};
  m.utime = u.utime;
  m.reference_utime = u.reference_utime;
  m.status = u.ok ? kestrel::vo_update_t::STATUS_OK : kestrel::vo_update_t::STATUS_NO_REFERENCE;
  m.T_reference_current = transport::to_message(u.T_refcam_curcam);
  m.T_body_camera = transport::to_message(u.T_body_camera);
  transport::covariance_to(u.covariance, m.covariance);
  return m;
}

SyntheticLog write_log(const std::string& path, double duration_s, bool with_bad_messages,
                       bool with_ground_truth) {
  const auto motion = AnalyticMotion::still(0.3);
  ImuNoiseTruth truth;
  truth.gyro_bias = {0.002, -0.001, 0.003};
  truth.accel_bias = {0.02, -0.03, 0.05};
  SyntheticLog out;
  out.imu = generate_imu(motion, 200.0, duration_s, truth, 5).samples;
  SyntheticVo vo(SyntheticVoOptions{}, 6);
  transport::LogWriter log(path);
  int64_t next_frame = out.imu.front().utime + 1667;
  std::vector<VoUpdate> pending;
  for (size_t i = 0; i < out.imu.size(); ++i) {
    const ImuSample& s = out.imu[i];
    while (next_frame <= s.utime) {
      pending.push_back(vo.next(next_frame, motion.state(seconds(next_frame)).T_world_body()));
      next_frame += 33333;
    }
    while (!pending.empty() && pending.front().utime + 30000 <= s.utime) {
      out.vo.push_back(pending.front());
      log.write_message("VO_UPDATE", s.utime, vo_message(pending.front()));
      pending.erase(pending.begin());
    }
    log.write_message("IMU", s.utime, imu_message(s));
    if (with_ground_truth) {
      kestrel::ground_truth_t g{};
      g.utime = s.utime;
      g.frame = kestrel::ground_truth_t::FRAME_BODY;
      g.T_world_frame = transport::to_message(motion.state(seconds(s.utime)).T_world_body());
      log.write_message("GROUND_TRUTH", s.utime, g);
    }
    if (with_bad_messages && i == 300) {
      log.write_message("IMU", s.utime, imu_message(s));  // duplicate
      ImuSample nan = s;
      nan.utime += 1;
      nan.gyro.x() = std::nan("");
      log.write_message("IMU", nan.utime, imu_message(nan));  // NaN: skipped
      log.write("VO_UPDATE", s.utime, {1, 2, 3});               // corrupt: skipped
    }
    if (i == 800) {  // a correction for 1 s ago, at the true pose (yaw 0.3, origin)
      kestrel::slam_correction_t c{};
      c.utime = out.imu[i - 200].utime;
      c.graph_revision = 1;
      c.T_world_body = transport::to_message(motion.state(seconds(c.utime)).T_world_body());
      log.write_message("SLAM_CORRECTION", s.utime, c);
    }
  }
  log.close();
  return out;
}

}  // namespace kestrel::estimator::test
