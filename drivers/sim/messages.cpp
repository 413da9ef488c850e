#include "drivers/sim/messages.h"

#include <cmath>
#include <string>

#include "common/error.h"
#include "common/transport/channels.h"
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

VehicleCommand vehicle_command(const kestrel::vehicle_command_t& m) {
  auto bad = [](const std::string& what) {
    return InputError(std::string(channel::kVehicleCommand) + ": " + what);
  };
  VehicleCommand c;
  const Eigen::Vector3d position(m.position[0], m.position[1], m.position[2]);
  const Eigen::Vector3d velocity(m.velocity[0], m.velocity[1], m.velocity[2]);
  switch (m.mode) {
    case kestrel::vehicle_command_t::MODE_HOLD:
      c.mode = VehicleCommand::kHold;
      break;
    case kestrel::vehicle_command_t::MODE_VELOCITY:
      if (!velocity.allFinite() || !std::isfinite(m.yaw_rate)) throw bad("non-finite velocity or yaw rate");
      c.mode = VehicleCommand::kVelocity;
      c.velocity = velocity;
      c.yaw_rate = m.yaw_rate;
      break;
    case kestrel::vehicle_command_t::MODE_POSITION:
      if (!position.allFinite() || !std::isfinite(m.yaw)) throw bad("non-finite position or yaw");
      c.mode = VehicleCommand::kPosition;
      c.position = position;
      c.yaw = m.yaw;
      c.velocity = velocity.allFinite() ? velocity : Eigen::Vector3d::Zero();  // feed-forward is optional
      c.yaw_rate = std::isfinite(m.yaw_rate) ? m.yaw_rate : 0.0;
      break;
    default:
      throw bad("unknown mode " + std::to_string(static_cast<int>(m.mode)));
  }
  return c;
}

bool vehicle_estimate(const kestrel::state_t& m, VehicleEstimate& out) {
  if (m.status != kestrel::state_t::STATUS_OK && m.status != kestrel::state_t::STATUS_DEGRADED) return false;
  const Eigen::Isometry3d T = transport::from_message(m.T_world_body, channel::kState);
  const Eigen::Vector3d v(m.velocity[0], m.velocity[1], m.velocity[2]);
  if (!T.matrix().allFinite() || !v.allFinite()) return false;
  out.p = T.translation();
  out.v = v;
  out.yaw = std::atan2(T.linear()(1, 0), T.linear()(0, 0));
  return true;
}

}  // namespace kestrel::sim
