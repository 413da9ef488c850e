#include "estimator/vo_noise_fit.h"

#include <Eigen/Cholesky>
#include <map>

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

namespace {

// With w_i = b + n_i for the updates of one keyframe (b common, n_i own, whitened so that
// E|w|^2 = 6): E[w_i . w_j] = 6 s for i != j, s the common share. Over a keyframe's n updates,
// sum_{i<j} w_i . w_j = (|sum w|^2 - sum |w|^2) / 2 and the matching sum of the pairs' mean
// squares is (n - 1) sum |w|^2 / 2: the ratio of their totals over all keyframes estimates s.
template <typename UsedUpdates>
void fit_keyframe_share(const UsedUpdates& usable, VoNoiseFit& fit) {
  struct Group {
    Vector6d sum = Vector6d::Zero();
    double sum_sq = 0.0;
    int64_t n = 0;
  };
  std::map<int64_t, Group> groups;
  for (const auto& x : usable) {
    Vector6d w;
    const Eigen::LLT<Matrix6d> llt(x.update->covariance);
    if (llt.info() == Eigen::Success && x.update->covariance.diagonal().minCoeff() > 0.0)
      w = llt.matrixL().solve(x.error);
    else
      w = x.error.cwiseQuotient(fit.sigma.cwiseMax(1e-12));
    Group& g = groups[x.update->reference_utime];
    g.sum += w;
    g.sum_sq += w.squaredNorm();
    ++g.n;
  }
  double common = 0.0, total = 0.0;
  for (const auto& [reference, g] : groups) {
    if (g.n < 2) continue;
    common += g.sum.squaredNorm() - g.sum_sq;
    total += static_cast<double>(g.n - 1) * g.sum_sq;
    ++fit.keyframes_with_pairs;
  }
  fit.keyframe_share = total > 0.0 ? common / total : 0.0;
}

}  // namespace

VoNoiseFit fit_vo_noise(const std::vector<VoUpdate>& updates, const Trajectory& truth,
                        int64_t max_gap_us) {
  VoNoiseFit fit;
  Vector6d sum = Vector6d::Zero(), sum_sq = Vector6d::Zero();
  double interval_sum = 0.0;
  struct Used {
    const VoUpdate* update;
    Vector6d error;
  };
  std::vector<Used> usable;
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
    usable.push_back({&u, e});
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
  fit_keyframe_share(usable, fit);
  return fit;
}

}  // namespace kestrel::estimator
