#include "estimator/messages.h"

#include "common/error.h"
#include "common/transport/convert.h"

namespace kestrel::estimator {
namespace {

Eigen::Vector3d vec3(const double (&v)[3]) { return {v[0], v[1], v[2]}; }
void copy3(const Eigen::Vector3d& v, double (&out)[3]) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

}  // namespace

ImuReading imu_from_message(const kestrel::imu_t& m, const std::string& channel) {
  const std::string what = channel + ": IMU sample at utime " + std::to_string(m.utime);
  ImuReading r;
  r.utime = m.utime;
  if (m.fields & kestrel::imu_t::HAS_GYRO) r.gyro = vec3(m.angular_velocity);
  if (m.fields & kestrel::imu_t::HAS_ACCEL) r.accel = vec3(m.linear_acceleration);
  if (!r.gyro && !r.accel)
    throw InputError(what + " has neither a gyro nor an accelerometer reading (fields = " +
                     std::to_string(static_cast<int>(m.fields)) + ")");
  // The filter's own checks, on the parts there are (a missing part stands in as zero).
  validate_imu({r.utime, r.gyro.value_or(Eigen::Vector3d::Zero()), r.accel.value_or(Eigen::Vector3d::Zero())},
               channel);
  return r;
}

VoUpdate vo_from_message(const kestrel::vo_update_t& m, const std::string& channel) {
  VoUpdate u;
  u.utime = m.utime;
  u.reference_utime = m.reference_utime;
  u.ok = m.status == kestrel::vo_update_t::STATUS_OK;
  if (!u.ok) return u;  // a failure's pose and covariance are meaningless
  // "CHANNEL: ..." as every rejection reads (Node drops the channel it names first).
  const std::string what = channel + ": update at utime " + std::to_string(m.utime);
  u.T_refcam_curcam = transport::from_message(m.T_reference_current, what.c_str());
  u.T_body_camera = transport::from_message(m.T_body_camera, what.c_str());
  u.covariance = transport::covariance_from(m.covariance);
  return u;
}

PoseCorrection correction_from_message(const kestrel::slam_correction_t& m,
                                       const std::string& channel) {
  const std::string what = channel + ": correction at utime " + std::to_string(m.utime);
  PoseCorrection c;
  c.utime = m.utime;
  c.revision = m.graph_revision;
  c.T_world_body = transport::from_message(m.T_world_body, what.c_str());
  c.covariance = transport::covariance_from(m.covariance);
  return c;
}

kestrel::state_t state_to_message(const EstimatorOutput& out, EstimatorMode mode,
                                  FilterKind filter, int64_t seq) {
  kestrel::state_t m;
  m.utime = out.utime;
  m.seq = seq;
  m.filter = mode == EstimatorMode::kVisualOnly ? kestrel::state_t::FILTER_VISUAL_ONLY
              : filter == FilterKind::kUkf       ? kestrel::state_t::FILTER_UKF
                                                 : kestrel::state_t::FILTER_EKF;
  switch (out.status) {
    case Status::kInitializing: m.status = kestrel::state_t::STATUS_INITIALIZING; break;
    case Status::kOk: m.status = kestrel::state_t::STATUS_OK; break;
    case Status::kDegraded: m.status = kestrel::state_t::STATUS_DEGRADED; break;
  }
  m.T_world_body = transport::to_message(out.nav.T_world_body());
  copy3(out.nav.v_world_body, m.velocity);
  copy3(out.angular_velocity, m.angular_velocity);
  copy3(out.nav.gyro_bias, m.gyro_bias);
  copy3(out.nav.accel_bias, m.accel_bias);
  m.cov_dim = idx::kNav;
  m.covariance.assign(idx::kNav, std::vector<double>(idx::kNav, 0.0));
  for (int r = 0; r < idx::kNav; ++r)
    for (int c = 0; c < idx::kNav; ++c) m.covariance[r][c] = out.covariance(r, c);
  return m;
}

}  // namespace kestrel::estimator
