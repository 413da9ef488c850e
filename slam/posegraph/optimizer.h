#pragma once
// Exact sparse non-linear least squares on a pose graph: Levenberg-Marquardt with exact
// Jacobians (spaces.h) and CHOLMOD (block_system.h), started from the chordal estimate
// (chordal_init.h), with geodesic acceleration and, on large graphs, inexact steps that reuse
// the last factorisation as the preconditioner of conjugate gradients. A robust kernel, when
// chosen, weighs the loop closures.
//
// Guarantees: every accepted step lowers the cost sum rho(e^T Omega e) (plain chi2 without a
// kernel), so the result is never worse than the start; the chordal start replaces the given
// poses only if it costs less; the fixed vertices keep their poses exactly. A component of the
// graph that reaches no fixed vertex (pose_graph.h, unanchored_components) is held at its first
// vertex's given pose for the solve and reported (OptimizerSummary::anchored_components): its
// place is not observable, only its shape, and without an anchor its singular equations left
// the damped steps short of the optimum (62 % above it in issue 38's probe). The graph's
// fixed flags are as given afterwards. The solution method is explained in slam/README.md
// ("Pose-graph optimiser").

#include <functional>
#include <vector>

#include "slam/posegraph/pose_graph.h"
#include "slam/posegraph/robust_kernel.h"

namespace kestrel::slam {

/// What one step did, for diagnostics (OptimizerOptions::on_step).
struct StepLog {
  int iteration = 0;
  double cost = 0.0;            ///< before the step
  double new_cost = 0.0;        ///< at the candidate
  double predicted = 0.0;       ///< decrease the Gauss-Newton model predicted
  double lambda = 0.0;          ///< damping used
  double step_norm = 0.0;
  int cg_iterations = 0;        ///< 0 when the step came from a fresh factorisation
  bool factorized = false;
  bool accelerated = false;     ///< geodesic acceleration applied
  bool accepted = false;
};

struct OptimizerOptions {
  int max_iterations = 100;
  /// Start from the chordal estimate (when it costs less than the given poses).
  bool chordal_initialization = true;
  /// Stop when a step lowers the cost by less than this fraction of it (Ceres: 1e-6).
  double function_tolerance = 1e-9;
  /// Stop when the largest gradient component is below this.
  double gradient_tolerance = 1e-10;
  /// Stop when the largest step component is below this (metres, radians).
  double parameter_tolerance = 1e-10;
  /// Initial damping, relative to the diagonal of H (Marquardt scaling). From the chordal start
  /// Gauss-Newton steps are almost always accepted; more damping than this slows the soft
  /// modes of large graphs (parking-garage: 6 iterations at 1e-6, 3 at 1e-12).
  double initial_lambda = 1e-12;
  /// Correct each step for the curvature of the residuals along it (Transtrum & Sethna 2012).
  bool geodesic_acceleration = true;
  /// Take steps by conjugate gradients preconditioned with the last factorisation while that
  /// is cheaper than factorising again (large graphs with much fill-in).
  bool reuse_factorization = true;
  /// Applied to loop-closure edges only.
  RobustKernel kernel;
  /// Called after every step tried (may be empty).
  std::function<void(const StepLog&)> on_step;
};

enum class StopReason { kFunctionTolerance, kGradientTolerance, kParameterTolerance,
                        kMaxIterations, kNoProgress, kNothingToDo };
const char* stop_reason_name(StopReason reason);

/// A component held at one of its vertices because nothing anchored it.
struct AnchoredComponent {
  int vertex = 0;  ///< index of the vertex held (the component's lowest)
  int size = 0;    ///< vertices in the component
};

struct OptimizerSummary {
  double initial_chi2 = 0.0;      ///< at the poses given
  double start_chi2 = 0.0;        ///< where the iterations began (after initialisation)
  double final_chi2 = 0.0;        ///< sum e^T Omega e at the result
  double final_cost = 0.0;        ///< sum rho(e^T Omega e), what was minimised
  bool used_chordal = false;      ///< the iterations began from the chordal estimate
  int iterations = 0;             ///< steps tried (accepted or not)
  int accepted = 0;               ///< steps that lowered the cost
  int factorizations = 0;         ///< numeric Cholesky factorisations
  int cg_iterations = 0;          ///< conjugate-gradient iterations of the inexact steps
  int downweighted_edges = 0;     ///< loop closures whose final kernel weight is below 0.5
  std::vector<AnchoredComponent> anchored_components;  ///< empty for a connected graph
  StopReason stop = StopReason::kNothingToDo;
};

/// Optimises the free poses of `graph` in place. Throws std::invalid_argument for a graph that
/// breaks the invariants of pose_graph.h.
template <class Space>
OptimizerSummary optimize(PoseGraph<Space>& graph, const OptimizerOptions& options = {});

/// sum rho(e^T Omega e) with `kernel` on loop closures: the cost optimize() lowers.
template <class Space>
double robust_cost(const PoseGraph<Space>& graph, const RobustKernel& kernel);

}  // namespace kestrel::slam
