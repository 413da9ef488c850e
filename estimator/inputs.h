#pragma once
// The inputs of the estimator besides the IMU (imu.h): a visual-odometry result and a SLAM
// correction, and the checks every input passes before the filter sees it (finite values,
// proper rotations, symmetric positive semi-definite covariances).

#include <Eigen/Geometry>
#include <cstdint>
#include <string>

#include "estimator/imu.h"
#include "estimator/measurements.h"
#include "estimator/options.h"

namespace kestrel::estimator {

/// One visual-odometry result (vo_update_t without the diagnostics).
struct VoUpdate {
  int64_t utime = 0;
  int64_t reference_utime = 0;
  bool ok = false;  ///< status OK: the motion below is an estimate
  Eigen::Isometry3d T_refcam_curcam = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Zero();  ///< [dp (reference camera); dtheta (current camera)]
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
};

/// A SLAM correction: the body pose at a past utime.
struct PoseCorrection {
  int64_t utime = 0;
  int64_t revision = 0;  ///< a newer revision replaces an older one for the same utime
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Zero();  ///< [dp (world); dtheta (body)]; zero = unknown
};

/// The noise of a VO update's [dp; dtheta] under `options` (reported or constant).
Matrix6d vo_noise(const VoNoiseOptions& options, const VoUpdate& update);
/// The noise of a correction's [dp; dtheta]: its covariance, or the options' sigmas when it
/// carries none (all zero).
Matrix6d correction_noise(const EstimatorOptions& options, const PoseCorrection& correction);

/// What makes an input unusable, for counting by reason: its pose (non-finite, not rigid, a
/// reference not before its frame) or its covariance (non-finite, not symmetric positive
/// definite). `what` is the one-line reason, naming the stream and the input's utime.
struct InputFault {
  enum class Kind { kNone, kPose, kCovariance };
  Kind kind = Kind::kNone;
  std::string what;
  explicit operator bool() const { return kind != Kind::kNone; }
};
InputFault check_vo(const VoUpdate& update, bool need_covariance, const std::string& what);
InputFault check_correction(const PoseCorrection& correction, const std::string& what);

/// Throws InputError (naming `what`) unless the input is usable: finite values, a proper
/// rotation, a symmetric positive semi-definite covariance (all zero allowed where noted).
void validate_imu(const ImuSample& sample, const std::string& what);
void validate_vo(const VoUpdate& update, bool need_covariance, const std::string& what);
void validate_correction(const PoseCorrection& correction, const std::string& what);

}  // namespace kestrel::estimator
