#include "estimator/initializer.h"

#include <cmath>

namespace kestrel::estimator {

Eigen::Matrix3d attitude_from_gravity(const Eigen::Vector3d& f, double yaw) {
  const double roll = std::atan2(f.y(), f.z());
  const double pitch = std::atan2(-f.x(), std::hypot(f.y(), f.z()));
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

std::optional<InitialState> StaticInitializer::add(const ImuSample& sample) {
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
                     std::abs(mean_a.norm() - gravity_) < 0.1 * gravity_;
  if (!still) {
    // Keep the newest sample: the next window starts from it.
    window_.erase(window_.begin(), window_.end() - 1);
    ++restarts_;
    return std::nullopt;
  }

  InitialState init;
  init.last = window_.back();
  NavState& x = init.nav;
  x.p_world_body = options_.position;
  x.R_world_body = attitude_from_gravity(mean_a, options_.yaw);
  x.gyro_bias = mean_w;
  // At rest the reading is R^T (0, 0, g) + b_a: only the part along gravity is observable.
  x.accel_bias = (mean_a.norm() - gravity_) * mean_a.normalized();
  const auto sq = [](double v) { return v * v; };
  Matrix15d P = Matrix15d::Zero();
  P.block<3, 3>(idx::kP, idx::kP).diagonal().setConstant(sq(options_.sigma_position));
  P.block<3, 3>(idx::kV, idx::kV).diagonal().setConstant(sq(options_.sigma_velocity));
  // Roll and pitch about the body axes; yaw about world z, which in the body frame is R^T e_z.
  const Eigen::Vector3d up_body = x.R_world_body.transpose() * Eigen::Vector3d::UnitZ();
  P.block<3, 3>(idx::kTheta, idx::kTheta) =
      sq(options_.sigma_tilt) * (Eigen::Matrix3d::Identity() - up_body * up_body.transpose()) +
      sq(options_.sigma_yaw) * up_body * up_body.transpose();
  P.block<3, 3>(idx::kBg, idx::kBg).diagonal().setConstant(sq(options_.sigma_gyro_bias));
  P.block<3, 3>(idx::kBa, idx::kBa).diagonal().setConstant(sq(options_.sigma_accel_bias));
  init.P = P;
  window_.clear();
  return init;
}

}  // namespace kestrel::estimator
