#include "estimator/vo_noise_fit.h"

#include "common/error.h"
#include "common/geometry/so3.h"

namespace kestrel::estimator {

Vector6d vo_error(const VoUpdate& u, const Eigen::Isometry3d& T_world_refbody,
                  const Eigen::Isometry3d& T_world_curbody) {
  const Eigen::Isometry3d T_true =
      (T_world_refbody * u.T_body_camera).inverse() * (T_world_curbody * u.T_body_camera);
  Vector6d e;
  e.head<3>() = T_true.translation() - u.T_refcam_curcam.translation();
  e.tail<3>() = so3::log(u.T_refcam_curcam.linear().transpose() * T_true.linear());
  return e;
}

VoNoiseFit fit_vo_noise(const std::vector<VoUpdate>& updates, const Trajectory& truth,
                        int64_t max_gap_us) {
  VoNoiseFit fit;
  Vector6d sum = Vector6d::Zero(), sum_sq = Vector6d::Zero();
  double interval_sum = 0.0;
  for (const VoUpdate& u : updates) {
    if (!u.ok) {
      ++fit.failed;
      continue;
    }
    const auto ref = truth.at(u.reference_utime, max_gap_us);
    const auto cur = truth.at(u.utime, max_gap_us);
    if (!ref || !cur) {
      ++fit.uncovered;
      continue;
    }
    const Vector6d e = vo_error(u, *ref, *cur);
    sum += e;
    sum_sq += e.cwiseAbs2();
    interval_sum += 1e-6 * static_cast<double>(u.utime - u.reference_utime);
    ++fit.used;
  }
  if (fit.used == 0)
    throw InputError("fit-vo-noise: no usable VO update (" + std::to_string(updates.size()) +
                     " updates, " + std::to_string(fit.failed) + " failed, " +
                     std::to_string(fit.uncovered) + " outside the ground truth)");
  const double n = static_cast<double>(fit.used);
  fit.mean = sum / n;
  fit.sigma = (sum_sq / n).cwiseSqrt();
  fit.mean_interval_s = interval_sum / n;
  return fit;
}

}  // namespace kestrel::estimator
