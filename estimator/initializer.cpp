#include "estimator/initializer.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "common/geometry/so3.h"
#include "common/numbers.h"

namespace kestrel::estimator {
namespace {

// The diagonal prior of a start; still and moving starts differ only in how well they know
// velocity, tilt and gyro bias.
Matrix15d start_covariance(const Eigen::Matrix3d& R_world_body, const InitOptions& o,
                           double sigma_velocity, double sigma_tilt, double sigma_gyro_bias) {
  Matrix15d P = Matrix15d::Zero();
  P.block<3, 3>(idx::kP, idx::kP).diagonal().setConstant(sq(o.sigma_position));
  P.block<3, 3>(idx::kV, idx::kV).diagonal().setConstant(sq(sigma_velocity));
  P.block<3, 3>(idx::kTheta, idx::kTheta) = attitude_covariance(R_world_body, sigma_tilt, o.sigma_yaw);
  P.block<3, 3>(idx::kBg, idx::kBg).diagonal().setConstant(sq(sigma_gyro_bias));
  P.block<3, 3>(idx::kBa, idx::kBa).diagonal().setConstant(sq(o.sigma_accel_bias));
  return P;
}

}  // namespace

Eigen::Matrix3d attitude_covariance(const Eigen::Matrix3d& R_world_body, double sigma_tilt,
                                    double sigma_yaw) {
  const Eigen::Vector3d up_body = R_world_body.transpose() * Eigen::Vector3d::UnitZ();
  return sq(sigma_tilt) * (Eigen::Matrix3d::Identity() - up_body * up_body.transpose()) +
         sq(sigma_yaw) * up_body * up_body.transpose();
}

double tilt_sigma(const Eigen::Matrix3d& R_world_body, const Eigen::Matrix3d& P_theta) {
  const Eigen::Vector3d up_body = R_world_body.transpose() * Eigen::Vector3d::UnitZ();
  const Eigen::Matrix3d level = Eigen::Matrix3d::Identity() - up_body * up_body.transpose();
  const Eigen::Matrix3d P_tilt = level * P_theta * level.transpose();
  return std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(P_tilt).eigenvalues().maxCoeff()));
}

Eigen::Matrix3d attitude_from_gravity(const Eigen::Vector3d& f, double yaw) {
  const double roll = std::atan2(f.y(), f.z());
  const double pitch = std::atan2(-f.x(), std::hypot(f.y(), f.z()));
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d mean_specific_force_in_last_frame(const std::vector<ImuSample>& window) {
  // Walk backwards from the last sample: R maps body-at-k into body-at-last.
  Eigen::Matrix3d R_last_k = Eigen::Matrix3d::Identity();
  Eigen::Vector3d sum = window.back().accel;
  for (size_t k = window.size() - 1; k-- > 0;) {
    const ImuSample& a = window[k];
    const ImuSample& b = window[k + 1];
    const double dt = 1e-6 * static_cast<double>(b.utime - a.utime);
    R_last_k = R_last_k * so3::exp(-0.5 * (a.gyro + b.gyro) * dt);
    sum += R_last_k * a.accel;
  }
  return sum / static_cast<double>(window.size());
}

void Initializer::reset() {
  window_.clear();
  first_utime_ = -1;
  last_vo_motion_utime_ = -1;
}

void Initializer::add_vo(const VoUpdate& u) {
  if (!u.ok || u.utime <= u.reference_utime) return;
  const double dt = 1e-6 * static_cast<double>(u.utime - u.reference_utime);
  const double moved = u.T_refcam_curcam.translation().norm();
  const double noise = std::sqrt(std::max(0.0, u.covariance.topLeftCorner<3, 3>().trace()));
  if (moved > options_.max_still_vo_speed * dt && moved > 3.0 * noise)
    last_vo_motion_utime_ = std::max(last_vo_motion_utime_, u.utime);
}

std::optional<InitialState> Initializer::add(const ImuSample& sample) {
  if (first_utime_ < 0) first_utime_ = sample.utime;
  window_.push_back(sample);
  const double span = 1e-6 * static_cast<double>(window_.back().utime - window_.front().utime);
  if (span < options_.duration_s) return std::nullopt;

  Eigen::Vector3d mean_w = Eigen::Vector3d::Zero(), mean_a = Eigen::Vector3d::Zero();
  for (const auto& s : window_) {
    mean_w += s.gyro;
    mean_a += s.accel;
  }
  const double n = static_cast<double>(window_.size());
  mean_w /= n;
  mean_a /= n;
  double var_w = 0.0, var_a = 0.0;
  for (const auto& s : window_) {
    var_w += (s.gyro - mean_w).squaredNorm();
    var_a += (s.accel - mean_a).squaredNorm();
  }
  const bool still = std::sqrt(var_w / n) <= options_.max_gyro_std &&
                     std::sqrt(var_a / n) <= options_.max_accel_std &&
                     mean_w.norm() <= options_.max_gyro_mean &&
                     std::abs(mean_a.norm() - gravity_) < 0.1 * gravity_ &&
                     last_vo_motion_utime_ < window_.front().utime;
  std::optional<InitialState> init;
  if (still) {
    init = still_start(mean_w, mean_a);
  } else {
    ++restarts_;
    const double waited = 1e-6 * static_cast<double>(sample.utime - first_utime_);
    if (options_.moving_start_after_s > 0.0 && waited >= options_.moving_start_after_s)
      init = moving_start();
  }
  if (init) {
    reset();
  } else {
    window_.erase(window_.begin(), window_.end() - 1);  // the next window starts from the newest
  }
  return init;
}

InitialState Initializer::still_start(const Eigen::Vector3d& mean_w,
                                      const Eigen::Vector3d& mean_a) const {
  InitialState init;
  init.last = window_.back();
  NavState& x = init.nav;
  x.p_world_body = options_.position;
  x.R_world_body = attitude_from_gravity(mean_a, options_.yaw);
  x.gyro_bias = mean_w;
  // At rest the reading is R^T (0, 0, g) + b_a: only the part along gravity is observable.
  x.accel_bias = (mean_a.norm() - gravity_) * mean_a.normalized();
  init.P = start_covariance(x.R_world_body, options_, options_.sigma_velocity, options_.sigma_tilt,
                            options_.sigma_gyro_bias);
  return init;
}

InitialState Initializer::moving_start() const {
  InitialState init;
  init.last = window_.back();
  init.moving = true;
  NavState& x = init.nav;
  x.p_world_body = options_.position;
  x.R_world_body = attitude_from_gravity(mean_specific_force_in_last_frame(window_), options_.yaw);
  // Velocity and biases zero: unknown, and the covariance below says how unknown.
  init.P = start_covariance(x.R_world_body, options_, options_.moving_sigma_velocity,
                            options_.moving_sigma_tilt, options_.moving_sigma_gyro_bias);
  return init;
}

}  // namespace kestrel::estimator
