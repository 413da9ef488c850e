#include "slam/backend/loop_consistency.h"

#include <algorithm>
#include <cmath>

#include "common/geometry/se3.h"

namespace kestrel::slam {

LoopConsistency check_loop_against_odometry(const PoseGraph3d& graph, int from, int to,
                                            const Eigen::Isometry3d& T_from_to,
                                            const LoopConsistencyOptions& options,
                                            const std::vector<Matrix6d>* odometry_information,
                                            const OdometryBeyondChain* beyond) {
  LoopConsistency c;
  const Eigen::Isometry3d estimate = graph.poses[static_cast<size_t>(from)].inverse() * graph.poses[static_cast<size_t>(to)];
  c.translation_m = se3::translation_distance(estimate, T_from_to);
  c.rotation_rad = se3::rotation_distance(estimate, T_from_to);
  double var_t = 0.0, var_r = 0.0, path_m = 0.0;
  // Covariance of the error: sigma_t^2 for translation, sigma_r^2 / 4 for vec(q) (= phi / 2);
  // the largest variance per block (the constant model is isotropic, a reported one need not be).
  const auto add = [&](const Matrix6d& information, const Eigen::Isometry3d& motion) {
    const Matrix6d cov = information.inverse();
    var_t += cov.diagonal().head<3>().maxCoeff();
    var_r += 4.0 * cov.diagonal().tail<3>().maxCoeff();
    path_m += motion.translation().norm();
  };
  const int lo = std::min(from, to), hi = std::max(from, to);
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const auto& e = graph.edges[k];
    if (e.kind != EdgeKind::kOdometry || std::min(e.from, e.to) < lo || std::max(e.from, e.to) > hi) continue;
    const bool given = odometry_information != nullptr && k < odometry_information->size();
    add(given ? (*odometry_information)[k] : e.information, e.measurement);
  }
  if (beyond != nullptr) add(beyond->information, beyond->motion);
  const double sigma_r = std::sqrt(var_r);
  const double sigma_t = std::sqrt(var_t + sigma_r * path_m * sigma_r * path_m);
  c.allowed_translation_m = std::max(options.min_translation_m, options.sigmas * sigma_t);
  c.allowed_rotation_rad = std::max(options.min_rotation_rad, options.sigmas * sigma_r);
  c.consistent = options.sigmas <= 0.0 ||
                 (c.translation_m <= c.allowed_translation_m && c.rotation_rad <= c.allowed_rotation_rad);
  return c;
}

}  // namespace kestrel::slam
