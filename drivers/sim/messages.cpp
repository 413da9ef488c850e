#include "drivers/sim/messages.h"

#include "common/transport/convert.h"

namespace kestrel::sim {
namespace {

void copy3(const Eigen::Vector3d& v, double (&out)[3]) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

}  // namespace

kestrel::imu_t imu_message(int64_t utime, const ImuSample& s) {
  kestrel::imu_t m{};
  m.utime = utime;
  m.seq = s.seq;
  m.fields = kestrel::imu_t::HAS_GYRO | kestrel::imu_t::HAS_ACCEL;
  copy3(s.gyro, m.angular_velocity);
  copy3(s.accel, m.linear_acceleration);
  return m;
}

kestrel::ground_truth_t ground_truth_message(int64_t utime, const MotionState& truth, const ImuSample* biases) {
  kestrel::ground_truth_t m{};
  m.utime = utime;
  m.frame = kestrel::ground_truth_t::FRAME_BODY;
  m.T_world_frame = transport::to_message(truth.T_world_body);
  m.fields = kestrel::ground_truth_t::HAS_VELOCITY;
  copy3(truth.v_world, m.velocity);
  copy3(truth.omega_body, m.angular_velocity);
  if (biases) {
    m.fields |= kestrel::ground_truth_t::HAS_IMU_BIASES;
    copy3(biases->gyro_bias, m.gyro_bias);
    copy3(biases->accel_bias, m.accel_bias);
  }
  return m;
}

}  // namespace kestrel::sim
