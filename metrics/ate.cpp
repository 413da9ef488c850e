#include "metrics/ate.h"

namespace kestrel::metrics {

AteResult compute_ate(const Association& association, bool align) {
  AteResult result;
  Eigen::Matrix3Xd p_est(3, static_cast<Eigen::Index>(association.scored));
  Eigen::Matrix3Xd p_gt(3, p_est.cols());
  Eigen::Index n = 0;
  for (const FramePoses& f : association.frames) {
    if (!f.scored()) continue;
    p_est.col(n) = f.T_world_est->translation();
    p_gt.col(n) = f.T_world_gt->translation();
    result.utimes.push_back(f.utime);
    ++n;
  }
  if (align && n > 0) result.alignment = align_positions(p_est, p_gt);
  const Eigen::Isometry3d& T_gt_est = result.alignment.T_gt_est;
  result.errors_m.reserve(static_cast<size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i)
    result.errors_m.push_back((p_gt.col(i) - T_gt_est * Eigen::Vector3d(p_est.col(i))).norm());
  result.error_m = summarize(result.errors_m);
  return result;
}

}  // namespace kestrel::metrics
