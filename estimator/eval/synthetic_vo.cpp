#include "estimator/eval/synthetic_vo.h"

#include <cmath>

#include "common/geometry/se3.h"

namespace kestrel::estimator {

SyntheticVo::SyntheticVo(const SyntheticVoOptions& options, uint64_t seed)
    : options_(options), rng_(seed) {}

void SyntheticVo::set_keyframe(int64_t utime, const Eigen::Isometry3d& T_world_cam) {
  keyframe_utime_ = utime;
  T_world_keycam_ = T_world_cam;
  if (options_.keyframe_share <= 0.0) return;  // no draw: the noise stream stays as without
  std::normal_distribution<double> normal(0.0, 1.0);
  const double scale = std::sqrt(options_.keyframe_share);
  for (int i = 0; i < 6; ++i) keyframe_error_[i] = scale * options_.sigma[i] * normal(rng_);
}

VoUpdate SyntheticVo::next(int64_t utime, const Eigen::Isometry3d& T_world_body) {
  const Eigen::Isometry3d T_world_cam = T_world_body * options_.T_body_camera;
  VoUpdate u;
  u.utime = utime;
  u.T_body_camera = options_.T_body_camera;
  if (!has_keyframe_) {
    has_keyframe_ = true;
    set_keyframe(utime, T_world_cam);
    return u;  // no reference yet: not ok
  }
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  u.reference_utime = keyframe_utime_;
  const Eigen::Isometry3d truth = T_world_keycam_.inverse() * T_world_cam;
  if (options_.blind && options_.blind(utime)) return u;  // not ok, keyframe kept
  if (truth.translation().norm() > options_.max_match_distance_m ||
      Eigen::AngleAxisd(truth.linear()).angle() > options_.max_match_angle_rad) {
    set_keyframe(utime, T_world_cam);  // nothing in common with the keyframe: restart from here
    return u;
  }
  if (uniform(rng_) >= options_.failure_probability) {
    const double own = std::sqrt(1.0 - options_.keyframe_share);
    Vector6d noise = keyframe_error_;
    for (int i = 0; i < 6; ++i) noise[i] += own * options_.sigma[i] * normal(rng_);
    u.ok = true;
    u.T_refcam_curcam = se3::boxplus(truth, noise);
    u.covariance = options_.sigma.array().square().matrix().asDiagonal();
  }
  if (truth.translation().norm() > options_.keyframe_distance_m ||
      Eigen::AngleAxisd(truth.linear()).angle() > options_.keyframe_angle_rad) {
    set_keyframe(utime, T_world_cam);
  }
  return u;
}

}  // namespace kestrel::estimator
