#pragma once
// The reference the SLAM optimiser is measured against (tests and benchmarks only): Ceres's
// Levenberg-Marquardt with default options on the same pose graph, as BASELINES.md ran it —
// sparse normal Cholesky (SuiteSparse), one thread, at most 100 iterations, the first pose
// fixed, residuals S e with S^T S = Omega, g2o's error convention, automatic derivatives;
// SE(3) orientations as unit quaternions on Ceres's quaternion manifold.

#include "slam/posegraph/pose_graph.h"

namespace kestrel::slam::test {

struct CeresResult {
  double final_chi2 = 0.0;
  int iterations = 0;  ///< Ceres's iteration count (successful and unsuccessful steps)
  double solve_seconds = 0.0;  ///< processor time of ceres::Solve alone (set-up excluded)
  bool converged = false;
};

/// Optimises `graph` in place with Ceres.
CeresResult ceres_optimize(PoseGraph2d& graph, int max_iterations = 100);
CeresResult ceres_optimize(PoseGraph3d& graph, int max_iterations = 100);

}  // namespace kestrel::slam::test
