#include "estimator/eval/synthetic_vo.h"

#include "common/geometry/se3.h"

namespace kestrel::estimator {

SyntheticVo::SyntheticVo(const SyntheticVoOptions& options, uint64_t seed)
    : options_(options), rng_(seed) {}

VoUpdate SyntheticVo::next(int64_t utime, const Eigen::Isometry3d& T_world_body) {
  const Eigen::Isometry3d T_world_cam = T_world_body * options_.T_body_camera;
  VoUpdate u;
  u.utime = utime;
  u.T_body_camera = options_.T_body_camera;
  if (!has_keyframe_) {
    has_keyframe_ = true;
    keyframe_utime_ = utime;
    T_world_keycam_ = T_world_cam;
    return u;  // no reference yet: not ok
  }
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  u.reference_utime = keyframe_utime_;
  const Eigen::Isometry3d truth = T_world_keycam_.inverse() * T_world_cam;
  if (options_.blind && options_.blind(utime)) return u;  // not ok, keyframe kept
  if (truth.translation().norm() > options_.max_match_distance_m ||
      Eigen::AngleAxisd(truth.linear()).angle() > options_.max_match_angle_rad) {
    keyframe_utime_ = utime;  // nothing in common with the keyframe: restart from here
    T_world_keycam_ = T_world_cam;
    return u;
  }
  if (uniform(rng_) >= options_.failure_probability) {
    Vector6d noise;
    for (int i = 0; i < 6; ++i) noise[i] = options_.sigma[i] * normal(rng_);
    u.ok = true;
    u.T_refcam_curcam = se3::boxplus(truth, noise);
    u.covariance = options_.sigma.array().square().matrix().asDiagonal();
  }
  if (truth.translation().norm() > options_.keyframe_distance_m ||
      Eigen::AngleAxisd(truth.linear()).angle() > options_.keyframe_angle_rad) {
    keyframe_utime_ = utime;
    T_world_keycam_ = T_world_cam;
  }
  return u;
}

}  // namespace kestrel::estimator
