#include "slam/posegraph/optimizer.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "slam/posegraph/chordal_init.h"
#include "slam/posegraph/gauge_preconditioner.h"
#include "slam/posegraph/normal_equations.h"
#include "slam/posegraph/pcg.h"

namespace kestrel::slam {
namespace {

constexpr double kMinRelativeDecrease = 1e-3;  // a step must achieve this share of its model
constexpr double kMaxLambda = 1e20;
constexpr double kAccelerationStep = 0.1;      // finite-difference step of r_vv (Transtrum)
constexpr double kMaxAccelerationRatio = 0.75; // 2|a| / |v| at most, else no acceleration
constexpr double kCgTolerance = 0.1;           // relative residual of an inexact step
constexpr int kMaxCgIterations = 20;

// Conjugate-gradient iterations that cost about half a factorisation. Measured with CHOLMOD
// on the benchmark graphs (slam/README.md): a factorisation takes about 0.05 ms per Mflop
// plus 19 ms per million non-zeros of the factor, a solve 2 ms per million non-zeros, an
// iteration a solve and a product with H (another 20 %).
int cg_budget(double flops, double nonzeros) {
  if (!(nonzeros > 0.0)) return 0;
  const double factor = 0.05 * flops + 19.0 * nonzeros;
  const double iteration = 2.4 * nonzeros;
  return std::clamp(static_cast<int>(0.5 * factor / iteration), 0, kMaxCgIterations);
}

}  // namespace

const char* stop_reason_name(StopReason reason) {
  switch (reason) {
    case StopReason::kFunctionTolerance: return "function tolerance";
    case StopReason::kGradientTolerance: return "gradient tolerance";
    case StopReason::kParameterTolerance: return "parameter tolerance";
    case StopReason::kMaxIterations: return "maximum iterations";
    case StopReason::kNoProgress: return "no progress (damping at its limit)";
    case StopReason::kNothingToDo: return "nothing to optimise";
  }
  return "?";
}

template <class Space>
double robust_cost(const PoseGraph<Space>& graph, const RobustKernel& kernel) {
  double sum = 0.0;
  for (const auto& edge : graph.edges) {
    const double s = edge_chi2(graph, edge);
    sum += edge.kind == EdgeKind::kLoopClosure ? kernel.cost(s) : s;
  }
  return sum;
}

template <class Space>
OptimizerSummary optimize(PoseGraph<Space>& graph, const OptimizerOptions& options) {
  using Poses = typename NormalEquations<Space>::Poses;
  check_graph(graph);
  OptimizerSummary summary;
  summary.initial_chi2 = summary.start_chi2 = summary.final_chi2 = chi2(graph);
  summary.final_cost = robust_cost(graph, options.kernel);
  if (graph.edges.empty()) return summary;

  // Each unanchored component is held at its first vertex for the solve (see the header); the
  // given flags come back however this function ends. Marking more than the implicit anchor
  // needs the implicit one marked too, or vertex 0 would lose it.
  class RestoreFixed {
   public:
    explicit RestoreFixed(PoseGraph<Space>& graph) : graph_(graph), given_(graph.fixed) {}
    RestoreFixed(const RestoreFixed&) = delete;
    RestoreFixed& operator=(const RestoreFixed&) = delete;
    ~RestoreFixed() { graph_.fixed = std::move(given_); }

   private:
    PoseGraph<Space>& graph_;
    std::vector<char> given_;
  };
  const std::vector<std::vector<int>> unanchored = unanchored_components(graph);
  std::optional<RestoreFixed> restore;
  if (!unanchored.empty()) {
    restore.emplace(graph);
    if (std::find(graph.fixed.begin(), graph.fixed.end(), 1) == graph.fixed.end()) graph.fixed[0] = 1;
    for (const std::vector<int>& component : unanchored) {
      graph.fixed[component.front()] = 1;
      summary.anchored_components.push_back({component.front(), static_cast<int>(component.size())});
    }
  }

  std::vector<std::pair<int, int>> pairs;
  pairs.reserve(graph.edges.size());
  for (const auto& e : graph.edges) pairs.emplace_back(e.from, e.to);
  const std::vector<int> order = order_blocks(graph.num_vertices(), pairs);
  NormalEquations<Space> equations(graph, options.kernel, order);
  if (equations.num_unknowns() == 0) return summary;

  Poses x = graph.poses;
  double cost = equations.cost(x);
  if (options.chordal_initialization) {
    PoseGraph<Space> chordal = graph;
    if (chordal_initialize(chordal, order)) {
      const double chordal_cost = equations.cost(chordal.poses);
      if (chordal_cost < cost) {
        x = std::move(chordal.poses);
        summary.used_chordal = true;
      }
    }
  }
  summary.start_chi2 = equations.cost(x, false);
  cost = equations.linearize(x);

  auto& system = equations.system();
  const int budget = options.reuse_factorization
                         ? cg_budget(system.factor_flops(), system.factor_nonzeros())
                         : 0;
  double lambda = options.initial_lambda;
  double nu = 2.0;
  bool have_factor = false;   // a factorisation exists (possibly of an earlier linearisation)
  bool must_factor = true;    // the next step needs a fresh one
  int cg_failures = 0;        // in a row: each halves the iterations allowed
  GaugePreconditioner preconditioner;
  const auto solve_factored = [&](const Eigen::VectorXd& r) { return system.solve_factored(r); };
  Poses candidate;
  summary.stop = StopReason::kMaxIterations;
  while (summary.iterations < options.max_iterations) {
    if (system.rhs().template lpNorm<Eigen::Infinity>() <= options.gradient_tolerance) {
      summary.stop = StopReason::kGradientTolerance;
      break;
    }
    if (lambda > kMaxLambda) {
      summary.stop = StopReason::kNoProgress;
      break;
    }
    ++summary.iterations;

    StepLog log;
    log.iteration = summary.iterations;
    log.cost = cost;
    log.lambda = lambda;
    Eigen::VectorXd dx;
    bool solved = false;
    const int allowed = cg_failures < 8 ? budget >> cg_failures : 0;
    if (!must_factor && have_factor && allowed > 0) {
      // The old factorisation with the rigid motions of its poses projected out
      // (gauge_preconditioner.h): without that projection the steps after the first on
      // sphere2500 ran out of iterations and each cost a factorisation (4 instead of 1).
      const PcgResult cg = pcg(
          [&](const Eigen::VectorXd& v) { return system.multiply(v, lambda); },
          [&](const Eigen::VectorXd& r) { return preconditioner.apply(solve_factored, r); },
          system.rhs(), dx, allowed, kCgTolerance);
      summary.cg_iterations += cg.iterations;
      log.cg_iterations = cg.iterations;
      solved = cg.converged && dx.allFinite();
      if (solved) equations.remove_rigid_motion(x, dx);
      cg_failures = solved ? 0 : cg_failures + 1;
    }
    if (!solved) {
      log.factorized = true;
      ++summary.factorizations;
      have_factor = system.factorize(lambda);
      if (have_factor && budget > 0) preconditioner.set_gauge(equations.rigid_motions(x));
      if (!have_factor) {
        lambda *= nu;
        nu *= 2.0;
        continue;
      }
      dx = system.solve();
      if (!dx.allFinite()) {
        have_factor = false;
        lambda *= nu;
        nu *= 2.0;
        continue;
      }
    }
    must_factor = false;
    // Decrease predicted by the Gauss-Newton model for the step dx: 2 b'dx - dx' H dx (b = -g).
    // The acceleration below is judged by the cost it reaches, not by this model.
    const double predicted = 2.0 * system.rhs().dot(dx) - dx.dot(system.multiply(dx));
    // Not after an inexact step: its acceleration would be solved with the old factorisation
    // at the old damping, and on sphere2500 it failed the ratio test on every such step (a
    // solve and a second-derivative evaluation, ~4 ms each time, for nothing).
    if (options.geodesic_acceleration && !solved) {
      const Eigen::VectorXd a =
          system.solve_factored(equations.acceleration_rhs(x, dx, kAccelerationStep));
      if (a.allFinite() && 2.0 * a.norm() <= kMaxAccelerationRatio * dx.norm()) {
        dx += 0.5 * a;
        log.accelerated = true;
      }
    }
    if (dx.template lpNorm<Eigen::Infinity>() <= options.parameter_tolerance) {
      summary.stop = StopReason::kParameterTolerance;
      break;
    }

    equations.retract(x, dx, candidate);
    const double new_cost = equations.cost(candidate);
    const double rho = predicted > 0.0 ? (cost - new_cost) / predicted : -1.0;
    log.new_cost = new_cost;
    log.predicted = predicted;
    log.step_norm = dx.norm();
    log.accepted = new_cost < cost && rho > kMinRelativeDecrease;
    if (options.on_step) options.on_step(log);
    if (log.accepted) {
      const double decrease = cost - new_cost;
      x.swap(candidate);
      ++summary.accepted;
      lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      nu = 2.0;
      // Judged on the candidate's cost, before linearising: the last linearisation of a solve
      // was never used (sphere2500: one of five, ~2 ms).
      if (decrease <= options.function_tolerance * (new_cost + decrease)) {
        summary.stop = StopReason::kFunctionTolerance;
        break;
      }
      cost = equations.linearize(x);
    } else {
      lambda *= nu;
      nu *= 2.0;
      must_factor = true;
    }
  }
  equations.anchor(x);
  summary.downweighted_edges = equations.downweighted(x);
  graph.poses = std::move(x);
  summary.final_chi2 = chi2(graph);
  summary.final_cost = robust_cost(graph, options.kernel);
  return summary;
}

template OptimizerSummary optimize(PoseGraph<Se2>&, const OptimizerOptions&);
template OptimizerSummary optimize(PoseGraph<Se3>&, const OptimizerOptions&);
template double robust_cost(const PoseGraph<Se2>&, const RobustKernel&);
template double robust_cost(const PoseGraph<Se3>&, const RobustKernel&);

}  // namespace kestrel::slam
