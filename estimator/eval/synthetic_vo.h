#pragma once
// A visual-odometry stand-in with known noise, for Monte-Carlo consistency runs: from true
// body poses it produces what the VO publishes (T_refcam_curcam against a keyframe, with a
// covariance), perturbed by exactly that covariance. A frame becomes the new keyframe once
// the camera has moved more than a distance or angle from the current one, as the real VO
// does when it runs out of overlap. Reproducible: all randomness comes from the seed.

#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <random>

#include "common/numbers.h"
#include "estimator/estimator.h"

namespace kestrel::estimator {

struct SyntheticVoOptions {
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
  /// Noise standard deviations of [dp (reference camera, m); dtheta (current camera, rad)].
  Eigen::Matrix<double, 6, 1> sigma =
      (Eigen::Matrix<double, 6, 1>() << 0.004, 0.004, 0.006, 0.003, 0.003, 0.002).finished();
  double keyframe_distance_m = 0.25;
  double keyframe_angle_rad = 10.0 * kPi / 180.0;
  double failure_probability = 0.0;  ///< per frame: a failed update, as the VO reports it
  /// Share of the noise (of sigma^2) that is the keyframe's own error: drawn once when a frame
  /// becomes the keyframe and common to every update against it, as the real VO's keyframe
  /// features and depths are. The reported covariance stays sigma^2 (the update's whole noise).
  /// 0.4: kestrel-vo's share between updates one frame apart on the simulator's stata flights
  /// (`kestrel fit-vo-noise`), the estimator's default.
  double keyframe_share = 0.4;
  /// Frames for which this returns true see nothing to track (a blank wall): failed updates
  /// that keep the keyframe, as the real VO keeps it. The first frame that sees again is
  /// matched against that keyframe if the camera is still within max_match_distance_m and
  /// max_match_angle_rad of it; otherwise it fails and becomes the new keyframe (a restart).
  std::function<bool(int64_t utime)> blind;
  double max_match_distance_m = 1.0;
  double max_match_angle_rad = 30.0 * kPi / 180.0;
};

class SyntheticVo {
 public:
  SyntheticVo(const SyntheticVoOptions& options, uint64_t seed);
  /// The update for the frame at `utime` whose true body pose is T_world_body.
  VoUpdate next(int64_t utime, const Eigen::Isometry3d& T_world_body);
  const SyntheticVoOptions& options() const { return options_; }

 private:
  SyntheticVoOptions options_;
  std::mt19937_64 rng_;
  bool has_keyframe_ = false;
  int64_t keyframe_utime_ = 0;
  Eigen::Isometry3d T_world_keycam_ = Eigen::Isometry3d::Identity();
  Vector6d keyframe_error_ = Vector6d::Zero();

  void set_keyframe(int64_t utime, const Eigen::Isometry3d& T_world_cam);
};

}  // namespace kestrel::estimator
