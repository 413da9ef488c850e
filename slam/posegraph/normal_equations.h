#pragma once
// The Gauss-Newton normal equations of a pose graph at given poses, with a robust kernel on
// loop closures (iteratively re-weighted: an edge enters with weight rho'(s)), the costs the
// solver compares, and the second directional derivative it uses for geodesic acceleration.
//
// Gauge: when a single vertex is held fixed (the usual anchor), it is optimised too, held only
// by a prior a million times weaker than its edges, and the result is moved back rigidly
// (anchor()) — which leaves every edge error unchanged. Without it the anchor's few edges are
// all that resist a rotation of the whole graph about it: a soft, strongly non-linear mode
// that costs Gauss-Newton many iterations on large graphs (sphere2500: 7 instead of 3).
// With several fixed vertices they are held exactly.

#include <memory>
#include <vector>

#include "slam/posegraph/block_system.h"
#include "slam/posegraph/pose_graph.h"
#include "slam/posegraph/robust_kernel.h"

namespace kestrel::slam {

template <class Space>
class NormalEquations {
 public:
  static constexpr int D = Space::kDim;
  using Pose = typename Space::Pose;
  using Poses = std::vector<Pose>;

  /// `vertex_order`: a fill-reducing order of all vertices (order_blocks()). With
  /// `free_gauge` false a single fixed vertex stays out of the unknowns (the system is then the
  /// information of the others given it: what marginal covariances need).
  NormalEquations(const PoseGraph<Space>& graph, const RobustKernel& kernel,
                  const std::vector<int>& vertex_order, bool free_gauge = true);

  int num_unknowns() const { return num_unknowns_; }
  /// The unknown index of a vertex, or -1 when it is held fixed.
  int unknown_of(int vertex) const { return index_[static_cast<size_t>(vertex)]; }
  BlockSystem<D>& system() { return *system_; }
  const BlockSystem<D>& system() const { return *system_; }

  /// sum rho(s) over edges at `poses` (plain chi2 when `robust` is false).
  double cost(const Poses& poses, bool robust = true) const;
  /// Accumulates H and b = -g at `poses` into system(); returns the robust cost there.
  double linearize(const Poses& poses);
  /// `poses` moved by the step dx (D entries per unknown).
  void retract(const Poses& poses, const Eigen::VectorXd& dx, Poses& out) const;
  /// -J^T W r_vv, with r_vv the second derivative of the edge errors along dx estimated by
  /// finite differences with step h: solving H a = this gives the geodesic acceleration
  /// (Transtrum & Sethna 2012) of the step.
  Eigen::VectorXd acceleration_rhs(const Poses& poses, const Eigen::VectorXd& dx, double h) const;
  /// Takes out of dx the rigid motion of the whole graph that is closest to it (least squares
  /// over the unknowns' local coordinates), when the gauge is free. Only the weak prior holds
  /// that motion, so an inexact (conjugate-gradient) step can carry a large one, which the
  /// pose-by-pose retraction does not apply rigidly: tens of metres on a 1000-pose helix.
  void remove_rigid_motion(const Poses& poses, Eigen::VectorXd& dx) const;
  /// The D rigid motions of the whole graph at `poses` in the unknowns' local coordinates (one
  /// column each), when the gauge is free; no columns otherwise. The preconditioner of the
  /// inexact steps projects them out (gauge_preconditioner.h).
  Eigen::MatrixXd rigid_motions(const Poses& poses) const;
  /// The poses moved rigidly so that the single fixed vertex is back where it was held.
  void anchor(Poses& poses) const;
  /// Loop closures whose kernel weight at `poses` is below one half.
  int downweighted(const Poses& poses) const;

 private:
  double kernel_weight(size_t k, double s) const;
  double kernel_cost(size_t k, double s) const;

  const PoseGraph<Space>& graph_;
  RobustKernel kernel_;
  std::vector<int> index_;  ///< per vertex: unknown index or -1
  int num_unknowns_ = 0;
  int gauge_vertex_ = -1;   ///< the anchor optimised with a weak prior, or -1
  std::vector<int> pair_of_edge_;
  Poses z_inv_;             ///< inverse measurements
  std::unique_ptr<BlockSystem<D>> system_;
};

}  // namespace kestrel::slam
