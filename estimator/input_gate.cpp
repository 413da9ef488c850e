#include "estimator/input_gate.h"

#include <cstdio>

#include "common/geometry/so3.h"
#include "estimator/estimator.h"

namespace kestrel::estimator {
namespace {

std::string beyond_range(const char* sensor, const char* unit, const char* option, double limit,
                         const Eigen::Vector3d& reading, int64_t utime, const std::string& what) {
  const double worst = reading.cwiseAbs().maxCoeff();
  if (worst <= limit) return {};
  return what + ": sample at utime " + std::to_string(utime) + ": " + sensor + " reads " +
         short_number(worst) + " " + unit + " on an axis, beyond the sensor's range of " +
         short_number(limit) + " " + unit + " (" + option + ")";
}

int64_t& counter_of(EstimatorCounters& c, Reason reason) {
  switch (reason) {
    case Reason::kImuInvalid: return c.imu_invalid;
    case Reason::kImuAccelRange: return c.imu_accel_range;
    case Reason::kImuGyroRange: return c.imu_gyro_range;
    case Reason::kImuTimeJump: return c.imu_time_jumps;
    case Reason::kImuResync: return c.imu_resyncs;
    case Reason::kVoInvalid: return c.vo_invalid;
    case Reason::kVoCovariance: return c.vo_bad_covariance;
    case Reason::kVoTimeJump: return c.vo_time_jumps;
    case Reason::kVoImplausible: return c.vo_implausible;
    case Reason::kVoUnknownReference: return c.vo_unknown_reference;
    case Reason::kVoResync: return c.vo_resyncs;
    case Reason::kCorrectionInvalid: return c.corrections_invalid;
    case Reason::kCorrectionCovariance: return c.corrections_bad_covariance;
    case Reason::kCorrectionTimeJump: return c.corrections_time_jumps;
    case Reason::kCorrectionImplausible: return c.corrections_implausible;
  }
  return c.imu_invalid;  // not reached: every reason is listed
}

}  // namespace

void count_refusal(EstimatorCounters& c, Reason reason) {
  ++counter_of(c, reason);
  if (reason == Reason::kVoCovariance) ++c.vo_invalid;
  if (reason == Reason::kCorrectionCovariance) ++c.corrections_invalid;
}

std::string describe(Reason reason, const InputGateOptions& o) {
  const std::string jump = "--max-time-jump " + short_number(o.max_time_jump_s) + " s";
  switch (reason) {
    case Reason::kImuInvalid: return "IMU: non-finite readings or negative stamps";
    case Reason::kImuAccelRange:
      return "IMU: accelerometer readings beyond the sensor's range of " + short_number(o.max_accel) +
             " m/s^2 (--imu-max-accel)";
    case Reason::kImuGyroRange:
      return "IMU: gyro readings beyond the sensor's range of " + short_number(o.max_gyro) +
             " rad/s (--imu-max-rate)";
    case Reason::kImuTimeJump: return "IMU: stamps beyond " + jump + " of the stream's time, held";
    case Reason::kImuResync: return "IMU: a new time base; the filter restarted on it";
    case Reason::kVoInvalid: return "VO_UPDATE: non-finite or non-rigid poses";
    case Reason::kVoCovariance: return "VO_UPDATE: covariances not symmetric positive definite";
    case Reason::kVoTimeJump: return "VO_UPDATE: stamps beyond " + jump + " of the estimator's time";
    case Reason::kVoImplausible:
      return "VO_UPDATE: motions faster than " + short_number(o.vo_max_speed) + " m/s or " +
             short_number(o.vo_max_rate) + " rad/s (--vo-max-speed, --vo-max-rate)";
    case Reason::kVoUnknownReference: return "VO_UPDATE: against frames this estimator cannot place";
    case Reason::kVoResync: return "VO_UPDATE: a new time base; the visual-only estimator restarted on it";
    case Reason::kCorrectionInvalid: return "SLAM_CORRECTION: non-finite or non-rigid poses";
    case Reason::kCorrectionCovariance:
      return "SLAM_CORRECTION: covariances not symmetric positive definite";
    case Reason::kCorrectionTimeJump: return "SLAM_CORRECTION: stamps beyond " + jump + " ahead of the estimator's time";
    case Reason::kCorrectionImplausible:
      return "SLAM_CORRECTION: corrections further than " + short_number(o.correction_max_jump_m) +
             " m from the state (--correction-max-jump)";
  }
  return {};
}

std::string short_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}

std::string accel_beyond_range(const InputGateOptions& o, const Eigen::Vector3d& accel, int64_t utime,
                               const std::string& what) {
  return beyond_range("the accelerometer", "m/s^2", "--imu-max-accel", o.max_accel, accel, utime, what);
}

std::string gyro_beyond_range(const InputGateOptions& o, const Eigen::Vector3d& gyro, int64_t utime,
                              const std::string& what) {
  return beyond_range("the gyro", "rad/s", "--imu-max-rate", o.max_gyro, gyro, utime, what);
}

std::string implausible_motion(const InputGateOptions& o, const VoUpdate& u, const std::string& what) {
  const double dt_s = seconds_between(u.reference_utime, u.utime);
  // The body's motion, not the camera's: that is what moves the state (and a lever arm turns
  // a camera's rotation into a body's translation).
  const Eigen::Isometry3d motion = u.T_body_camera * u.T_refcam_curcam * u.T_body_camera.inverse();
  const double speed = motion.translation().norm() / dt_s;
  const double rate = so3::angle(motion.linear()) / dt_s;
  const std::string at = what + ": update at utime " + std::to_string(u.utime) + " against frame " +
                         std::to_string(u.reference_utime) + " (" + short_number(dt_s) + " s before)";
  if (speed > o.vo_max_speed)
    return at + ": the body moved " + short_number(motion.translation().norm()) + " m, " +
           short_number(speed) + " m/s, beyond " + short_number(o.vo_max_speed) + " m/s (--vo-max-speed)";
  if (rate > o.vo_max_rate)
    return at + ": the body turned " + short_number(so3::angle(motion.linear())) + " rad, " +
           short_number(rate) + " rad/s, beyond " + short_number(o.vo_max_rate) + " rad/s (--vo-max-rate)";
  return {};
}

std::string time_jump(const InputGateOptions& o, const std::string& what, int64_t utime, int64_t newest) {
  const double d_s = seconds_between(newest, utime);
  return what + " at utime " + std::to_string(utime) + " is " + short_number(std::abs(d_s)) + " s " +
         (d_s > 0 ? "ahead of" : "behind") + " the newest, utime " + std::to_string(newest) +
         ", beyond --max-time-jump " + short_number(o.max_time_jump_s) + " s";
}

}  // namespace kestrel::estimator
