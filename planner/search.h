#pragma once
// Searches over a Roadmap: PRM's shortest path, and the Belief Roadmap's search (the paper's
// Algorithm 1) with either objective.
//
// BRM labels are (node, Sigma, path); a label never revisits a node on its own path.
//  * kMinGoalUncertainty — the goal's label of least tr(Sigma). Labels are expanded in order of
//    tr(Sigma) (the paper uses FIFO) and skipped once superseded at their node.
//  * kShortestBounded — shortest path with tr(Sigma) < max_trace at every node: labels in order
//    of length; the goal's first is the answer. The bound is checked at nodes, as in the paper,
//    and along edges too when the query gives `edge_peak_trace`.
// Which labels a node keeps (for kShortestBounded a label must also be no longer to beat one):
//  * kTrace — Algorithm 1's rule: a label is dropped when another at its node has a tr(Sigma)
//    no larger (one label per node for kMinGoalUncertainty). A heuristic: the dropped label's
//    Sigma may be smaller in some direction, and a later edge may need exactly that one.
//  * kCovarianceDominance — a label is dropped only when another at its node has a Sigma no
//    larger in any direction (the Loewner order). Every edge's transfer is monotone in that
//    order, so the kept label matches every continuation of the dropped one that it may take;
//    the rule misses the best simple path only when that continuation passes through the kept
//    label's own path (on 10 of 190 random roadmaps in the tests, where kTrace misses 93).
//    Requiring the kept label's path to lie within the dropped one's would make it exact, and
//    exponential on the experiments' every-pair roadmaps. A node keeps many labels: the search
//    costs ~2000x kTrace's there. With dominance_slack s > 0 a newcomer is also dropped when
//    another's Sigma is within (1 + s) of its own; a transfer phi has phi(c Sigma) <= c
//    phi(Sigma) for c >= 1, so that costs at most a factor (1 + s) per edge, and s = 0.01
//    cuts the search ~45x (planner_bench).

#include <functional>
#include <limits>
#include <vector>

#include "planner/roadmap.h"

namespace kestrel::planner {

enum class BrmObjective { kMinGoalUncertainty, kShortestBounded };
enum class BrmPruning { kTrace, kCovarianceDominance };

struct PlanResult {
  bool found = false;
  std::vector<int> nodes;          ///< start ... goal
  std::vector<double> traces;      ///< predicted tr(Sigma) at each node (empty for PRM)
  double length_m = 0.0;
  Mat4 goal_covariance = Mat4::Zero();
  long expansions = 0;             ///< labels expanded
};

/// Dijkstra on edge length.
PlanResult shortest_path(const Roadmap& map, int start, int goal);

/// The slack the tools and the process use with kCovarianceDominance (the library's default
/// is 0): at most 1 % per edge above the zero-slack answer, for ~45x less search.
inline constexpr double kToolsDominanceSlack = 0.01;

struct BrmQuery {
  Mat4 start_covariance = Mat4::Identity();
  BrmObjective objective = BrmObjective::kMinGoalUncertainty;
  BrmPruning pruning = BrmPruning::kTrace;
  double dominance_slack = 0.0;  ///< kCovarianceDominance only; 0 = exact
  double max_trace = std::numeric_limits<double>::infinity();
  /// Unset: max_trace is checked at nodes only (the paper's Algorithm 1). Set: also along
  /// each edge, from -> to entered with `sigma`: it returns the largest tr(Sigma) on the way
  /// (e.g. peak_trace_along with the roadmap's BeliefModel), and a label whose edge peaks at
  /// or over max_trace is dropped. Called only for labels that pass every other test.
  std::function<double(int from, int to, const Mat4& sigma)> edge_peak_trace;
};

PlanResult belief_search(const Roadmap& map, int start, int goal, const BrmQuery& query);

/// tr(Sigma) at each node of `nodes` flown from `start_covariance` (fills traces and
/// goal_covariance of a PRM result). Throws std::invalid_argument if two nodes are not joined.
void predict_along(const Roadmap& map, const Mat4& start_covariance, PlanResult& path);

}  // namespace kestrel::planner
