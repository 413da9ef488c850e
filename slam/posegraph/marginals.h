#pragma once
// Marginal covariance of one pose of an optimised pose graph: the block of H^-1 that belongs
// to it, with H the Gauss-Newton information of the free poses given the fixed ones (the
// robust kernel's weights at the current poses included). It says how well the graph pins the
// pose down relative to the anchor: zero for a fixed vertex, growing along odometry away from
// it, shrinking where loop closures tie the pose back.
//
// Coordinates: those of the solver's retraction (spaces.h), for SE(3) d = [rho; phi] with
// X <- (R Exp(phi), t + R rho), both in the pose's own frame; for SE(2) [dx; dy; dtheta] alike.

#include <optional>

#include "slam/posegraph/pose_graph.h"
#include "slam/posegraph/robust_kernel.h"

namespace kestrel::slam {

/// The covariance of vertex `vertex` at the graph's current poses (one sparse factorisation and
/// D solves); nullopt when the information is not positive definite (a pose the edges do not
/// determine). Throws std::invalid_argument for a bad graph or vertex index.
template <class Space>
std::optional<typename Space::Matrix> marginal_covariance(const PoseGraph<Space>& graph, int vertex,
                                                          const RobustKernel& kernel = {});

}  // namespace kestrel::slam
