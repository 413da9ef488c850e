#pragma once
// A loop closure against the odometry between its two keyframes: when the graph's estimate is
// trustworthy (no unresolved odometry break), a verified loop whose relative pose disagrees
// with the estimate by more than the odometry chain between them can have drifted is
// perceptual aliasing (e.g. a periodic floor texture matched one period off), not a revisit.
//
// The bound is conservative: the chain's accumulated uncertainty, sigma_t^2 = sum of the
// odometry edges' translation variances + (sigma_r * path length)^2 with sigma_r^2 the sum of
// their rotation variances, ignoring earlier loop closures (which only make the estimate
// better). Over a long loop the bound is metres, so only short-range aliasing is caught.

#include <Eigen/Geometry>
#include <vector>

#include "common/geometry/se3.h"
#include "slam/posegraph/pose_graph.h"

namespace kestrel::slam {

struct LoopConsistencyOptions {
  double sigmas = 3.0;              ///< allowed discrepancy in chain sigmas (<= 0: no check)
  double min_translation_m = 0.1;   ///< never stricter than this...
  double min_rotation_rad = 0.05;   ///< ...or this
};

struct LoopConsistency {
  bool consistent = true;
  double translation_m = 0.0;       ///< |discrepancy| of the loop against the estimate
  double rotation_rad = 0.0;
  double allowed_translation_m = 0.0;
  double allowed_rotation_rad = 0.0;
};

/// An odometry measurement the loop was measured through that is no edge of the graph: the
/// motion from `to` to a frame that a loop closed without a keyframe located (Slam), and its
/// information (the graph's error convention).
struct OdometryBeyondChain {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Identity();
};

/// Compares the loop measurement T_from_to with graph.poses[from]^-1 poses[to] (either vertex
/// the older), allowing for the odometry edges (kind kOdometry) between the two vertices: their
/// information in the graph, or `odometry_information[e]` for edge e when given (one per edge;
/// the back-end passes its constant noise model there, so that the gate stays as conservative as
/// it was when the graph's odometry edges take the VO's own, tighter covariance); and for
/// `beyond`, when given, as one more edge of the chain.
LoopConsistency check_loop_against_odometry(const PoseGraph3d& graph, int from, int to,
                                            const Eigen::Isometry3d& T_from_to,
                                            const LoopConsistencyOptions& options,
                                            const std::vector<Matrix6d>* odometry_information = nullptr,
                                            const OdometryBeyondChain* beyond = nullptr);

}  // namespace kestrel::slam
