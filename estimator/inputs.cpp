#include "estimator/inputs.h"

#include <Eigen/Eigenvalues>
#include <algorithm>

#include "common/error.h"
#include "common/geometry/se3.h"

namespace kestrel::estimator {
namespace {

bool finite_pose(const Eigen::Isometry3d& T) { return se3::is_valid(T, 1e-6); }

bool symmetric_psd(const Matrix6d& C, bool allow_zero) {
  if (!C.allFinite()) return false;
  if ((C - C.transpose()).cwiseAbs().maxCoeff() > 1e-9 * std::max(1.0, C.cwiseAbs().maxCoeff()))
    return false;
  if (C.isZero(0.0)) return allow_zero;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(C, Eigen::EigenvaluesOnly);
  return eig.eigenvalues().minCoeff() > 0.0;
}

}  // namespace

Matrix6d vo_noise(const VoNoiseOptions& options, const VoUpdate& u) {
  if (options.source == VoNoiseOptions::Source::kConstant)
    return options.constant_sigma.array().square().matrix().asDiagonal();
  return options.reported_scale * u.covariance;
}

Matrix6d correction_noise(const EstimatorOptions& options, const PoseCorrection& c) {
  if (!c.covariance.isZero(0.0)) return c.covariance;
  Matrix6d Q = Matrix6d::Zero();
  Q.topLeftCorner<3, 3>().diagonal().setConstant(options.correction_sigma_position * options.correction_sigma_position);
  Q.bottomRightCorner<3, 3>().diagonal().setConstant(options.correction_sigma_rotation * options.correction_sigma_rotation);
  return Q;
}

void validate_imu(const ImuSample& s, const std::string& what) {
  if (!s.gyro.allFinite() || !s.accel.allFinite())
    throw InputError(what + ": non-finite IMU reading at utime " + std::to_string(s.utime));
  if (s.utime < 0) throw InputError(what + ": negative utime " + std::to_string(s.utime));
}

InputFault check_vo(const VoUpdate& u, bool need_covariance, const std::string& what) {
  using Kind = InputFault::Kind;
  if (!u.ok) return {};  // a failure carries nothing to check
  const std::string at = what + ": update at utime " + std::to_string(u.utime);
  if (!finite_pose(u.T_refcam_curcam) || !finite_pose(u.T_body_camera))
    return {Kind::kPose, at + ": non-finite or non-rigid pose"};
  if (u.reference_utime >= u.utime)
    return {Kind::kPose, at + ": reference utime " + std::to_string(u.reference_utime) +
                             " is not before the frame's"};
  if (!symmetric_psd(u.covariance, !need_covariance))
    return {Kind::kCovariance, at + ": covariance is not symmetric positive definite"};
  return {};
}

InputFault check_correction(const PoseCorrection& c, const std::string& what) {
  using Kind = InputFault::Kind;
  const std::string at = what + ": correction at utime " + std::to_string(c.utime);
  if (!finite_pose(c.T_world_body)) return {Kind::kPose, at + ": non-finite or non-rigid pose"};
  if (!symmetric_psd(c.covariance, true))
    return {Kind::kCovariance, at + ": covariance is not symmetric positive definite"};
  return {};
}

void validate_vo(const VoUpdate& u, bool need_covariance, const std::string& what) {
  if (const InputFault f = check_vo(u, need_covariance, what)) throw InputError(f.what);
}

void validate_correction(const PoseCorrection& c, const std::string& what) {
  if (const InputFault f = check_correction(c, what)) throw InputError(f.what);
}

}  // namespace kestrel::estimator
