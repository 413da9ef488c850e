#include "slam/backend/loop_consistency.h"

#include <algorithm>
#include <cmath>

#include "common/geometry/se3.h"

namespace kestrel::slam {

LoopConsistency check_loop_against_odometry(const PoseGraph3d& graph, int from, int to,
                                            const Eigen::Isometry3d& T_from_to,
                                            const LoopConsistencyOptions& options) {
  LoopConsistency c;
  const Eigen::Isometry3d estimate = graph.poses[static_cast<size_t>(from)].inverse() * graph.poses[static_cast<size_t>(to)];
  c.translation_m = se3::translation_distance(estimate, T_from_to);
  c.rotation_rad = se3::rotation_distance(estimate, T_from_to);
  double var_t = 0.0, var_r = 0.0, path_m = 0.0;
  const int lo = std::min(from, to), hi = std::max(from, to);
  for (const auto& e : graph.edges) {
    if (e.kind != EdgeKind::kOdometry || std::min(e.from, e.to) < lo || std::max(e.from, e.to) > hi) continue;
    // Information diag: 1/sigma_t^2 for translation, 4/sigma_r^2 for vec(q) (= phi / 2).
    var_t += 1.0 / e.information(0, 0);
    var_r += 4.0 / e.information(3, 3);
    path_m += e.measurement.translation().norm();
  }
  const double sigma_r = std::sqrt(var_r);
  const double sigma_t = std::sqrt(var_t + sigma_r * path_m * sigma_r * path_m);
  c.allowed_translation_m = std::max(options.min_translation_m, options.sigmas * sigma_t);
  c.allowed_rotation_rad = std::max(options.min_rotation_rad, options.sigmas * sigma_r);
  c.consistent = options.sigmas <= 0.0 ||
                 (c.translation_m <= c.allowed_translation_m && c.rotation_rad <= c.allowed_rotation_rad);
  return c;
}

}  // namespace kestrel::slam
