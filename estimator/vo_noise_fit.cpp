#include "estimator/vo_noise_fit.h"

#include <Eigen/Cholesky>
#include <map>
#include <vector>

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
// E|w|^2 = 6): E[w_i . w_j] = 6 s for i != j, s the common share. The ratio of the pairs'
// summed products to their summed mean squares estimates s, over all pairs and by lag. The
// errors' mean is removed first (a bias is not a keyframe's). The same ratio for consecutive
// updates either side of a re-key is the check on that reading: the new keyframe is the frame
// of the update before, whose own error then enters the next update as its keyframe's with the
// opposite sign, so it is negative where the keyframe's part is real; error that drifts slowly
// (a timing offset, the truth's own) would make it positive instead.
template <typename UsedUpdates>
void fit_keyframe_share(const UsedUpdates& usable, VoNoiseFit& fit) {
  std::map<int64_t, std::vector<Vector6d>> groups;  // whitened errors by keyframe, in order
  double sum_sq = 0.0, across_common = 0.0, across_total = 0.0;
  int64_t whitened = 0;
  Vector6d previous = Vector6d::Zero();
  int64_t previous_reference = 0;
  bool has_previous = false;
  for (const auto& x : usable) {
    Vector6d w;
    const Vector6d e = x.error - fit.mean;
    const Eigen::LLT<Matrix6d> llt(x.update->covariance);
    if (llt.info() == Eigen::Success && x.update->covariance.diagonal().minCoeff() > 0.0) {
      w = llt.matrixL().solve(e);
      sum_sq += w.squaredNorm();
      ++whitened;
    } else {
      w = e.cwiseQuotient(fit.sigma.cwiseMax(1e-12));
    }
    groups[x.update->reference_utime].push_back(w);
    if (has_previous && previous_reference != x.update->reference_utime) {
      across_common += previous.dot(w);
      across_total += 0.5 * (previous.squaredNorm() + w.squaredNorm());
      ++fit.rekey_pairs;
    }
    previous = w;
    previous_reference = x.update->reference_utime;
    has_previous = true;
  }
  fit.reported_nees = whitened > 0 ? sum_sq / (6.0 * static_cast<double>(whitened)) : 0.0;
  fit.share_across_rekey = across_total > 0.0 ? across_common / across_total : 0.0;
  const size_t buckets = fit.share_by_lag.size();
  std::vector<double> common(buckets, 0.0), total(buckets, 0.0);
  double all_common = 0.0, all_total = 0.0;
  for (const auto& [reference, g] : groups) {
    if (g.size() < 2) continue;
    ++fit.keyframes_with_pairs;
    for (size_t i = 0; i < g.size(); ++i) {
      for (size_t j = i + 1; j < g.size(); ++j) {
        const double product = g[i].dot(g[j]);
        const double square = 0.5 * (g[i].squaredNorm() + g[j].squaredNorm());
        all_common += product;
        all_total += square;
        size_t b = 0;  // lag 1, 2-3, 4-7, ...: bucket floor(log2(lag)), the last open
        for (size_t lag = j - i; lag > 1 && b + 1 < buckets; lag >>= 1) ++b;
        common[b] += product;
        total[b] += square;
        ++fit.share_by_lag[b].pairs;
      }
    }
  }
  fit.keyframe_share = all_total > 0.0 ? all_common / all_total : 0.0;
  for (size_t b = 0; b < buckets; ++b)
    fit.share_by_lag[b].share = total[b] > 0.0 ? common[b] / total[b] : 0.0;
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
